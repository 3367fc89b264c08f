//! Tests of the LPV model: grid points, interpolation, the extension
//! below the grid, the predictor against a piecewise-constant-speed truth.

use super::*;
use crate::simulation::integrate::simulate as rk4_simulate;
use crate::validation::nrmse_fit_columns;

const GRID: [f64; 3] = [0.5, 1.0, 1.5];

/// Surge–yaw sub-model at grid speed `x`: surge damping grows with speed,
/// surge couples into yaw through D̄[yaw,surge] (Munk-like moment).
fn point(x: f64) -> LinearVesselModel {
    let m = DMatrix::from_row_slice(2, 2, &[5000.0, 0.0, 0.0, 3000.0]);
    let d = DMatrix::from_row_slice(
        2,
        2,
        &[300.0 + 600.0 * x, 0.0, 150.0 * x, 400.0 + 200.0 * x],
    );
    LinearVesselModel::new(vec![Dof::Surge, Dof::Yaw], m, d).unwrap()
}

fn lpv() -> LpvModel {
    LpvModel::new(GRID.to_vec(), GRID.iter().map(|&x| point(x)).collect()).unwrap()
}

#[test]
fn grid_speeds_return_their_sub_model() {
    let lpv = lpv();
    for (i, &x) in GRID.iter().enumerate() {
        for s in [Scheduling::Nearest, Scheduling::Interpolate] {
            let w = lpv.weights(x, s).unwrap();
            assert_eq!((w.lower, w.upper, w.w_lower), (i, i, 1.0));
            assert_eq!(&lpv.at(x, s).unwrap(), &lpv.points()[i]);
        }
    }
    // Outside the grid: the end models (thesis's edge rule).
    for s in [Scheduling::Nearest, Scheduling::Interpolate] {
        assert_eq!(lpv.weights(0.1, s).unwrap().lower, 0);
        assert_eq!(lpv.weights(2.4, s).unwrap().upper, 2);
    }
    // Nearest: 0.74 → 0.5, 0.76 → 1.0, tie 0.75 → the lower point.
    let near = |v| lpv.weights(v, Scheduling::Nearest).unwrap().lower;
    assert_eq!((near(0.74), near(0.76), near(0.75)), (0, 1, 0));
    assert!(lpv.weights(f64::NAN, Scheduling::Nearest).is_err());
}

#[test]
fn midway_interpolation_is_the_average() {
    let lpv = lpv();
    let mid = lpv.at(1.25, Scheduling::Interpolate).unwrap();
    let (a, b) = (&lpv.points()[1], &lpv.points()[2]);
    assert!((mid.m() - (a.m() + b.m()) * 0.5).amax() < 1e-12);
    assert!((mid.d_bar() - (a.d_bar() + b.d_bar()) * 0.5).amax() < 1e-12);
    // Surge damping is linear in x, so the average equals the model at 1.25.
    assert!((mid.d_bar()[(0, 0)] - (300.0 + 600.0 * 1.25)).abs() < 1e-9);
    // A quarter of the way: w_lower = 0.75.
    let w = lpv.weights(1.125, Scheduling::Interpolate).unwrap();
    assert_eq!((w.lower, w.upper), (1, 2));
    assert!((w.w_lower - 0.75).abs() < 1e-15);
    // Discrete: Φ and Γ averaged.
    let d = lpv.discretize(0.1).unwrap();
    let dm = d.at(1.25, Scheduling::Interpolate).unwrap();
    let (pa, pb) = (&d.points()[1], &d.points()[2]);
    assert!((dm.phi() - (pa.phi() + pb.phi()) * 0.5).amax() < 1e-15);
    assert!((dm.gamma() - (pa.gamma() + pb.gamma()) * 0.5).amax() < 1e-15);
}

