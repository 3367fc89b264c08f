//! The filter engine on small systems with known truth.

use nalgebra::{DMatrix, DVector};

use super::super::*;
use crate::estimation::{Cancelled, NoProgress};
use crate::rng::SplitMix64;
use crate::simulation::integrate::simulate;

/// ẋ = −a·x + u, x measured; θ = [a].
struct FirstOrder {
    h_meas: DMatrix<f64>,
}

impl FirstOrder {
    fn new() -> Self {
        FirstOrder {
            h_meas: DMatrix::from_element(1, 1, 1.0),
        }
    }
}

impl ContinuousRunModel for FirstOrder {
    fn n_states(&self) -> usize {
        1
    }
    fn n_params(&self) -> usize {
        1
    }
    fn n_inputs(&self) -> usize {
        1
    }
    fn measurement_matrix(&self) -> &DMatrix<f64> {
        &self.h_meas
    }
    fn derivative(
        &self,
        x: &[f64],
        u: &[f64],
        th: &[f64],
        dx: &mut [f64],
        gx: &mut DMatrix<f64>,
        gt: &mut DMatrix<f64>,
    ) {
        dx[0] = -th[0] * x[0] + u[0];
        gx[(0, 0)] = -th[0];
        gt[(0, 0)] = -x[0];
    }
}

/// A random-binary input and the noisy response of ẋ = −a·x + u.
fn first_order_run(
    a: f64,
    h: f64,
    n: usize,
    noise: f64,
    seed: u64,
) -> (DMatrix<f64>, DMatrix<f64>) {
    let mut rng = SplitMix64::new(seed);
    let mut u = Vec::with_capacity(n);
    let mut level = 1.0;
    for k in 0..n {
        if k % 20 == 0 && rng.uniform() < 0.5 {
            level = -level;
        }
        u.push(vec![level]);
    }
    let xs = simulate(|x, u, dx| dx[0] = -a * x[0] + u[0], &[0.0], &u[..n - 1], h);
    let um = DMatrix::from_fn(n, 1, |k, _| u[k][0]);
    let z = DMatrix::from_fn(n, 1, |k, _| xs[k][0] + noise * rng.normal());
    (um, z)
}

fn first_order_settings(runs: usize, noise: f64) -> EkfSettings {
    EkfSettings {
        x0: vec![vec![0.0]; runs],
        theta0: vec![1.0],
        p0_x: vec![noise * noise],
        p0_theta: vec![1.0],
        q_x: vec![1e-10],
        q_theta: vec![0.0],
        r: vec![noise * noise],
    }
}

#[test]
fn first_order_parameter_is_recovered() {
    let (a, h, noise) = (0.4, 0.1, 0.02);
    let (u, z) = first_order_run(a, h, 2000, noise, 5);
    let model = Rk4 {
        model: FirstOrder::new(),
        h,
    };
    let out = parallel_ekf(
        &model,
        &[RunData { u: &u, z: &z }],
        &first_order_settings(1, noise),
        "test",
        &mut NoProgress,
    )
    .unwrap();
    let err = out.theta[0] - a;
    let std = out.theta_std()[0];
    assert!(err.abs() < 0.01 * a, "â = {} vs {a}", out.theta[0]);
    assert!(err.abs() < 4.0 * std, "error {err} vs σ {std}");
    // Innovations are white-ish with variance ≈ H·P·Hᵀ + R ≥ R.
    let e = &out.innovations[0];
    let var = e.rows(100, e.nrows() - 100).norm_squared() / (e.nrows() - 100) as f64;
    assert!(
        var / (noise * noise) > 0.9 && var / (noise * noise) < 1.2,
        "{var}"
    );
}

#[test]
fn parallel_runs_beat_a_single_run() {
    let (a, h, noise) = (0.4, 0.1, 0.05);
    let model = Rk4 {
        model: FirstOrder::new(),
        h,
    };
    let (mut se1, mut se2) = (0.0, 0.0);
    let seeds = 20;
    for seed in 0..seeds {
        let (u1, z1) = first_order_run(a, h, 400, noise, 100 + seed);
        let (u2, z2) = first_order_run(a, h, 400, noise, 200 + seed);
        let one = [RunData { u: &u1, z: &z1 }];
        let other = [RunData { u: &u2, z: &z2 }];
        let two = [RunData { u: &u1, z: &z1 }, RunData { u: &u2, z: &z2 }];
        let o1 = parallel_ekf(
            &model,
            &one,
            &first_order_settings(1, noise),
            "",
            &mut NoProgress,
        )
        .unwrap();
        let ob = parallel_ekf(
            &model,
            &other,
            &first_order_settings(1, noise),
            "",
            &mut NoProgress,
        )
        .unwrap();
        let o2 = parallel_ekf(
            &model,
            &two,
            &first_order_settings(2, noise),
            "",
            &mut NoProgress,
        )
        .unwrap();
        // The runs' information adds up: σ⁻² of N = 2 is the sum of the
        // single runs' σ⁻² (the prior's share is negligible).
        let (s1, sb, s2) = (o1.theta_std()[0], ob.theta_std()[0], o2.theta_std()[0]);
        let expected = (s1.powi(-2) + sb.powi(-2)).powf(-0.5);
        assert!(
            (s2 / expected - 1.0).abs() < 0.05,
            "σ N=2 {s2} vs {expected}"
        );
        assert!(s2 < s1.min(sb));
        se1 += (o1.theta[0] - a).powi(2);
        se2 += (o2.theta[0] - a).powi(2);
    }
    assert!(
        se2 < 0.8 * se1,
        "rms error N=2 {} vs N=1 {}",
        se2.sqrt(),
        se1.sqrt()
    );
}

