use super::*;

#[test]
fn actuator_chain_delays_clips_and_kills_small_commands() {
    let tau = [0.0, 1.0, 3.0, -3.0, 0.5];
    let d = Dof::Surge;
    let (x, _) = actuate(&tau, d, &[(Effect::InputDelay { dof: d }, 1.0)]);
    assert_eq!(x, vec![0.0, 0.0, 1.0, 3.0, -3.0]);
    let (x, _) = actuate(&tau, d, &[(Effect::Saturation { dof: d }, 2.0)]);
    assert_eq!(x, vec![0.0, 1.0, 2.0, -2.0, 0.5]);
    let (x, _) = actuate(&tau, d, &[(Effect::DeadZone { dof: d }, 0.8)]);
    assert_eq!(x[4], 0.0);
    assert!((x[2] - 2.2).abs() < 1e-12 && (x[3] + 2.2).abs() < 1e-12);
    let (_, lag) = actuate(&tau, Dof::Sway, &[(Effect::ActuatorLag { dof: d }, 0.4)]);
    assert!(lag.is_none(), "a surge lag must not act on sway");
}

/// A delay of 0.4 samples on a held command: over each interval the thrust
/// is the previous command for 0.4 of it and the new one after, so the
/// interval's mean is 0.4·τ(k − 1) + 0.6·τ(k); 1.25 samples likewise one
/// interval further back. The step response of m u̇ + d u = X through the
/// mean matches the exactly delayed step's to within the hull's change
/// over one interval.
#[test]
fn a_delay_of_a_fraction_of_a_sample_holds_the_interval_mean() {
    let tau = [0.0, 1.0, 3.0, -3.0, 0.5];
    let x = delayed(&tau, 0.4);
    let want = [0.0, 0.6, 2.2, -0.6, -0.9];
    for (a, b) in x.iter().zip(want) {
        assert!((a - b).abs() < 1e-12, "{x:?}");
    }
    let x = delayed(&tau, 1.25);
    let want = [0.0, 0.0, 0.75, 2.5, -1.5];
    for (a, b) in x.iter().zip(want) {
        assert!((a - b).abs() < 1e-12, "{x:?}");
    }
    assert_eq!(delayed(&tau, 2.0), vec![0.0, 0.0, 0.0, 1.0, 3.0]);

    // m u̇ + d u = X(t − 0.04 s) from rest, X a unit step at t = 0.1 s held
    // at 10 Hz: exactly, u(t) = (1 − e^{−(t − 0.14) d/m})/d after 0.14 s.
    let (m, d, h) = (50.0, 20.0, 0.1);
    let steps: Vec<f64> = (0..40).map(|k| if k >= 1 { 1.0 } else { 0.0 }).collect();
    let held = delayed(&steps, 0.04 / h);
    let a = (-d / m * h).exp();
    let mut u = 0.0;
    for (k, x) in held.iter().enumerate().take(39) {
        u = a * u + (1.0 - a) * x / d;
        let t = (k + 1) as f64 * h;
        let exact = if t > 0.14 {
            (1.0 - (-(t - 0.14) * d / m).exp()) / d
        } else {
            0.0
        };
        // 1e-5 m/s against the 8e-4 m/s the delay itself makes at 0.2 s.
        assert!((u - exact).abs() < 2e-5, "t {t}: {u} vs {exact}");
    }
}

/// m u̇ + d u = X from rest with a step X: the surge-only baseline and
/// the exact record u = X/d (1 − e^{−t d/m}) of `n` samples every `h`.
fn step_response(m: f64, d: f64, x: f64, n: usize, h: f64) -> (Baseline, Record) {
    let b = Baseline {
        dofs: vec![Dof::Surge],
        m: DMatrix::from_element(1, 1, m),
        d_bar: DMatrix::from_element(1, 1, d),
        restoring: Restoring::default(),
        coriolis: None,
        quadratic: None,
    };
    let rec = Record {
        name: "step".into(),
        h,
        tau: DMatrix::from_element(n, 1, x),
        nu: DMatrix::from_fn(n, 1, |k, _| x / d * (1.0 - (-(k as f64) * h * d / m).exp())),
        eta: DMatrix::zeros(n, 6),
    };
    (b, rec)
}

#[test]
fn first_order_dof_matches_its_exponential_and_k_step_is_exact() {
    // m u̇ + d u = X with a step: u = X/d (1 − e^{−t d/m}).
    let n = 60;
    let (b, rec) = step_response(100.0, 50.0, 10.0, n, 0.1);
    let nu = rec.nu.clone();
    let model = AugmentedModel::from_baseline(&b);
    let sim = model.simulate(&rec);
    let k5 = model.predict_k_step(&rec, 5);
    for k in 0..n {
        assert!((sim[(k, 0)] - nu[(k, 0)]).abs() < 1e-7);
        if k >= 5 {
            assert!((k5[(k, 0)] - nu[(k, 0)]).abs() < 1e-7);
        } else {
            assert!(k5[(k, 0)].is_nan());
        }
    }
}

