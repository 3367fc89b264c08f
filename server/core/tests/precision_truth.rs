//! Issue 15's proof for the ROV: the service's rule-based Surveyor plan
//! (`planning::generate_plan(surveyor_rov, surveyor_campaign(7))`, 127
//! runs) flown over 20 noise seeds by the INDEPENDENT truth
//! (`seatrial-truth`, its Surveyor-like vessel, one autopilot tuned once),
//! each campaign identified by the λ-filter method with its defaults; the
//! empirical spread of every parameter against the std
//! `design::predict_precision` predicts with a prior equal to the vessel.
//!
//! The goal — empirical spread within 1.5× of the predicted std
//! for ≥ 90 % of the parameters — is NOT met: 2 % (median
//! empirical/predicted 0.075). Not because the posterior is overconfident
//! (the std the identification reports on the truth's runs is above the
//! spread for every parameter, median spread/reported 0.014), but because
//! the λ posterior std — and so the prediction — is set by the pooled
//! residual variance, which here is deterministic equation error, not
//! noise: on the project's own simulator the noise-free std equals the
//! noisy one, and its own noise spread is 0.03× the std (median). Most of
//! that error comes from the plan's recursive (REC) runs: their roll/pitch
//! RATE references (PRBS ±0.15 rad/s) integrate to φ ≈ 1.4 rad, θ ≈ 1.2 rad
//! on the project's simulator and to an inverted vehicle (φ ≈ 3.1 rad) on
//! the truth. Without the REC family (`--no-recursive` in the example):
//! 37 % within 1.5×, median 0.90; the rest splits into misfit still in the
//! std (own-simulator spread/predicted median 0.56) and the truth's larger
//! noise spread (1.6× the project's simulator's: its autopilot acts on
//! noisy measurements, the project's on noise-free ν).
//! The goal is kept as an ignored test; the live test asserts what holds —
//! neither the prediction nor the reported std understates the spread.
//! `cargo run --release -p seatrial-core --example precision_table -- 20 --own [--no-recursive]`
//! prints the full table with the project's own simulator's noise spread.

#[path = "support/precision_truth.rs"]
mod precision_truth;

use std::sync::OnceLock;
use std::time::Instant;

use precision_truth::{
    Comparison, FACTOR, PlanVariant, compare, fly_seeds, predict, print_table, setup,
};

/// Noise seeds flown.
const SEEDS: u64 = 20;

fn comparisons() -> &'static Vec<Comparison> {
    static C: OnceLock<Vec<Comparison>> = OnceLock::new();
    C.get_or_init(|| {
        let t0 = Instant::now();
        let s = setup(&PlanVariant::default());
        let pred = predict(&s);
        let seeds: Vec<u64> = (1..=SEEDS).collect();
        let est = fly_seeds(&s, &seeds, 2);
        let (c, missing) = compare(&pred, &est);
        assert_eq!(
            missing, 0,
            "every predicted parameter is identified on the truth"
        );
        assert_eq!(c.len(), pred.total);
        print_table(&c, SEEDS as usize);
        eprintln!(
            "prediction and {SEEDS} truth campaigns of {} runs in {:.1} s",
            pred.runs,
            t0.elapsed().as_secs_f64()
        );
        c
    })
}

/// What holds: neither the prediction nor the std the identification
/// reports on the truth's runs understates the spread over noise seeds.
#[test]
fn predicted_and_reported_std_bound_the_truths_noise_spread() {
    let c = comparisons();
    let live: Vec<&Comparison> = c.iter().filter(|c| !c.structural_zero()).collect();
    assert!(live.len() > 250, "{} parameters compared", live.len());
    let bounded = live.iter().filter(|c| c.ratio() <= FACTOR).count();
    assert!(
        bounded as f64 >= 0.9 * live.len() as f64,
        "the prediction understates the spread of {} of {} parameters",
        live.len() - bounded,
        live.len()
    );
    let reported = live.iter().filter(|c| c.reported_ratio() <= FACTOR).count();
    assert!(
        reported as f64 >= 0.9 * live.len() as f64,
        "the identification's std understates the spread of {} of {} parameters",
        live.len() - reported,
        live.len()
    );
}

/// Issue 15's goal: empirical spread within 1.5× of the predicted std for
/// ≥ 90 % of the parameters. Not met (see the module docs).
#[test]
#[ignore = "issue 15's goal is not met (2 %): the λ posterior std is set by deterministic equation error (mostly the REC runs' large attitudes), ≈ 13× the noise spread (median)"]
fn empirical_spread_matches_the_predicted_std() {
    let c = comparisons();
    let live: Vec<&Comparison> = c.iter().filter(|c| !c.structural_zero()).collect();
    let within = live.iter().filter(|c| c.within()).count();
    assert!(
        within as f64 >= 0.9 * live.len() as f64,
        "{within} of {} parameters within {FACTOR}×",
        live.len()
    );
}