/// Truth: ν̇ = A_i ν + B_i γ with i the grid point nearest to the forward
/// speed sampled at the start of each interval (piecewise constant in
/// speed), integrated by fine RK4. Surge is driven to hold 0.5, 1.0,
/// 1.5, 1.0 m/s in turn with a square-wave perturbation; yaw is excited
/// by its own square wave.
fn truth_record(n: usize, h: f64) -> (DMatrix<f64>, DMatrix<f64>) {
    let lpv = lpv();
    let targets = [0.5, 1.0, 1.5, 1.0];
    let seg = n / targets.len() + 1;
    let u = DMatrix::from_fn(n, 2, |k, j| {
        let sq = if (k / [13, 29][j]) % 2 == 0 {
            1.0
        } else {
            -1.0
        };
        if j == 0 {
            let x = targets[k / seg];
            (300.0 + 600.0 * x) * x + 120.0 * sq
        } else {
            80.0 * sq
        }
    });
    let sub = 40;
    let mut y = DMatrix::zeros(n, 2);
    let mut x = vec![0.5, 0.0];
    for k in 0..n {
        y[(k, 0)] = x[0];
        y[(k, 1)] = x[1];
        let w = lpv.weights(x[0], Scheduling::Nearest).unwrap();
        let p = &lpv.points()[w.lower];
        let (a, b) = (p.a().clone(), p.b().clone());
        let g = vec![vec![u[(k, 0)], u[(k, 1)]]; sub];
        let xs = rk4_simulate(
            |s, gg, ds| {
                let dv = &a * DVector::from_column_slice(s) + &b * DVector::from_column_slice(gg);
                ds.copy_from_slice(dv.as_slice());
            },
            &x,
            &g,
            h / sub as f64,
        );
        x = xs[sub].clone();
    }
    (u, y)
}

#[test]
fn predictor_follows_a_piecewise_constant_speed_truth() {
    let h = 0.1;
    let n = 1600;
    let (u, y) = truth_record(n, h);
    // The record visits every grid cell.
    let (lo, hi) = (y.column(0).min(), y.column(0).max());
    assert!(lo < 0.6 && hi > 1.4, "u range {lo}..{hi}");
    let rec = ValidationRecord { h, u: &u, y: &y };

    let nearest = lpv().with_scheduling(Scheduling::Nearest);
    for k in [1, 10] {
        let yh = nearest.predict_k_step(&rec, k);
        let err = (yh.rows(k, n - k) - y.rows(k, n - k)).amax();
        assert!(err < 1e-9, "nearest, k = {k}: max error {err}");
    }
    let sim_err = (nearest.simulate(&rec) - &y).amax();
    assert!(sim_err < 1e-8, "nearest free run: {sim_err}");

    // Interpolation blends neighbours the truth does not blend: close but
    // not exact. A single LTI model (1.0 m/s) is clearly worse in surge.
    let fit = |p: &dyn Predictor| nrmse_fit_columns(&y, &p.simulate(&rec))[0].unwrap();
    let f_interp = fit(&lpv());
    let f_lti = fit(&lpv().points()[1]);
    assert!(
        f_interp > 0.9 && f_interp < 1.0 - 1e-6,
        "interpolated fit {f_interp}"
    );
    assert!(f_lti < 0.5, "LTI fit {f_lti} vs LPV {f_interp}");
}

/// Below the grid, within an extension: D̄ linear and the load quadratic
/// in speed (exact for the tangents of d_l·u + d_q·u|u|), M the lowest
/// point's even when the points' estimates of it differ; the discrete
/// model is the exact discretization there, not an extrapolated Φ.
#[test]
fn an_extension_extrapolates_damping_and_load_and_keeps_m() {
    let (d_l, d_q) = (300.0, 600.0);
    let points = GRID
        .iter()
        .map(|&x| {
            let m = DMatrix::from_row_slice(2, 2, &[5000.0 + 200.0 * x, 0.0, 0.0, 3000.0]);
            let d = DMatrix::from_row_slice(2, 2, &[d_l + 2.0 * d_q * x, 0.0, 150.0 * x, 400.0]);
            LinearVesselModel::new(vec![Dof::Surge, Dof::Yaw], m, d)
                .unwrap()
                .with_load(DVector::from_vec(vec![-d_q * x * x, 10.0 * x]))
                .unwrap()
        })
        .collect();
    let ext = Extension {
        from_mps: 0.2,
        to_mps: 1.5,
    };
    let lpv = LpvModel::new(GRID.to_vec(), points).unwrap();
    assert!(
        lpv.clone()
            .with_extension(Extension {
                from_mps: 0.6,
                to_mps: 1.5
            })
            .is_err()
    );
    let lpv = lpv.with_extension(ext).unwrap();
    let at = lpv.at(0.35, Scheduling::Interpolate).unwrap();
    assert_eq!(at.m(), lpv.points()[0].m());
    assert!((at.d_bar()[(0, 0)] - (d_l + 2.0 * d_q * 0.35)).abs() < 1e-9);
    assert!((at.d_bar()[(1, 0)] - 150.0 * 0.35).abs() < 1e-9);
    assert!((at.load()[0] + d_q * 0.35 * 0.35).abs() < 1e-9);
    assert!((at.load()[1] - 3.5).abs() < 1e-9);
    // Below the extension: its edge model; above the grid: held.
    assert_eq!(
        lpv.at(0.05, Scheduling::Interpolate).unwrap(),
        lpv.at(0.2, Scheduling::Interpolate).unwrap()
    );
    assert_eq!(
        &lpv.at(1.9, Scheduling::Interpolate).unwrap(),
        &lpv.points()[2]
    );
    // 0.35 m/s is one of the tabulated speeds (0.5 − 0.3·4/8).
    let d = lpv.discretize(0.1).unwrap();
    let exact = at.discretize(0.1).unwrap();
    let tab = d.at(0.35, Scheduling::Interpolate).unwrap();
    assert!((tab.phi() - exact.phi()).amax() < 1e-12);
    assert!((tab.offset() - exact.offset()).amax() < 1e-12);
    // Between tabulated speeds, close to the exact discretization.
    let mid = d.at(0.3, Scheduling::Interpolate).unwrap();
    let exact = lpv
        .at(0.3, Scheduling::Interpolate)
        .unwrap()
        .discretize(0.1)
        .unwrap();
    assert!((mid.phi() - exact.phi()).amax() < 1e-5);
    // Nearest scheduling ignores the extension.
    assert_eq!(&lpv.at(0.3, Scheduling::Nearest).unwrap(), &lpv.points()[0]);
}

