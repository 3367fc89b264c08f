//! True-model predictions on logged runs.

use nalgebra::{DMatrix, Vector6};
use seatrial_truth::rng::Rng;
use seatrial_truth::{
    CampaignSpec, Log, Plant, State, Vessel, fly_campaign, free_run, free_run_restarted,
    predict_k_step, true_predictions,
};

/// An open-loop 10 Hz log of the plant integrated finely (h = 1 ms) under
/// τ held over each interval: a log the predictions must reproduce.
fn open_loop_log(v: &Vessel, rows: usize, seed: u64) -> (Log, DMatrix<f64>) {
    let plant = Plant::new(v);
    let mut rng = Rng::new(seed);
    let mut x = State::new(
        Vector6::new(0.0, 0.0, 40.0, 0.0, 0.0, 1.0),
        Vector6::new(0.8, 0.0, 0.0, 0.0, 0.0, 0.0),
    );
    let trim = v.hydrodynamic_force(&x.nu) + v.restoring(&x.eta);
    let m = v.m();
    let (mut t, mut tau, mut nu, mut eta) = (vec![], vec![], vec![], vec![]);
    for k in 0..rows {
        let u = trim + Vector6::from_fn(|i, _| 0.3 * m[(i, i)] * rng.range(-1.0, 1.0));
        t.push(100.0 + k as f64 * 0.1);
        tau.push(u);
        nu.push(x.nu);
        eta.push(x.eta);
        x = plant.advance(&x, &u, 0.1, 0.001);
    }
    let mat = |r: &[Vector6<f64>]| DMatrix::from_fn(r.len(), 6, |i, j| r[i][j]);
    let log = Log {
        t,
        tau: mat(&tau),
        nu: mat(&nu),
        eta: mat(&eta),
    };
    let truth = log.nu.clone();
    (log, truth)
}

#[test]
fn predictions_reproduce_a_noise_free_open_loop_log() {
    let v = Vessel::draw(6);
    let (log, truth) = open_loop_log(&v, 200, 1);
    let scale = truth.abs().max();
    let p = true_predictions(&v, &log);
    for (name, m) in [
        ("1-step", &p.one_step),
        ("10-step", &p.k_step),
        ("restarted", &p.restarted_10s),
        ("free run", &p.free_run),
    ] {
        let err = (m - &truth).abs().max();
        assert!(err < 1e-7 * scale, "{name}: error {err:e}");
    }
    // rows without a prediction hold the measurement; others are predictions
    let k3 = predict_k_step(&v, &log, 3);
    assert_eq!(k3.rows(0, 3), log.nu.rows(0, 3));
    // a different τ history changes them (the log's τ is really used)
    let mut shifted = log.clone();
    shifted.tau.row_mut(50).add_scalar_mut(20.0);
    let moved = (predict_k_step(&v, &shifted, 1) - &p.one_step).abs();
    assert!(moved.row(51).max() > 1e-3 && moved.row(52).max() == 0.0);
    let fr = free_run(&v, &shifted);
    assert!((fr.row(150) - p.free_run.row(150)).abs().max() > 1e-4);
    let rs = free_run_restarted(&v, &shifted, 10.0);
    assert_eq!(
        rs.row(100),
        log.nu.row(100),
        "restart rows are measured states"
    );
}

fn rms(m: &DMatrix<f64>, j: usize, from: usize) -> f64 {
    let c = m.column(j);
    let n = (m.nrows() - from) as f64;
    (c.rows(from, m.nrows() - from).norm_squared() / n).sqrt()
}

#[test]
fn true_model_predicts_a_flown_validation_run() {
    let v = Vessel::draw(7);
    let spec = CampaignSpec {
        grid_speeds: vec![1.0],
        dynamic_dofs: vec![],
        ..CampaignSpec::default()
    };
    let c = fly_campaign(&v, &spec, 7);
    let run = c.validation_runs()[0];
    let log = &run.log;
    let p = true_predictions(&v, log);
    let n = log.t.len();
    // persistence (ν̂_j = ν_{j−10}) is the bar a model must beat
    let persistence = DMatrix::from_fn(n, 6, |i, j| log.nu[(i.saturating_sub(10), j)]);
    for j in 0..6 {
        let e1 = rms(&(&p.one_step - &log.nu), j, 1);
        let e10 = rms(&(&p.k_step - &log.nu), j, 10);
        let ep = rms(&(&persistence - &log.nu), j, 10);
        let er = rms(&(&p.restarted_10s - &log.nu), j, 0);
        let ef = rms(&(&p.free_run - &log.nu), j, 0);
        let spread = run.truth.nu.column(j).variance().sqrt();
        let sigma = c.spec.noise.nu_std(j);
        println!(
            "ν_{j}: 1-step {e1:.4}, 10-step {e10:.4}, restarted {er:.4}, free {ef:.4}, persistence {ep:.4}, std {spread:.4}, σ {sigma}"
        );
        assert!(
            e10 < 0.5 * ep,
            "ν_{j}: the true model must beat persistence"
        );
        // the open-loop vessel is stable, so even free runs stay on track
        assert!(
            er < 0.25 * spread && ef < 0.5 * spread,
            "ν_{j}: {er} / {ef} of {spread}"
        );
        assert!(e1 < 4.0 * sigma + 0.2 * e10, "ν_{j}: 1-step error {e1}");
    }
}
