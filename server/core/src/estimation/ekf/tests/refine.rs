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
