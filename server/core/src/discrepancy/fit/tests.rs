use super::*;
use crate::discrepancy::candidates::TermContext;
use crate::models::current::body_current;

/// A 1-DOF surge record with M ν̇ + D ν + θ|ν|ν = τ written from
/// `nu(t)` and its derivative, and the prepared fits on it.
fn surge_record(nu: impl Fn(f64) -> (f64, f64), theta: f64) -> (Baseline, [Record; 1]) {
    let (n, h, m, d) = (3000, 0.1, 500.0, 300.0);
    let (mut tau, mut v) = (DMatrix::zeros(n, 1), DMatrix::zeros(n, 1));
    for k in 0..n {
        let (x, xd) = nu(k as f64 * h);
        v[(k, 0)] = x;
        tau[(k, 0)] = m * xd + d * x + theta * x.abs() * x;
    }
    let rec = Record {
        name: "surge".into(),
        h,
        tau,
        nu: v,
        eta: DMatrix::zeros(n, 6),
    };
    let baseline = Baseline {
        dofs: vec![Dof::Surge],
        m: DMatrix::from_element(1, 1, m),
        d_bar: DMatrix::from_element(1, 1, d),
        restoring: Default::default(),

        coriolis: None,
        quadratic: None,
    };
    (baseline, [rec])
}

/// ν(t) of two sines (0.3 and 1.1 rad/s) and its derivative.
fn two_sines(t: f64) -> (f64, f64) {
    (
        0.6 * (0.3 * t).sin() + 0.2 * (1.1 * t).sin(),
        0.18 * (0.3 * t).cos() + 0.22 * (1.1 * t).cos(),
    )
}

/// The force share of `spec` on the surge record (fits without and with
/// it, the surge row refitted) and its fitted coefficient.
fn share_of(spec: Spec, baseline: &Baseline, records: &[Record]) -> (f64, f64) {
    let prep = Prepared::new(baseline, records, 0.5, 10, 5).expect("prepared");
    let null = prep.fit(&[], &[0], &[0], false).expect("null");
    let with = prep.fit(&[spec], &[], &[0], false).expect("with");
    let share = prep
        .force_share(&null, &with, &[0], &[0])
        .expect("same blocks");
    (share, with.theta[0][0])
}

#[test]
fn a_terms_force_share_is_the_force_it_explains_not_its_coefficient() {
    let quad = Spec {
        effect: Effect::QuadraticDamping { dof: Dof::Surge },
        shape: None,
    };
    // A real quadratic drag: the share is the part of θ|ν|ν that M and
    // D̄ cannot take over, at most the whole of it against τ.
    let theta = 400.0;
    let (baseline, records) = surge_record(two_sines, theta);
    let (share, fitted) = share_of(quad, &baseline, &records);
    let rms = |f: &dyn Fn(usize) -> f64| {
        ((0..records[0].len()).map(|k| f(k).powi(2)).sum::<f64>() / records[0].len() as f64).sqrt()
    };
    let whole = rms(&|k| {
        let x = records[0].nu[(k, 0)];
        theta * x.abs() * x
    }) / rms(&|k| records[0].tau[(k, 0)]);
    assert!(
        share > 0.2 * whole && share < 1.05 * whole,
        "{share} vs {whole}"
    );
    assert!((fitted / theta - 1.0).abs() < 0.1, "{fitted}");

    // A square-wave speed: |ν|ν = a·ν, the term is D̄ over again and
    // changes nothing, whatever its coefficient.
    let square = |t: f64| (if (0.2 * t).sin() >= 0.0 { 0.5 } else { -0.5 }, 0.0);
    let (baseline, records) = surge_record(square, 0.0);
    let (share, _) = share_of(quad, &baseline, &records);
    assert!(share < 1e-4, "collinear term: share {share}");
}

