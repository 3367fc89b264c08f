//! The truth simulator against known truths: equilibria, steady states,
//! closed-form responses and conservation laws.

use nalgebra::{DMatrix, Matrix6, Vector3, Vector6};

use super::*;

fn row(m: &DMatrix<f64>, k: usize) -> Vector6<f64> {
    Vector6::from_iterator(m.row(k).iter().copied())
}

fn constant_tau(n: usize, tau: [f64; 6]) -> DMatrix<f64> {
    DMatrix::from_fn(n, 6, |_, j| tau[j])
}

/// Surveyor-like, neutrally buoyant: g(η) = 0 upright, only the B-above-G
/// righting moments remain.
fn neutral() -> RovTruth {
    let mut t = RovTruth::surveyor_like();
    t.restoring.buoyancy = t.restoring.weight;
    t
}

/// Diagonal M and D, no restoring: each DOF is m ν̇ + d ν = τ.
fn diagonal(m: [f64; 6], d: [f64; 6]) -> RovTruth {
    RovTruth::new(
        Matrix6::from_diagonal(&Vector6::from(m)),
        LinearDamping::constant(Matrix6::from_diagonal(&Vector6::from(d))),
    )
}

fn cfg() -> SimConfig {
    SimConfig::default()
}

#[test]
fn unforced_vehicle_decays_to_the_restoring_equilibrium() {
    let truth = neutral();
    let c = SimConfig {
        nu0: [0.5, -0.3, 0.2, 0.1, -0.1, 0.2],
        eta0: [0.0, 0.0, 10.0, 0.3, -0.2, 0.5],
        ..cfg()
    };
    let rec = truth.simulate(&DMatrix::zeros(3000, 6), &c).unwrap();
    let last = rec.len() - 1;
    assert!(
        row(&rec.nu, last).amax() < 1e-9,
        "ν(end) = {}",
        row(&rec.nu, last)
    );
    assert!(rec.eta[(last, 3)].abs() < 1e-9 && rec.eta[(last, 4)].abs() < 1e-9);
    // Roll is under-damped (ζ ≈ 0.19): φ overshoots through zero, which a
    // model without the righting moment could not do.
    assert!(rec.eta.column(3).min() < -0.05, "no roll overshoot");

    // 250 N positively buoyant: settles at φ = θ = 0 rising at
    // w = −(B − W)/D_w = −250/4000 m/s.
    let rec = RovTruth::surveyor_like()
        .simulate(&DMatrix::zeros(3000, 6), &c)
        .unwrap();
    let nu = row(&rec.nu, last);
    assert!((nu[2] + 0.0625).abs() < 1e-9, "w = {}", nu[2]);
    assert!(nu.iter().enumerate().all(|(i, v)| i == 2 || v.abs() < 1e-9));
    assert!(
        rec.eta[(last, 2)] < 10.0 - 15.0,
        "depth z = {}",
        rec.eta[(last, 2)]
    );
}