#[test]
fn without_surge_the_first_grid_point_is_used() {
    let mk = |x: f64| {
        LinearVesselModel::new(
            vec![Dof::Sway, Dof::Yaw],
            DMatrix::from_row_slice(2, 2, &[7000.0, 100.0, 100.0, 3000.0]),
            DMatrix::from_row_slice(2, 2, &[900.0 * x, 0.0, 0.0, 500.0 * x]),
        )
        .unwrap()
    };
    let lpv = LpvModel::new(GRID.to_vec(), GRID.iter().map(|&x| mk(x)).collect()).unwrap();
    let u = DMatrix::from_fn(200, 2, |k, j| {
        if (k / (17 + 5 * j)) % 2 == 0 {
            300.0
        } else {
            -200.0
        }
    });
    let y = DMatrix::from_fn(200, 2, |k, j| 2.0 + (0.1 * k as f64 + j as f64).sin());
    let rec = ValidationRecord {
        h: 0.1,
        u: &u,
        y: &y,
    };
    let a = lpv.predict_k_step(&rec, 5);
    let b = lpv.points()[0].predict_k_step(&rec, 5);
    assert!((a.rows(5, 195) - b.rows(5, 195)).amax() < 1e-12);
    assert_eq!(lpv.output_names(), ["v", "r"]);
}

#[test]
fn inconsistent_grids_are_typed_errors() {
    let err = LpvModel::new(vec![1.0, 0.5], vec![point(1.0), point(0.5)]).unwrap_err();
    assert_eq!(
        err.to_string(),
        "LPV grid: grid_speeds must be strictly increasing, but grid_speeds[1] = 0.5 follows 1"
    );
    let err = LpvModel::new(vec![0.5], vec![point(0.5), point(1.0)]).unwrap_err();
    assert!(
        err.to_string()
            .contains("grid_speeds has 1 entries but points has 2"),
        "{err}"
    );
    let other = LinearVesselModel::new(
        vec![Dof::Surge, Dof::Sway],
        DMatrix::identity(2, 2),
        DMatrix::identity(2, 2),
    )
    .unwrap();
    let err = LpvModel::new(vec![0.5, 1.0], vec![point(0.5), other]).unwrap_err();
    assert_eq!(
        err.to_string(),
        "LPV grid: points[1] models [surge, sway] but points[0] models [surge, yaw]"
    );
    let err = LpvModel::new(vec![f64::NAN], vec![point(0.5)]).unwrap_err();
    assert_eq!(
        err.to_string(),
        "grid_speeds contains NaN or infinite entries"
    );
    assert!(LpvModel::new(vec![], vec![]).is_err());
}