#[test]
fn the_current_regressor_from_kept_signals_is_the_filtered_direct_one() {
    // A turning run: ψ sweeps, r varies; a coupled D̄, M. The combined
    // cached signals equal filtering the regressor sample by sample.
    let dofs = Dof::ALL.to_vec();
    let n = 400;
    let h = 0.1;
    let mut nu = DMatrix::zeros(n, 6);
    let mut eta = DMatrix::zeros(n, 6);
    for k in 0..n {
        let t = k as f64 * h;
        nu[(k, 0)] = 0.5 + 0.1 * (0.3 * t).sin();
        nu[(k, 1)] = 0.05 * (0.7 * t).cos();
        nu[(k, 5)] = 0.2 * (0.1 * t).sin();
        eta[(k, 5)] = 2.0 * (1.0 - (0.1 * t).cos());
    }
    let rec = Record {
        name: "turn".into(),
        h,
        tau: DMatrix::zeros(n, 6),
        nu,
        eta,
    };
    let m = DMatrix::from_fn(6, 6, |i, j| {
        if i == j {
            100.0 + i as f64
        } else {
            3.0 * (i + 2 * j) as f64
        }
    });
    let d = DMatrix::from_fn(6, 6, |i, j| {
        if i == j {
            40.0
        } else {
            (i as f64 - j as f64) * 2.5
        }
    });
    let baseline = Baseline {
        dofs: dofs.clone(),
        m: m.clone(),
        d_bar: d.clone(),
        restoring: Default::default(),

        coriolis: None,
        quadratic: None,
    };
    let records = [rec];
    let prep = Prepared::new(&baseline, &records, 0.5, 10, 5).expect("prepared");
    let ctx = TermContext {
        dofs: &dofs,
        m_ref: &m,
        d_ref: &d,
    };
    for r in 0..6 {
        for p in 0..2 {
            let raw: Vec<f64> = (0..n)
                .map(|k| {
                    let v: Vec<f64> = (0..6).map(|j| records[0].nu[(k, j)]).collect();
                    Effect::Current.regressor(p, r, &ctx, &v, &records[0].eta_at(k))
                })
                .collect();
            let direct = prep.svf.foh(&raw);
            let kept = prep.filtered_regressor(Effect::Current, p, r, 0, &ctx);
            let scale = direct.iter().fold(1e-12_f64, |a, x| a.max(x.abs()));
            for k in 0..n {
                assert!(
                    (kept[k] - direct[k]).abs() < 1e-9 * scale,
                    "row {r}, coefficient {p}, sample {k}: {} vs {}",
                    kept[k],
                    direct[k]
                );
            }
        }
    }
}

/// The baseline blocks, term columns and their products kept between fits
/// (`fit/blocks.rs`) change no result: a fit whose actuator hypothesis
/// reshapes the target, then one on the logged τ, give bit for bit what
/// each gives on a fresh preparation, and a repeated fit (its products now
/// all kept) gives the same again.
#[test]
fn fits_from_kept_baseline_blocks_equal_fresh_ones() {
    let (baseline, records) = surge_record(two_sines, 400.0);
    let quad = Spec {
        effect: Effect::QuadraticDamping { dof: Dof::Surge },
        shape: None,
    };
    let lag = Spec {
        effect: Effect::ActuatorLag { dof: Dof::Surge },
        shape: Some(0.3),
    };
    let fresh = |spec: Spec| {
        let prep = Prepared::new(&baseline, &records, 0.5, 10, 5).expect("prepared");
        prep.fit(&[spec], &[], &[0], true).expect("fit")
    };
    let same = |a: &FitOut, b: &FitOut| {
        assert_eq!(a.theta, b.theta);
        assert_eq!(a.base, b.base);
        assert_eq!(a.sse.to_bits(), b.sse.to_bits());
        assert_eq!(a.resid, b.resid);
        assert_eq!(a.cov, b.cov);
    };
    let prep = Prepared::new(&baseline, &records, 0.5, 10, 5).expect("prepared");
    let lagged = prep.fit(&[lag], &[], &[0], true).expect("lag");
    let plain = prep.fit(&[quad], &[], &[0], true).expect("quad");
    same(&lagged, &fresh(lag));
    same(&plain, &fresh(quad));
    same(
        &prep.fit(&[lag], &[], &[0], true).expect("lag again"),
        &lagged,
    );
    same(
        &prep.fit(&[quad], &[], &[0], true).expect("quad again"),
        &plain,
    );
    // The lag reshapes the target: its fit is not the plain one's.
    assert_ne!(lagged.sse.to_bits(), plain.sse.to_bits());
    // The quadratic term of the record is found.
    assert!(
        (plain.theta[0][0] / 400.0 - 1.0).abs() < 0.1,
        "{:?}",
        plain.theta
    );
}