#[test]
fn constant_surge_force_gives_tau_over_d() {
    // Surveyor D_u = 1500 kg/s at every speed: τ_X = 1500 N → u = 1 m/s; the
    // surge–pitch inertia coupling leaves only a transient.
    let rec = neutral()
        .simulate(
            &constant_tau(1500, [1500.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
            &cfg(),
        )
        .unwrap();
    let nu = row(&rec.nu, 1499);
    assert!((nu[0] - 1.0).abs() < 1e-9, "u = {}", nu[0]);
    assert!(nu.rows(1, 5).amax() < 1e-9 && rec.eta[(1499, 4)].abs() < 1e-9);
    assert!(
        rec.nu.column(4).amax() > 1e-4,
        "the m₁₅ coupling excites pitch"
    );

    // Speed-scheduled D_u(u) = 1000 + 500 u: τ = 3000 N solves
    // 500 u² + 1000 u = 3000, u = √7 − 1.
    let mut d1 = Matrix6::zeros();
    d1[(0, 0)] = 500.0;
    let mut truth = diagonal(
        [6000.0, 9000.0, 11000.0, 3000.0, 15000.0, 15000.0],
        [0.0; 6],
    );
    let d0 = Matrix6::from_diagonal(&Vector6::new(
        1000.0, 3000.0, 4000.0, 2000.0, 6000.0, 5000.0,
    ));
    truth.damping = LinearDamping::affine(d0, d1, vec![0.0, 1.0, 2.0, 3.0]);
    let rec = truth
        .simulate(
            &constant_tau(1500, [3000.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
            &cfg(),
        )
        .unwrap();
    let want = 7.0_f64.sqrt() - 1.0;
    assert!(
        (rec.nu[(1499, 0)] - want).abs() < 1e-9,
        "u = {}",
        rec.nu[(1499, 0)]
    );
}

#[test]
fn drift_in_a_current_is_the_current_in_the_body_frame() {
    let v_c = [0.4, -0.3, 0.0];
    let mut truth = neutral();
    truth.current = Current::Constant { ned: v_c };
    let vc = Vector3::from(v_c);
    for psi0 in [0.0, 1.0, -2.5] {
        let c = SimConfig {
            eta0: [0.0, 0.0, 0.0, 0.0, 0.0, psi0],
            ..cfg()
        };
        let rec = truth.simulate(&DMatrix::zeros(2000, 6), &c).unwrap();
        let k = rec.len() - 1;
        let eta = row(&rec.eta, k);
        let want = kinematics::rotation(eta[3], eta[4], eta[5]).transpose() * vc;
        let nu = row(&rec.nu, k);
        assert!(
            (nu.fixed_rows::<3>(0) - want).amax() < 1e-9,
            "ψ0 = {psi0}: {nu} vs {want}"
        );
        assert!(nu.fixed_rows::<3>(3).amax() < 1e-9);
        // Over ground the vehicle moves with the water.
        let dx = (row(&rec.eta, k) - row(&rec.eta, k - 1)) / 0.1;
        assert!((dx.fixed_rows::<3>(0) - vc).amax() < 1e-9);
    }

    // Turning at r = N/D_r = 1000/5000 rad/s: the body-frame current turns
    // with the heading, u = V_N cos ψ + V_E sin ψ, v = −V_N sin ψ + V_E cos ψ.
    let rec = truth
        .simulate(
            &constant_tau(1500, [0.0, 0.0, 0.0, 0.0, 0.0, 1000.0]),
            &cfg(),
        )
        .unwrap();
    // From 100 s on, the start-up transient (ν_r(0) = −ν_c, slowest time
    // constant M_u/D_u ≈ 3.9 s) is below 1e-11.
    let mut worst: f64 = 0.0;
    for k in 1000..rec.len() {
        let psi = rec.eta[(k, 5)];
        let u = v_c[0] * psi.cos() + v_c[1] * psi.sin();
        let v = -v_c[0] * psi.sin() + v_c[1] * psi.cos();
        worst = worst
            .max((rec.nu[(k, 0)] - u).abs())
            .max((rec.nu[(k, 1)] - v).abs());
    }
    assert!(worst < 1e-10, "max deviation {worst}");
    assert!(
        rec.eta[(1499, 5)] - rec.eta[(1000, 5)] > std::f64::consts::TAU,
        "the compared window covers a full turn"
    );
    assert!((rec.nu[(1499, 5)] - 0.2).abs() < 1e-9);
}

#[test]
fn first_order_lag_gives_the_exponential_step() {
    // τ_a = τ(1 − e^{−t/T}); surge m u̇ + d u = τ_a:
    // u = τ/d [1 − (T_p e^{−t/T_p} − T e^{−t/T}) / (T_p − T)], T_p = m/d.
    let (m, d, t_lag, tau) = (6000.0, 1500.0, 2.0, 1000.0);
    let mut truth = diagonal(
        [m, 9000.0, 11000.0, 3000.0, 15000.0, 15000.0],
        [d, 3000.0, 4000.0, 2000.0, 6000.0, 5000.0],
    );
    truth.actuators.time_constants[0] = t_lag;
    let rec = truth
        .simulate(&constant_tau(300, [tau, 0.0, 0.0, 0.0, 0.0, 0.0]), &cfg())
        .unwrap();
    let tp = m / d;
    for k in 0..rec.len() {
        let t = rec.t[k];
        let ta = tau * (1.0 - (-t / t_lag).exp());
        let u =
            tau / d * (1.0 - (tp * (-t / tp).exp() - t_lag * (-t / t_lag).exp()) / (tp - t_lag));
        assert!(
            (rec.tau_applied[(k, 0)] - ta).abs() < 1e-8,
            "k = {k}: {} vs {ta}",
            rec.tau_applied[(k, 0)]
        );
        assert!(
            (rec.nu[(k, 0)] - u).abs() < 1e-10,
            "k = {k}: {} vs {u}",
            rec.nu[(k, 0)]
        );
    }
    assert_eq!(rec.tau_commanded[(0, 0)], tau);
}

#[test]
fn input_delay_shifts_the_response_by_whole_samples() {
    let n = 400;
    let tau = DMatrix::from_fn(n, 6, |k, j| {
        let amp = [2000.0, 1500.0, 1500.0, 300.0, 500.0, 800.0][j];
        if (k / (11 + 3 * j)) % 2 == 0 {
            amp
        } else {
            -amp
        }
    });
    let base = neutral().simulate(&tau, &cfg()).unwrap();
    let d = 3;
    let mut truth = neutral();
    truth.actuators.delay_samples = d;
    let late = truth.simulate(&tau, &cfg()).unwrap();
    for k in 0..d {
        assert_eq!(row(&late.nu, k), Vector6::zeros());
        assert_eq!(row(&late.tau_applied, k), Vector6::zeros());
    }
    let mut worst: f64 = 0.0;
    for k in d..n {
        worst = worst
            .max((row(&late.nu, k) - row(&base.nu, k - d)).amax())
            .max((row(&late.eta, k) - row(&base.eta, k - d)).amax());
        assert_eq!(row(&late.tau_applied, k), row(&base.tau_applied, k - d));
    }
    assert!(worst < 1e-12, "max deviation {worst}");
    assert!(base.nu.column(0).amax() > 0.1);
}

#[test]
fn saturation_and_dead_zone_shape_the_applied_force() {
    let n = 600;
    let tau = DMatrix::from_fn(n, 6, |k, j| match j {
        0 => 20_000.0 * (0.05 * k as f64).sin(),
        1 => 150.0 * (0.07 * k as f64).sin(),
        5 => 600.0,
        _ => 0.0,
    });
    let mut truth = neutral();
    truth.actuators.saturation[0] = 10_000.0;
    truth.actuators.dead_zone[1] = 200.0;
    let rec = truth.simulate(&tau, &cfg()).unwrap();
    for k in 0..n {
        assert_eq!(
            rec.tau_applied[(k, 0)],
            tau[(k, 0)].clamp(-10_000.0, 10_000.0)
        );
        assert_eq!(rec.tau_applied[(k, 1)], 0.0);
        assert_eq!(rec.tau_applied[(k, 5)], 600.0);
    }
    assert_eq!(rec.tau_applied.column(0).max(), 10_000.0);
    assert_eq!(rec.tau_applied.column(0).min(), -10_000.0);
    // The clipped run is slower than the unclipped one.
    let free = neutral().simulate(&tau, &cfg()).unwrap();
    assert!(free.nu.column(0).amax() > rec.nu.column(0).amax() + 0.1);
}

#[test]
fn kinetic_energy_is_conserved_without_damping_and_forces() {
    for coriolis in [false, true] {
        let mut truth = RovTruth::new(
            RovTruth::surveyor_like().m,
            LinearDamping::constant(Matrix6::zeros()),
        );
        truth.coriolis = coriolis;
        let nu0 = [1.0, 0.3, -0.2, 0.05, -0.03, 0.1];
        let c = SimConfig { nu0, ..cfg() };
        let rec = truth.simulate(&DMatrix::zeros(200, 6), &c).unwrap();
        let energy = |k: usize| {
            let nu = row(&rec.nu, k);
            0.5 * nu.dot(&(truth.m * nu))
        };
        let e0 = energy(0);
        let mut drift: f64 = 0.0;
        let mut change: f64 = 0.0;
        for k in 0..rec.len() {
            drift = drift.max((energy(k) - e0).abs() / e0);
            change = change.max((row(&rec.nu, k) - Vector6::from(nu0)).amax());
        }
        assert!(
            drift < 1e-9,
            "coriolis {coriolis}: relative energy drift {drift}"
        );
        if coriolis {
            // C(ν) redistributes the energy among the DOFs.
            assert!(change > 0.05, "ν barely changed: {change}");
        } else {
            assert_eq!(change, 0.0);
        }
    }
}

#[test]
fn steady_turn_traces_the_exact_circle() {
    // Constant ν = [U 0 0 0 0 r] held by τ = D ν: x = (U/r) sin rt,
    // y = (U/r)(1 − cos rt), ψ = r t.
    let (u, r) = (1.0, 0.1);
    let d = [1500.0, 3000.0, 4000.0, 2000.0, 6000.0, 5000.0];
    let truth = diagonal([6000.0, 9000.0, 11000.0, 3000.0, 15000.0, 15000.0], d);
    let c = SimConfig {
        nu0: [u, 0.0, 0.0, 0.0, 0.0, r],
        ..cfg()
    };
    let rec = truth
        .simulate(
            &constant_tau(700, [d[0] * u, 0.0, 0.0, 0.0, 0.0, d[5] * r]),
            &c,
        )
        .unwrap();
    for k in 0..rec.len() {
        let t = rec.t[k];
        assert!(
            (rec.eta[(k, 0)] - u / r * (r * t).sin()).abs() < 1e-9,
            "x at {t}"
        );
        assert!(
            (rec.eta[(k, 1)] - u / r * (1.0 - (r * t).cos())).abs() < 1e-9,
            "y at {t}"
        );
        assert!((rec.eta[(k, 5)] - r * t).abs() < 1e-12);
    }
}

#[test]
fn tether_tilts_and_tows_to_the_static_balance() {
    // (z_G W − z_B B) sin θ = τ_t,M with z_G W − z_B B = 0.2 W; u = X_t / D_u.
    let mut truth = neutral();
    truth.tether = Tether {
        pitch_moment: 2000.0,
        body_force: [500.0, 0.0, 0.0],
    };
    let rec = truth.simulate(&DMatrix::zeros(2000, 6), &cfg()).unwrap();
    let k = rec.len() - 1;
    let theta = (2000.0 / (0.2 * truth.restoring.weight)).asin();
    assert!(
        (rec.eta[(k, 4)] - theta).abs() < 1e-9,
        "θ = {}",
        rec.eta[(k, 4)]
    );
    assert!((rec.nu[(k, 0)] - 500.0 / 1500.0).abs() < 1e-9);
    assert!(row(&rec.nu, k).rows(1, 5).amax() < 1e-9);
}

#[test]
fn measurement_noise_has_the_set_spread_and_is_seeded() {
    let noise_nu = [0.01, 0.02, 0.005, 0.001, 0.002, 0.003];
    let noise_eta = [0.1, 0.1, 0.05, 0.001, 0.001, 0.002];
    let c = SimConfig {
        noise_nu,
        noise_eta,
        noise_seed: 42,
        ..cfg()
    };
    let tau = constant_tau(5000, [800.0, 0.0, 0.0, 0.0, 0.0, 300.0]);
    let rec = neutral().simulate(&tau, &c).unwrap();
    let n = rec.len() as f64;
    for i in 0..6 {
        for (meas, truth, std) in [
            (&rec.nu, &rec.nu_true, noise_nu[i]),
            (&rec.eta, &rec.eta_true, noise_eta[i]),
        ] {
            let e: Vec<f64> = (0..rec.len())
                .map(|k| meas[(k, i)] - truth[(k, i)])
                .collect();
            let mean = e.iter().sum::<f64>() / n;
            let s = (e.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n).sqrt();
            // Standard error of s is std/√(2N) = 1 %.
            assert!((s / std - 1.0).abs() < 0.05, "channel {i}: {s} vs {std}");
            assert!(mean.abs() < 4.0 * std / n.sqrt());
        }
    }
    let again = neutral().simulate(&tau, &c).unwrap();
    assert_eq!(again, rec);
    let other = neutral()
        .simulate(
            &tau,
            &SimConfig {
                noise_seed: 43,
                ..c
            },
        )
        .unwrap();
    assert_eq!(other.nu_true, rec.nu_true);
    assert_ne!(other.nu, rec.nu);
    let clean = neutral().simulate(&tau, &cfg()).unwrap();
    assert_eq!(clean.nu, clean.nu_true);
    assert_eq!(clean.nu_true, rec.nu_true);
}

#[test]
fn random_current_is_reproducible_and_felt() {
    let mut truth = neutral();
    truth.current = Current::RandomWalk(RandomWalkCurrent {
        initial_ned: [0.3, 0.0, 0.0],
        sigma: [0.01, 0.01, 0.0],
        mu: 0.0,
        max_speed: 1.0,
        seed: 5,
    });
    let tau = DMatrix::zeros(3000, 6);
    let a = truth.simulate(&tau, &cfg()).unwrap();
    let b = truth.simulate(&tau, &cfg()).unwrap();
    assert_eq!(a, b);
    assert_eq!(a.current_ned[(0, 0)], 0.3);
    let spread = (a.current_ned.column(0).max() - a.current_ned.column(0).min())
        .max(a.current_ned.column(1).max() - a.current_ned.column(1).min());
    assert!(spread > 0.02, "the current did not wander: {spread}");
    // The vehicle drifts with the water: the north drift over ground follows
    // the mean current within the lag of a few seconds.
    let mean_vn = a.current_ned.column(0).mean();
    let drift = (a.eta[(2999, 0)] - a.eta[(0, 0)]) / a.t[2999];
    assert!(
        (drift - mean_vn).abs() < 0.02,
        "drift {drift} vs mean current {mean_vn}"
    );
}

#[test]
fn csv_follows_the_log_schema() {
    let c = SimConfig {
        nu0: [0.5, 0.0, 0.0, 0.0, 0.0, 0.1],
        noise_nu: [0.01; 6],
        ..cfg()
    };
    let rec = neutral()
        .simulate(&constant_tau(5, [100.0, -50.0, 0.0, 0.0, 1.5, 0.0]), &c)
        .unwrap();
    let csv = rec.to_csv();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(
        lines[0],
        "t,tau_X,tau_Y,tau_Z,tau_K,tau_M,tau_N,u,v,w,p,q,r,x,y,z,phi,theta,psi"
    );
    assert_eq!(lines.len(), 6);
    let fields: Vec<f64> = lines[3].split(',').map(|s| s.parse().unwrap()).collect();
    assert_eq!(fields.len(), 19);
    assert_eq!(fields[0], rec.t[2]);
    assert_eq!(fields[1..7], [100.0, -50.0, 0.0, 0.0, 1.5, 0.0]);
    for i in 0..6 {
        assert_eq!(fields[7 + i], rec.nu[(2, i)]);
        assert_eq!(fields[13 + i], rec.eta[(2, i)]);
    }
}

#[test]
fn bad_input_is_a_typed_error_naming_the_field() {
    let truth = neutral();
    let err = truth.simulate(&DMatrix::zeros(10, 5), &cfg()).unwrap_err();
    assert_eq!(
        err.to_string(),
        "tau_commanded is 10×5 but must be N×6 with N ≥ 1 (columns tau_X … tau_N)"
    );
    let mut tau = DMatrix::zeros(10, 6);
    tau[(4, 2)] = f64::NAN;
    assert_eq!(
        truth.simulate(&tau, &cfg()).unwrap_err().to_string(),
        "tau_commanded contains NaN or infinite entries"
    );
    let tau = DMatrix::zeros(10, 6);
    let err = truth
        .simulate(&tau, &SimConfig { h: 0.0, ..cfg() })
        .unwrap_err();
    assert!(err.to_string().starts_with("h = 0 must be"), "{err}");
    let err = truth
        .simulate(
            &tau,
            &SimConfig {
                substeps: 0,
                ..cfg()
            },
        )
        .unwrap_err();
    assert!(err.to_string().starts_with("substeps"), "{err}");
    let c = SimConfig {
        eta0: [0.0, 0.0, 0.0, 0.0, std::f64::consts::FRAC_PI_2, 0.0],
        ..cfg()
    };
    assert!(
        truth
            .simulate(&tau, &c)
            .unwrap_err()
            .to_string()
            .starts_with("eta0[theta]")
    );
    let c = SimConfig {
        noise_eta: [0.0, 0.0, -1.0, 0.0, 0.0, 0.0],
        ..cfg()
    };
    assert!(
        truth
            .simulate(&tau, &c)
            .unwrap_err()
            .to_string()
            .starts_with("noise_eta[heave] = -1")
    );

    let mut bad = neutral();
    bad.m[(3, 3)] = -10.0;
    let err = bad.simulate(&tau, &cfg()).unwrap_err();
    assert!(
        err.to_string()
            .starts_with("M must be symmetric positive definite: the smallest eigenvalue"),
        "{err}"
    );
    let mut bad = neutral();
    bad.m[(0, 5)] = 100.0;
    assert!(matches!(
        bad.simulate(&tau, &cfg()),
        Err(SimError::InertiaNotSpd { .. })
    ));
    let mut bad = neutral();
    bad.damping.tables.pop();
    assert!(
        bad.simulate(&tau, &cfg())
            .unwrap_err()
            .to_string()
            .starts_with("damping: 5 speeds and 4 tables")
    );

    // A violently unstable truth is stopped with the time it blew up.
    let bad = diagonal([1.0; 6], [-1e4; 6]);
    let c = SimConfig {
        nu0: [1.0; 6],
        ..cfg()
    };
    let err = bad.simulate(&DMatrix::zeros(100, 6), &c).unwrap_err();
    assert!(matches!(err, SimError::Diverged { .. }), "{err}");
}

#[test]
fn cubic_and_cross_damping_reach_their_analytic_steady_states() {
    // Surge: d·u + c·u³ = F; sway under a steady turn: (d_v + d_vr·|r|)·v =
    // F_v with r = N/d_r (diagonal M, no Coriolis: the DOFs are decoupled).
    let (d, c, f) = (1500.0, 2000.0, 3000.0);
    let (dv, dvr, fv, dr, n) = (3000.0, 8000.0, 600.0, 5000.0, 1000.0);
    let mut t = diagonal(
        [5800.0, 9000.0, 11000.0, 2800.0, 15000.0, 15000.0],
        [d, dv, 4000.0, 2000.0, 6000.0, dr],
    );
    t.cubic_damping[0] = c;
    t.cross_damping[1][5] = dvr;
    let rec = t
        .simulate(&constant_tau(4000, [f, fv, 0.0, 0.0, 0.0, n]), &cfg())
        .unwrap();
    let last = row(&rec.nu, rec.len() - 1);
    // Newton on d·u + c·u³ − F.
    let mut u: f64 = f / d;
    for _ in 0..50 {
        u -= (d * u + c * u.powi(3) - f) / (d + 3.0 * c * u * u);
    }
    assert!((last[0] - u).abs() < 1e-6, "u = {} vs {u}", last[0]);
    assert!(u < f / d - 0.5, "the cubic term is material");
    let r = n / dr;
    assert!((last[5] - r).abs() < 1e-9);
    let v = fv / (dv + dvr * r.abs());
    assert!((last[1] - v).abs() < 1e-6, "v = {} vs {v}", last[1]);
    // Turning the other way damps sway alike (|r|).
    let rec = t
        .simulate(&constant_tau(4000, [f, fv, 0.0, 0.0, 0.0, -n]), &cfg())
        .unwrap();
    assert!((rec.nu[(rec.len() - 1, 1)] - v).abs() < 1e-6);
}