/// A horizontal hull with diagonal M and linear damping, integrated with
/// its full C(ν)ν (Fossen 2011, eq. 6.43) through a turn at speed; the LPV
/// model of its exact linearizations at 0.5, 1.0, 1.5 m/s (D̄ = D +
/// J_C(M, u₀), no load: C(ν₀)ν₀ = 0) follows it only with C(δ)δ — the
/// blend of J_C is exact in u, the rest is the second-order term.
#[test]
fn second_order_coriolis_follows_a_turning_hull() {
    let (mu, mv, iz) = (400.0, 450.0, 300.0);
    let d = [120.0, 400.0, 500.0];
    let m = DMatrix::from_diagonal(&DVector::from_vec(vec![mu, mv, iz]));
    let dofs = vec![Dof::Surge, Dof::Sway, Dof::Yaw];
    let point = |u0: f64| {
        let d_bar = DMatrix::from_row_slice(
            3,
            3,
            &[
                d[0],
                0.0,
                0.0,
                0.0,
                d[1],
                mu * u0,
                0.0,
                (mv - mu) * u0,
                d[2],
            ],
        );
        LinearVesselModel::new(dofs.clone(), m.clone(), d_bar).unwrap()
    };
    let grid = vec![0.5, 1.0, 1.5];
    let linear = LpvModel::new(grid.clone(), grid.iter().map(|&u| point(u)).collect()).unwrap();
    let with_c = linear
        .clone()
        .with_second_order_coriolis(vec![m.clone(); 3])
        .unwrap();
    // The truth: M ν̇ + C(ν)ν + Dν = τ, a surge thrust and a yaw square wave.
    let (h, n, sub) = (0.1, 1200, 20);
    let tau = DMatrix::from_fn(n, 3, |k, j| match j {
        0 => 150.0,
        1 => 0.0,
        _ => 100.0 * if (k / 150) % 2 == 0 { 1.0 } else { -1.0 },
    });
    let mut y = DMatrix::zeros(n, 3);
    let mut x = vec![1.0, 0.0, 0.0];
    for k in 0..n {
        for j in 0..3 {
            y[(k, j)] = x[j];
        }
        let g = vec![vec![tau[(k, 0)], tau[(k, 1)], tau[(k, 2)]]; sub];
        let xs = rk4_simulate(
            |s, t, ds| {
                let (u, v, r) = (s[0], s[1], s[2]);
                // C(ν)ν of a diagonal 3-DOF M: (−m_v v r, m_u u r, (m_v − m_u) u v).
                let c = [-mv * v * r, mu * u * r, (mv - mu) * u * v];
                ds[0] = (t[0] - c[0] - d[0] * u) / mu;
                ds[1] = (t[1] - c[1] - d[1] * v) / mv;
                ds[2] = (t[2] - c[2] - d[2] * r) / iz;
            },
            &x,
            &g,
            h / sub as f64,
        );
        x = xs[sub].clone();
    }
    let (lo, hi) = (y.column(0).min(), y.column(0).max());
    assert!(
        lo > 0.5 && hi < 1.5,
        "the turn stays inside the grid: u {lo}..{hi}"
    );
    assert!(
        y.column(2).amax() > 0.15,
        "a real turn: r {}",
        y.column(2).amax()
    );
    let rec = ValidationRecord { h, u: &tau, y: &y };
    let fits = |p: &dyn Predictor| nrmse_fit_columns(&y, &p.simulate(&rec));
    let (fl, fc) = (fits(&linear), fits(&with_c));
    // Surge: the turn's centripetal m_v·v·r is what the linear model lacks.
    assert!(fc[0].unwrap() > 0.99, "with C(δ)δ: surge fit {:?}", fc[0]);
    assert!(
        fl[0].unwrap() < fc[0].unwrap() - 0.05,
        "without it surge should be clearly worse: {:?} vs {:?}",
        fl[0],
        fc[0]
    );
    for (j, f) in fc.iter().enumerate().skip(1) {
        assert!(f.unwrap() > 0.99, "with C(δ)δ: channel {j} fit {f:?}");
    }
    // Without surge the term cannot be placed.
    let yaw_only = LpvModel::new(
        vec![0.5],
        vec![
            LinearVesselModel::new(
                vec![Dof::Yaw],
                m.view((2, 2), (1, 1)).into_owned(),
                DMatrix::from_element(1, 1, 40.0),
            )
            .unwrap(),
        ],
    )
    .unwrap();
    assert!(
        yaw_only
            .with_second_order_coriolis(vec![DMatrix::from_element(1, 1, 70.0)])
            .is_err()
    );
}

