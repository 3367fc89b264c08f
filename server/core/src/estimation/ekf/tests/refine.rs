//! Prediction-error refinement on the supply vessel simulated from the
//! paper's numbers (the crate's own truth, N = 2 per manoeuvre).

use nalgebra::DMatrix;

use super::super::*;
use crate::estimation::NoProgress;
use crate::simulation::dp_ship::{DpRun, DpShip, TrialConfig, paper, simulate_campaign};

fn data(runs: &[DpRun]) -> Vec<RunData<'_>> {
    runs.iter()
        .map(|r| RunData { u: &r.u, z: &r.eta })
        .collect()
}

/// From every θ″ 20 % off, the nine θ″ are refined jointly on all six runs
/// to within 3 calibrated std of the truth, V falls, the std is never below
/// the Cramér–Rao bound, and the truth predicts a fresh run better than
/// the start did.
#[test]
fn refinement_recovers_the_supply_vessel_from_a_wrong_start() {
    let (truth, trial, runs, cfg) = super::supply_campaign(4242);
    let start = paper::THETA.map(|t| 1.2 * t);
    let all: Vec<usize> = (0..9).collect();
    let r = refine_dp_ship(
        &cfg,
        &data(&runs),
        &all,
        &start,
        &RefineSettings::default(),
        &mut NoProgress,
    )
    .unwrap();
    let fit = &r.refinement;
    assert!(fit.converged, "{} steps", fit.iterations);
    assert!(fit.nll < fit.nll_start);
    assert!(
        (fit.variance_ratio - 1.0).abs() < 0.1,
        "{}",
        fit.variance_ratio
    );
    for p in 0..9 {
        let z = (r.theta[p] - paper::THETA[p]) / r.theta_std[p];
        assert!(z.abs() < 3.0, "θ″{}: z {z:.2}", p + 1);
        assert!(fit.inflation[p] >= 1.0);
        assert!(r.theta_std[p] >= fit.crb_cov[(p, p)].sqrt() * (1.0 - 1e-12));
    }
    let info = &fit.pass.info;
    assert!((info - info.transpose()).abs().max() < 1e-9 * info.abs().max());
    assert!(info.clone().cholesky().is_some());

    let fresh = simulate_campaign(&truth, &trial, paper::SAMPLES_PER_RUN, 99);
    let held = data(&fresh[2..4]);
    let at = |theta: &[f64; 9]| dp_predictor_nll(&cfg, &held, theta).unwrap();
    assert!(at(&r.theta) < at(&start));
}

/// Bad requests name their field; a pass never returns non-finite numbers.
#[test]
fn refinement_refuses_bad_requests() {
    let trial = TrialConfig::supply_vessel();
    let runs = simulate_campaign(&DpShip::supply_vessel(), &trial, 80, 1);
    let cfg = DpIdentConfig::supply_vessel(&trial);
    let d = data(&runs);
    let err = |free: &[usize], settings: RefineSettings| {
        refine_dp_ship(&cfg, &d, free, &paper::THETA, &settings, &mut NoProgress).unwrap_err()
    };
    let field = |e: EkfError| match e {
        EkfError::Invalid { field, .. } | EkfError::Shape { field, .. } => field,
        other => panic!("{other:?}"),
    };
    assert_eq!(field(err(&[], RefineSettings::default())), "free");
    assert_eq!(field(err(&[9], RefineSettings::default())), "free");
    let none = RefineSettings {
        max_iterations: 0,
        ..Default::default()
    };
    assert_eq!(field(err(&[0], none)), "max_iterations");
    let u = DMatrix::zeros(10, 6);
    let z = DMatrix::zeros(10, 2);
    let bad = [RunData { u: &u, z: &z }];
    let e = refine_dp_ship(
        &cfg,
        &bad,
        &[0],
        &paper::THETA,
        &RefineSettings::default(),
        &mut NoProgress,
    )
    .unwrap_err();
    assert_eq!(field(e), "runs[0].z");
    let nll = dp_predictor_nll(&cfg, &d, &paper::THETA).unwrap();
    assert!(nll.is_finite());
}