/// Sway released at v₀ = 1 m/s under m v̇ + d v + q|v|v = 0 (the
/// baseline's D_q): the free run follows the closed form
/// v(t) = d / ((d/v₀ + q) e^{t d/m} − q), the known force carries
/// q|v|v, and the further discovery refits against the same D_q.
#[test]
fn a_baseline_with_quadratic_damping_decays_as_the_closed_form() {
    use nalgebra::DVector;
    let (m, d, q, v0, h, n) = (200.0, 50.0, 300.0, 1.0, 0.1, 40);
    let b = Baseline {
        dofs: vec![Dof::Sway],
        m: DMatrix::from_element(1, 1, m),
        d_bar: DMatrix::from_element(1, 1, d),
        restoring: Restoring::default(),
        coriolis: None,
        quadratic: Some(QuadraticDamping {
            d_q: DVector::from_element(1, q),
            u0: 0.0,
        }),
    };
    let exact = |t: f64| d / ((d / v0 + q) * (t * d / m).exp() - q);
    let rec = Record {
        name: "decay".into(),
        h,
        tau: DMatrix::zeros(n, 1),
        nu: DMatrix::from_fn(n, 1, |k, _| exact(k as f64 * h)),
        eta: DMatrix::zeros(n, 6),
    };
    let f = b.known_force(&[0.0; 6], &[-0.5]);
    assert!((f[0] + q * 0.25).abs() < 1e-12, "{f:?}");
    let model = AugmentedModel::from_baseline(&b);
    assert_eq!(model.baseline().quadratic, b.quadratic);
    let sim = model.simulate(&rec);
    let linear = AugmentedModel::from_baseline(&Baseline {
        quadratic: None,
        ..b.clone()
    })
    .simulate(&rec);
    for k in 0..n {
        let t = k as f64 * h;
        assert!(
            (sim[(k, 0)] - exact(t)).abs() < 1e-5,
            "t = {t}: {} vs {}",
            sim[(k, 0)],
            exact(t)
        );
    }
    // Without D_q the decay is far slower: the check can fail.
    let end = n - 1;
    assert!(linear[(end, 0)] > 3.0 * exact(end as f64 * h));
}

/// A stiff DOF — time constant m/d = 5 ms, a twentieth of the 0.1 s
/// log interval, and a fitted row whose inertia has collapsed (0.02 kg
/// against 50 N·s/m: 0.4 ms) — where one RK4 step per sample would
/// multiply the error by ≈ 5.5·10³ (4·10⁷) each sample: stepped by
/// ETDRK4 once per sample, the free run and the k-step predictions
/// follow u = X/d (1 − e^{−t d/m}).
#[test]
fn a_stiff_dof_follows_its_exponential() {
    for (m, d) in [(1.0, 200.0), (0.02, 50.0)] {
        let (x, n) = (10.0, 40);
        let (b, rec) = step_response(m, d, x, n, 0.1);
        let model = AugmentedModel::from_baseline(&b);
        assert!(rec.h * model.rate > STIFF_STEP);
        let sim = model.simulate(&rec);
        let k3 = model.predict_k_step(&rec, 3);
        for k in 0..n {
            let want = rec.nu[(k, 0)];
            assert!(
                (sim[(k, 0)] - want).abs() < 1e-9,
                "m={m} k={k}: {}",
                sim[(k, 0)]
            );
            if k >= 3 {
                assert!((k3[(k, 0)] - want).abs() < 1e-9, "m={m} k={k}");
            }
        }
    }
}

/// Unforced, a hull in a current drifts with it: started at ν = ν_c(ψ)
/// (over ground) it stays there, its velocity through the water zero, so
/// neither D̄ nor D_q|δ_r|δ_r acts. Drag on ν over ground would slow it.
#[test]
fn an_unforced_hull_drifts_with_the_current_its_quadratic_drag_on_the_relative_velocity() {
    use crate::models::current::body_current;
    use nalgebra::DVector;
    let dofs = vec![Dof::Surge, Dof::Sway, Dof::Yaw];
    let m = DMatrix::from_diagonal(&DVector::from_vec(vec![60.0, 90.0, 25.0]));
    let d = DMatrix::from_diagonal(&DVector::from_vec(vec![20.0, 30.0, 15.0]));
    let current = [0.2, 0.1];
    let (psi, n, h) = (1.0, 200, 0.1);
    let (uc, vc) = body_current(current, psi);
    assert!((uc - (0.2 * psi.cos() + 0.1 * psi.sin())).abs() < 1e-15);
    assert!((vc - (-0.2 * psi.sin() + 0.1 * psi.cos())).abs() < 1e-15);
    let mut eta = DMatrix::zeros(n, 6);
    eta.column_mut(5).fill(psi);
    let rec = Record {
        name: "drift".into(),
        h,
        tau: DMatrix::zeros(n, 3),
        nu: DMatrix::from_fn(n, 3, |_, j| [uc, vc, 0.0][j]),
        eta,
    };
    let model = AugmentedModel::new(
        dofs,
        m.clone(),
        d.clone(),
        Restoring::default(),
        m,
        d,
        vec![ModelTerm {
            effect: Effect::Current,
            coefficients: current.to_vec(),
            covariance: vec![],
            shape: None,
            shape_std: None,
        }],
    )
    .with_quadratic(Some(QuadraticDamping {
        d_q: DVector::from_vec(vec![40.0, 300.0, 20.0]),
        u0: 0.0,
    }));
    assert_eq!(model.current(), Some(current));
    let sim = model.simulate(&rec);
    for k in 0..n {
        for (j, want) in [uc, vc, 0.0].into_iter().enumerate() {
            assert!(
                (sim[(k, j)] - want).abs() < 1e-9,
                "sample {k}, DOF {j}: {} for {want}",
                sim[(k, j)]
            );
        }
    }
}