/// A shape profile's points from normal equations assembled once
/// ([`Prepared::shape_profile`]) give θ bit for bit as full fits at each
/// shape, with a quadratic term fitted beside the lag, a held lag and a
/// delay of other rows untouched; a profile over specs with a current is
/// not exact and says so.
#[test]
fn profile_points_from_one_assembly_equal_full_fits() {
    let (baseline, records) = surge_record(two_sines, 400.0);
    let prep = Prepared::new(&baseline, &records, 0.5, 10, 5).expect("prepared");
    let quad = Spec {
        effect: Effect::QuadraticDamping { dof: Dof::Surge },
        shape: None,
    };
    let lag = |v: f64| Spec {
        effect: Effect::ActuatorLag { dof: Dof::Surge },
        shape: Some(v),
    };
    let fits = prep
        .shape_profile(&[quad, lag(0.05)], &[], &[0])
        .expect("a profile");
    assert!(fits.exact);
    let mut thetas = Vec::new();
    for v in [0.05, 0.2, 0.7] {
        let fast = fits.at(v).expect("θ");
        let full = prep.fit(&[quad, lag(v)], &[], &[0], false).expect("fit");
        assert_eq!(fast.theta, full.theta, "lag {v}");
        assert_eq!(fast.base, full.base, "lag {v}");
        assert!(fast.sse.is_nan() && fast.resid.is_empty());
        thetas.push(fast.theta[0][0]);
    }
    // The shape changes the fit.
    assert_ne!(thetas[0], thetas[2]);
    let current = Spec {
        effect: Effect::Current,
        shape: None,
    };
    let with_current = prep.shape_profile(&[current, lag(0.05)], &[], &[0]);
    assert!(with_current.is_none_or(|f| !f.exact));
}

/// Sway never forced (τ_Y = 0), moved only by yaw through the coupling
/// D̄_vr: M_v v̇ + D_v v + D_vr r = 0, M_r ṙ + D_r r = τ_N. The sway row is
/// homogeneous, so its mass is held at the baseline's and the row's
/// damping comes back from the data instead of collapsing to zero.
#[test]
fn an_unforced_row_keeps_its_mass_and_fits_the_rest_against_it() {
    let (mv, dv, dvr, mr, dr) = (160.0, 150.0, 40.0, 40.0, 45.0);
    let (n, h, sub) = (3000, 0.1, 20);
    let (mut tau, mut nu) = (DMatrix::zeros(n, 2), DMatrix::zeros(n, 2));
    let (mut v, mut r) = (0.0_f64, 0.0_f64);
    for k in 0..n {
        let t = k as f64 * h;
        let tn = 8.0 * (0.4 * t).sin() + 5.0 * (1.3 * t).sin();
        nu[(k, 0)] = v;
        nu[(k, 1)] = r;
        tau[(k, 1)] = tn;
        let dt = h / sub as f64;
        for _ in 0..sub {
            let vd = (-dv * v - dvr * r) / mv;
            let rd = (tn - dr * r) / mr;
            v += dt * vd;
            r += dt * rd;
        }
    }
    let records = [Record {
        name: "turns".into(),
        h,
        tau,
        nu,
        eta: DMatrix::zeros(n, 6),
    }];
    let baseline = Baseline {
        dofs: vec![Dof::Sway, Dof::Yaw],
        m: DMatrix::from_row_slice(2, 2, &[mv, 0.0, 0.0, mr]),
        d_bar: DMatrix::from_row_slice(2, 2, &[dv, dvr, 0.0, dr]),
        restoring: Default::default(),
        coriolis: None,
        quadratic: None,
    };
    let prep = Prepared::new(&baseline, &records, 0.5, 10, 5).expect("prepared");
    assert!(prep.structure[0].0.is_empty(), "sway's M_vv is held");
    assert_eq!(prep.structure[1].0, vec![1], "yaw's M_rr is fitted");
    let f = prep.fit(&[], &[0], &[0], false).expect("sway row");
    let (m_free, d_free) = &f.base[0];
    assert!(m_free.is_empty());
    assert!(
        (d_free[0] - dv).abs() < 0.02 * dv,
        "D_v {} against {dv}",
        d_free[0]
    );
    assert!(
        (d_free[1] - dvr).abs() < 0.02 * dvr,
        "D_vr {} against {dvr}",
        d_free[1]
    );
}