/// A D_q far stiffer than the step (q|v|/m = 10⁴ s⁻¹ at 0.1 s: the
/// explicit force would overshoot zero by 10³ and diverge): the free run
/// still decays monotonically, as the closed form, never past zero.
#[test]
fn a_stiff_quadratic_damping_decays_without_overshoot() {
    let (m, d, q, v0) = (1.0, 1.0, 1.0e4, 1.0);
    let model = LinearVesselModel::new(
        vec![Dof::Roll],
        DMatrix::from_element(1, 1, m),
        DMatrix::from_element(1, 1, d),
    )
    .unwrap();
    let lpv = LpvModel::new(vec![0.0], vec![model])
        .unwrap()
        .with_quadratic_damping(vec![DVector::from_element(1, q)])
        .unwrap();
    let (h, n) = (0.1, 50);
    let truth = |t: f64| 1.0 / ((1.0 / v0 + q / d) * (d / m * t).exp() - q / d);
    let y = DMatrix::from_fn(n, 1, |k, _| truth(k as f64 * h));
    let u = DMatrix::zeros(n, 1);
    let sim = lpv
        .try_simulate(&ValidationRecord { h, u: &u, y: &y })
        .unwrap();
    for k in 1..n {
        assert!(
            sim[(k, 0)] > 0.0 && sim[(k, 0)] <= sim[(k - 1, 0)],
            "{k}: {}",
            sim[(k, 0)]
        );
        assert!(
            (sim[(k, 0)] - y[(k, 0)]).abs() <= 1e-9,
            "{k}: {} vs {}",
            sim[(k, 0)],
            y[(k, 0)]
        );
    }
}

/// Sway decaying under linear plus quadratic damping, m v̇ + d v + q|v|v = 0,
/// has the closed form 1/v(t) = (1/v₀ + q/d)·e^{(d/m)t} − q/d (v > 0, a
/// Bernoulli equation). A one-point LPV with D̄ = d and D_q = q follows it
/// from two release speeds (its linearly implicit step is exact for this
/// equation: to round-off); without D_q it cannot follow both.
#[test]
fn quadratic_damping_follows_the_closed_form_decay() {
    let (m, d, q) = (450.0, 120.0, 600.0);
    let model = LinearVesselModel::new(
        vec![Dof::Sway],
        DMatrix::from_element(1, 1, m),
        DMatrix::from_element(1, 1, d),
    )
    .unwrap();
    let linear = LpvModel::new(vec![0.0], vec![model]).unwrap();
    let quadratic = linear
        .clone()
        .with_quadratic_damping(vec![DVector::from_element(1, q)])
        .unwrap();
    let (h, n) = (0.1, 100);
    for v0 in [0.2, 1.0] {
        let truth = |t: f64| 1.0 / ((1.0 / v0 + q / d) * (d / m * t).exp() - q / d);
        let y = DMatrix::from_fn(n, 1, |k, _| truth(k as f64 * h));
        let u = DMatrix::zeros(n, 1);
        let rec = ValidationRecord { h, u: &u, y: &y };
        let sim = quadratic.try_simulate(&rec).unwrap();
        for k in 0..n {
            let err = (sim[(k, 0)] - y[(k, 0)]).abs();
            assert!(
                err <= 1e-9 * v0,
                "v0 {v0}, t {:.1}: {} vs {}",
                k as f64 * h,
                sim[(k, 0)],
                y[(k, 0)]
            );
        }
        // The linear model alone decays with time constant m/d throughout:
        // at t = 2 s it is far above the quadratic truth from 1 m/s.
        let lin = linear.try_simulate(&rec).unwrap();
        if v0 == 1.0 {
            assert!(
                lin[(20, 0)] > 1.5 * y[(20, 0)],
                "{} vs {}",
                lin[(20, 0)],
                y[(20, 0)]
            );
        }
    }
    assert!(
        LpvModel::new(
            vec![0.0],
            vec![
                LinearVesselModel::new(
                    vec![Dof::Sway],
                    DMatrix::from_element(1, 1, m),
                    DMatrix::from_element(1, 1, d)
                )
                .unwrap()
            ]
        )
        .unwrap()
        .with_quadratic_damping(vec![DVector::from_element(1, -1.0)])
        .is_err(),
        "a negative D_q feeds energy"
    );
}