/// x(k+1) = a·x + θ₁·u₁ + θ₂·u₂, z = x: the gain and S do not depend on θ
/// and e is affine in θ, so V is exactly quadratic in θ and the pass's
/// gradient and Gauss–Newton Hessian are its exact derivatives.
struct InputGains {
    a: f64,
    h: DMatrix<f64>,
}

impl RunModel for InputGains {
    fn n_states(&self) -> usize {
        1
    }
    fn n_params(&self) -> usize {
        2
    }
    fn n_inputs(&self) -> usize {
        2
    }
    fn measurement_matrix(&self) -> &DMatrix<f64> {
        &self.h
    }
    fn transition(
        &self,
        x: &[f64],
        u: &[f64],
        theta: &[f64],
        x_next: &mut [f64],
        phi_x: &mut DMatrix<f64>,
        phi_theta: &mut DMatrix<f64>,
    ) {
        x_next[0] = self.a * x[0] + theta[0] * u[0] + theta[1] * u[1];
        phi_x[(0, 0)] = self.a;
        phi_theta[(0, 0)] = u[0];
        phi_theta[(0, 1)] = u[1];
    }
}

#[test]
fn sensitivities_are_the_exact_derivatives_of_a_quadratic_criterion() {
    let model = InputGains {
        a: 0.9,
        h: DMatrix::from_element(1, 1, 1.0),
    };
    let mut rng = crate::rng::SplitMix64::new(11);
    let truth = [0.5, -0.2];
    let runs: Vec<(DMatrix<f64>, DMatrix<f64>)> = (0..2)
        .map(|_| {
            let n = 300;
            let u = DMatrix::from_fn(n, 2, |_, _| rng.normal());
            let mut x = 0.0;
            let z = DMatrix::from_fn(n, 1, |k, _| {
                let out = x + 0.05 * rng.normal();
                x = 0.9 * x + truth[0] * u[(k, 0)] + truth[1] * u[(k, 1)] + 0.01 * rng.normal();
                out
            });
            (u, z)
        })
        .collect();
    let data: Vec<RunData<'_>> = runs.iter().map(|(u, z)| RunData { u, z }).collect();
    let noise = PredictorNoise {
        x0: vec![vec![0.0]; 2],
        p0_x: vec![1e-2],
        q_x: vec![1e-4],
        r: vec![0.0025],
    };
    let theta = [0.3, 0.1];
    let pass = predictor_pass(&model, &data, &noise, &theta, true).unwrap();
    let nll = |t: [f64; 2]| {
        predictor_pass(&model, &data, &noise, &t, false)
            .unwrap()
            .nll
    };
    let d = 1e-4;
    for j in 0..2 {
        let (mut up, mut down) = (theta, theta);
        up[j] += d;
        down[j] -= d;
        // V quadratic: the central difference is exact up to rounding.
        let fd = (nll(up) - nll(down)) / (2.0 * d);
        assert!(
            (pass.grad[j] - fd).abs() < 1e-6 * pass.grad[j].abs().max(1.0),
            "g{j}: {} vs {fd}",
            pass.grad[j]
        );
        let g_up = predictor_pass(&model, &data, &noise, &up, true)
            .unwrap()
            .grad;
        let g_down = predictor_pass(&model, &data, &noise, &down, true)
            .unwrap()
            .grad;
        for i in 0..2 {
            let h = (g_up[i] - g_down[i]) / (2.0 * d);
            assert!(
                (pass.info[(i, j)] - h).abs() < 1e-6 * pass.info[(i, j)].abs().max(1.0),
                "J{i}{j}"
            );
        }
    }
    // One Gauss–Newton step from any start lands on the minimum.
    let step = pass.info.clone().lu().solve(&pass.grad).unwrap();
    let min = [theta[0] - step[0], theta[1] - step[1]];
    let at_min = predictor_pass(&model, &data, &noise, &min, true).unwrap();
    assert!(at_min.grad.norm() < 1e-8 * pass.grad.norm());
    // And it is near the truth, within a few Cramér–Rao std.
    let cov = at_min.info.clone().try_inverse().unwrap();
    for j in 0..2 {
        assert!(
            (min[j] - truth[j]).abs() < 4.0 * cov[(j, j)].sqrt(),
            "θ{j}: {} vs {}",
            min[j],
            truth[j]
        );
    }
}