/// A 3-DOF hull in a current with quadratic drag on the velocity through
/// the water, M ν̇_r + D̄ ν_r + D_q|ν_r|ν_r = τ (ν_r = ν − ν_c(ψ),
/// ψ̇ = r; Fossen 2011, sec. 10.3: a constant irrotational current), its
/// records generated here by RK4 on ν_r (not the model's integrator),
/// logged as ν over ground. The baseline knows M, D̄ and D_q; the current
/// is fitted. Its drag is not linear in (V_N, V_E): with the drag put on
/// ν over ground, or the current taken through D̄ alone, the fit is off.
#[test]
fn the_current_is_fitted_through_the_quadratic_drag_on_the_relative_velocity() {
    use crate::models::quadratic_damping::QuadraticDamping;
    use nalgebra::DVector;
    let dofs = vec![Dof::Surge, Dof::Sway, Dof::Yaw];
    let m = DMatrix::from_diagonal(&DVector::from_vec(vec![60.0, 90.0, 25.0]));
    let d = DMatrix::from_diagonal(&DVector::from_vec(vec![20.0, 30.0, 15.0]));
    let d_q = DVector::from_vec(vec![0.0, 250.0, 20.0]);
    let current = [0.25, -0.15];
    let (h, n, sub) = (0.1, 3000, 10);
    let rhs = |x: &[f64; 4], tau: &[f64; 3]| -> [f64; 4] {
        let mut dx = [0.0; 4];
        for i in 0..3 {
            let q = d_q[i] * x[i].abs() * x[i];
            dx[i] = (tau[i] - d[(i, i)] * x[i] - q) / m[(i, i)];
        }
        dx[3] = x[2];
        dx
    };
    let records: Vec<Record> = (0..2)
        .map(|run| {
            let (mut tau_m, mut nu_m, mut eta_m) = (
                DMatrix::zeros(n, 3),
                DMatrix::zeros(n, 3),
                DMatrix::zeros(n, 6),
            );
            // x = (u_r, v_r, r, ψ).
            let mut x = [0.3, 0.0, 0.0, 0.5 * run as f64];
            for k in 0..n {
                let t = k as f64 * h;
                let tau = [
                    12.0 + 6.0 * (0.11 * t + run as f64).sin(),
                    25.0 * (0.23 * t).sin() + 15.0 * (0.07 * t + 1.0).cos(),
                    4.0 * (0.05 * t).sin() + 2.0 * (0.31 * t).cos(),
                ];
                let (uc, vc) = body_current(current, x[3]);
                for (i, v) in [x[0] + uc, x[1] + vc, x[2]].into_iter().enumerate() {
                    nu_m[(k, i)] = v;
                    tau_m[(k, i)] = tau[i];
                }
                eta_m[(k, 5)] = x[3];
                let hs = h / sub as f64;
                for _ in 0..sub {
                    let k1 = rhs(&x, &tau);
                    let x2 = std::array::from_fn(|i| x[i] + 0.5 * hs * k1[i]);
                    let k2 = rhs(&x2, &tau);
                    let x3 = std::array::from_fn(|i| x[i] + 0.5 * hs * k2[i]);
                    let k3 = rhs(&x3, &tau);
                    let x4 = std::array::from_fn(|i| x[i] + hs * k3[i]);
                    let k4 = rhs(&x4, &tau);
                    for i in 0..4 {
                        x[i] += hs / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
                    }
                }
            }
            Record {
                name: format!("turns-{run}"),
                h,
                tau: tau_m,
                nu: nu_m,
                eta: eta_m,
            }
        })
        .collect();
    let baseline = Baseline {
        dofs,
        m,
        d_bar: d,
        restoring: Default::default(),
        coriolis: None,
        quadratic: Some(QuadraticDamping { d_q, u0: 0.0 }),
    };
    let prep = Prepared::new(&baseline, &records, 0.5, 10, 5).expect("prepared");
    let spec = Spec {
        effect: Effect::Current,
        shape: None,
    };
    let f = prep.fit_for_model(&[spec], &[0, 1], false).expect("fit");
    let est = &f.theta[0];
    let err = ((est[0] - current[0]).powi(2) + (est[1] - current[1]).powi(2)).sqrt();
    assert!(
        err < 0.005,
        "current {est:?} for {current:?} (error {err:.4} m/s)"
    );
    // The model of the fit carries the current into the drag: started on
    // the true ν it follows the record.
    let model = prep.model(&[spec], &f, &[]);
    let sim = model.simulate(&records[1]);
    let worst = (0..n)
        .map(|k| (sim[(k, 1)] - records[1].nu[(k, 1)]).abs())
        .fold(0.0, f64::max);
    assert!(worst < 0.02, "sway free run off by {worst:.4} m/s");
}