/// ẋ1 = x2, ẋ2 = −θ1·x1 − θ2·x2 + u, x1 measured: a model whose Φ_θ and
/// cross-run covariances are all non-trivial.
struct MassSpring {
    h_meas: DMatrix<f64>,
}

impl ContinuousRunModel for MassSpring {
    fn n_states(&self) -> usize {
        2
    }
    fn n_params(&self) -> usize {
        2
    }
    fn n_inputs(&self) -> usize {
        1
    }
    fn measurement_matrix(&self) -> &DMatrix<f64> {
        &self.h_meas
    }
    fn derivative(
        &self,
        x: &[f64],
        u: &[f64],
        th: &[f64],
        dx: &mut [f64],
        gx: &mut DMatrix<f64>,
        gt: &mut DMatrix<f64>,
    ) {
        dx[0] = x[1];
        dx[1] = -th[0] * x[0] - th[1] * x[1] + u[0];
        gx.copy_from_slice(&[0.0, -th[0], 1.0, -th[1]]);
        gt.copy_from_slice(&[0.0, -x[0], 0.0, -x[1]]);
    }
}

/// Table 1 with dense matrices: Φ·P·Φᵀ + Q and (I−KH)P(I−KH)ᵀ + KRKᵀ.
fn dense_reference(
    model: &dyn RunModel,
    runs: &[RunData<'_>],
    s: &EkfSettings,
) -> (DVector<f64>, DMatrix<f64>) {
    let (n, p) = (model.n_states(), model.n_params());
    let nr = runs.len();
    let dim = nr * n + p;
    let h = model.measurement_matrix();
    let m = h.nrows();
    let mut xi = DVector::zeros(dim);
    let mut pm = DMatrix::zeros(dim, dim);
    for i in 0..nr {
        for c in 0..n {
            xi[i * n + c] = s.x0[i][c];
            pm[(i * n + c, i * n + c)] = s.p0_x[c];
        }
    }
    for c in 0..p {
        xi[nr * n + c] = s.theta0[c];
        pm[(nr * n + c, nr * n + c)] = s.p0_theta[c];
    }
    let steps = runs.iter().map(|r| r.z.nrows()).max().unwrap();
    for k in 0..steps {
        let active: Vec<usize> = (0..nr).filter(|&i| k < runs[i].z.nrows()).collect();
        let mm = active.len() * m;
        let mut hb = DMatrix::zeros(mm, dim);
        let mut rb = DMatrix::zeros(mm, mm);
        let mut e = DVector::zeros(mm);
        for (slot, &i) in active.iter().enumerate() {
            hb.view_mut((slot * m, i * n), (m, n)).copy_from(h);
            for j in 0..m {
                rb[(slot * m + j, slot * m + j)] = s.r[j];
                e[slot * m + j] = runs[i].z[(k, j)];
            }
        }
        e -= &hb * &xi;
        let sm = &hb * &pm * hb.transpose() + &rb;
        let kg = &pm * hb.transpose() * sm.try_inverse().unwrap();
        xi += &kg * e;
        let ikh = DMatrix::identity(dim, dim) - &kg * &hb;
        pm = &ikh * &pm * ikh.transpose() + &kg * &rb * kg.transpose();
        if k + 1 == steps {
            break;
        }
        let mut phi = DMatrix::identity(dim, dim);
        let mut q = DMatrix::zeros(dim, dim);
        let theta: Vec<f64> = xi.rows(nr * n, p).iter().copied().collect();
        for i in 0..nr {
            if k + 1 < runs[i].z.nrows() {
                let mut fx = DMatrix::zeros(n, n);
                let mut ft = DMatrix::zeros(n, p);
                let mut xn = vec![0.0; n];
                let x: Vec<f64> = xi.rows(i * n, n).iter().copied().collect();
                let u: Vec<f64> = runs[i].u.row(k).iter().copied().collect();
                model.transition(&x, &u, &theta, &mut xn, &mut fx, &mut ft);
                xi.rows_mut(i * n, n).copy_from_slice(&xn);
                phi.view_mut((i * n, i * n), (n, n)).copy_from(&fx);
                phi.view_mut((i * n, nr * n), (n, p)).copy_from(&ft);
                for c in 0..n {
                    q[(i * n + c, i * n + c)] = s.q_x[c];
                }
            }
        }
        for c in 0..p {
            q[(nr * n + c, nr * n + c)] = s.q_theta[c];
        }
        pm = &phi * &pm * phi.transpose() + q;
    }
    (xi, pm)
}

#[test]
fn blockwise_filter_equals_dense_table_1() {
    let h = 0.05;
    let model = Rk4 {
        model: MassSpring {
            h_meas: DMatrix::from_row_slice(1, 2, &[1.0, 0.0]),
        },
        h,
    };
    let mut rng = SplitMix64::new(9);
    // Three runs of different lengths: the shorter ones are held at the end.
    let lens = [300, 220, 260];
    let data: Vec<(DMatrix<f64>, DMatrix<f64>)> = lens
        .iter()
        .map(|&n| {
            let u = DMatrix::from_fn(n, 1, |k, _| ((k / 25) as f64).sin().signum());
            let z = DMatrix::from_fn(n, 1, |_, _| 0.01 * rng.normal());
            (u, z)
        })
        .collect();
    let runs: Vec<RunData<'_>> = data.iter().map(|(u, z)| RunData { u, z }).collect();
    let s = EkfSettings {
        x0: vec![vec![0.0, 0.0], vec![0.1, 0.0], vec![0.0, -0.1]],
        theta0: vec![2.0, 0.5],
        p0_x: vec![1e-2, 1e-2],
        p0_theta: vec![1.0, 0.5],
        q_x: vec![1e-6, 1e-5],
        q_theta: vec![1e-8, 0.0],
        r: vec![1e-4],
    };
    let out = parallel_ekf(&model, &runs, &s, "", &mut NoProgress).unwrap();
    let (xi, pm) = dense_reference(&model, &runs, &s);
    let scale = pm.abs().max();
    assert!((&out.covariance - &pm).abs().max() < 1e-10 * scale);
    assert!((out.covariance.transpose() - &out.covariance).abs().max() == 0.0);
    for c in 0..2 {
        assert!((out.theta[c] - xi[6 + c]).abs() < 1e-10 * xi[6 + c].abs());
    }
    // Cross-run blocks are really there (runs correlate through θ).
    assert!(out.covariance.view((0, 2), (2, 2)).abs().max() > 1e-8);
}

#[test]
fn bad_input_names_the_field_and_cancellation_stops() {
    let model = Rk4 {
        model: FirstOrder::new(),
        h: 0.1,
    };
    let (u, z) = first_order_run(0.4, 0.1, 300, 0.01, 1);
    let run = [RunData { u: &u, z: &z }];
    let s = first_order_settings(1, 0.01);
    assert_eq!(
        parallel_ekf(
            &model,
            &[],
            &first_order_settings(0, 0.01),
            "",
            &mut NoProgress
        ),
        Err(EkfError::NoRuns)
    );
    let mut bad_z = z.clone();
    bad_z[(17, 0)] = f64::NAN;
    let err = parallel_ekf(
        &model,
        &[RunData { u: &u, z: &bad_z }],
        &s,
        "",
        &mut NoProgress,
    );
    assert_eq!(
        err,
        Err(EkfError::NotFinite {
            field: "runs[0].z[17]".into()
        })
    );
    let short = u.rows(0, 10).into_owned();
    match parallel_ekf(
        &model,
        &[RunData { u: &short, z: &z }],
        &s,
        "",
        &mut NoProgress,
    ) {
        Err(EkfError::Shape { field, .. }) => assert_eq!(field, "runs[0].u"),
        other => panic!("{other:?}"),
    }
    let mut s_bad = s.clone();
    s_bad.r[0] = 0.0;
    assert_eq!(
        parallel_ekf(&model, &run, &s_bad, "", &mut NoProgress),
        Err(EkfError::NonPositive {
            field: "r[0]".into(),
            value: 0.0
        })
    );
    let mut s_bad = s.clone();
    s_bad.q_theta[0] = -1.0;
    assert!(matches!(
        parallel_ekf(&model, &run, &s_bad, "", &mut NoProgress),
        Err(EkfError::NonPositive { field, .. }) if field == "q_theta[0]"
    ));
    // Cancelled at the second report (sample 100).
    let mut calls = 0;
    let mut stop = |_f: f64, _s: &str| {
        calls += 1;
        if calls > 1 { Err(Cancelled) } else { Ok(()) }
    };
    assert_eq!(
        parallel_ekf(&model, &run, &s, "", &mut stop),
        Err(EkfError::Cancelled)
    );
}
