use super::*;
use crate::discrepancy::candidates::TermContext;

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
    let nu = |t: f64| {
        (
            0.6 * (0.3 * t).sin() + 0.2 * (1.1 * t).sin(),
            0.18 * (0.3 * t).cos() + 0.22 * (1.1 * t).cos(),
        )
    };
    let (baseline, records) = surge_record(nu, theta);
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

/// The baseline blocks kept between fits (`fit/blocks.rs`) change no
/// result: a fit whose actuator hypothesis reshapes the target, then one
/// on the logged τ, give bit for bit what each gives on a fresh
/// preparation, and a repeated fit gives the same again.
#[test]
fn fits_from_kept_baseline_blocks_equal_fresh_ones() {
    let nu = |t: f64| {
        (
            0.6 * (0.3 * t).sin() + 0.2 * (1.1 * t).sin(),
            0.18 * (0.3 * t).cos() + 0.22 * (1.1 * t).cos(),
        )
    };
    let (baseline, records) = surge_record(nu, 400.0);
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
    // The lag reshapes the target: its fit is not the plain one's.
    assert_ne!(lagged.sse.to_bits(), plain.sse.to_bits());
    // The quadratic term of the record is found.
    assert!(
        (plain.theta[0][0] / 400.0 - 1.0).abs() < 0.1,
        "{:?}",
        plain.theta
    );
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
