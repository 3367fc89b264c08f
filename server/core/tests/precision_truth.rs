//! Issue 15's proof for the ROV: the service's rule-based Surveyor plan
//! (`planning::generate_plan(surveyor_rov, surveyor_campaign(7))`, 127
//! runs), and the campaign `design::design_campaign` designs in its hours
//! (85 runs), each flown over 20 noise seeds by the INDEPENDENT truth
//! (`seatrial-truth`, its Surveyor-like vessel, one autopilot tuned once),
//! each campaign identified by the λ-filter method with its defaults; the
//! empirical spread of every parameter against the std
//! `design::predict_precision` predicts with a prior equal to the vessel.
//!
//! The team declares its autopilot in the vessel profile (`autopilot`: the
//! PI gains of u, v, w, r, the PD gains of φ, θ, the nominal W − B and
//! z_G W − z_B B it feeds forward — the truth's `ControllerConfig` as plain
//! numbers), and the prediction flies the plan through those loops in the
//! project's own simulator, reading noisy sensors; the truth's 20 Hz
//! autopilot, plant and 10 Hz logger are its own.
//!
//! Measured (20 seeds, the service's default identification with quadratic
//! damping): 240 of 262 parameters (91.6 %; M fitted symmetric: an
//! off-diagonal pair is one parameter) have an empirical spread within
//! 1.5× of the prediction, median empirical/predicted 1.02; on the
//! designed campaign 237 of 261 (90.8 %), median 0.97. Without the
//! declared autopilot the prediction flies the project's generic loops
//! (designed from the limits, ≈ 9× the truth's roll gain) and only 57 % are
//! within 1.5× (median 0.77): how stiffly each loop holds its DOF decides
//! how much sensor noise becomes thrust and motion. The std the
//! identification reports on the truth's runs is ≈ 11× the spread (median):
//! the linear LPV model's misfit to the truth's nonlinear plant, which the
//! prediction shows as the *reported* std beside its spread.
//! `cargo run --release -p seatrial-core --example precision_table -- 20
//! [--generic-autopilot] [--linear] [--tune-seed N]` prints the table.

#[path = "support/precision_truth.rs"]
mod precision_truth;

use std::sync::OnceLock;
use std::time::Instant;

use precision_truth::{
    Comparison, FACTOR, PlanVariant, compare, fly_seeds, predict, print_table, setup,
};

/// Noise seeds flown.
const SEEDS: u64 = 20;

/// The prediction of `variant`'s plan against its flights on the truth.
fn compare_variant(variant: &PlanVariant) -> Vec<Comparison> {
    let t0 = Instant::now();
    let s = setup(variant);
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
}

/// The rule-based Surveyor plan.
fn comparisons() -> &'static Vec<Comparison> {
    static C: OnceLock<Vec<Comparison>> = OnceLock::new();
    C.get_or_init(|| compare_variant(&PlanVariant::default()))
}

/// Share of the live parameters within [`FACTOR`]× and their count.
fn within_share(c: &[Comparison]) -> (usize, usize) {
    let live: Vec<&Comparison> = c.iter().filter(|c| !c.structural_zero()).collect();
    (live.iter().filter(|c| c.within()).count(), live.len())
}

/// The prediction is centred on the truth's spread (median
/// empirical/predicted within [1/1.2, 1.2]) and rarely promises more
/// precision than the truth gives (spread ≤ 1.5× the prediction for ≥ 90 %
/// of the parameters); the std the identification reports on the truth's
/// runs never understates the spread.
#[test]
fn prediction_is_centred_and_does_not_overstate_the_truths_precision() {
    let c = comparisons();
    let live: Vec<&Comparison> = c.iter().filter(|c| !c.structural_zero()).collect();
    assert!(live.len() > 230, "{} parameters compared", live.len());
    let mut ratios: Vec<f64> = live.iter().map(|c| c.ratio()).collect();
    ratios.sort_by(f64::total_cmp);
    let median = ratios[ratios.len() / 2];
    assert!(
        (1.0 / 1.2..=1.2).contains(&median),
        "median empirical/predicted {median}"
    );
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
/// ≥ 90 % of the parameters, on the rule-based plan.
#[test]
fn empirical_spread_matches_the_predicted_std() {
    let (within, live) = within_share(comparisons());
    assert!(
        within as f64 >= 0.9 * live as f64,
        "{within} of {live} parameters within {FACTOR}×"
    );
}

/// The same on the campaign `design::design_campaign` designs within the
/// rule-based plan's hours (85 runs; prior: the source documents' vessel).
#[test]
fn on_the_designed_campaign_too() {
    let c = compare_variant(&PlanVariant {
        designed: true,
        ..PlanVariant::default()
    });
    let (within, live) = within_share(&c);
    assert!(live > 230, "{live} parameters compared");
    assert!(
        within as f64 >= 0.9 * live as f64,
        "{within} of {live} parameters within {FACTOR}×"
    );
}

/// The autopilot the service infers from a first dive's logs
/// (`identification::autopilot_fit`) is the truth's: every gain and the
/// feed-forward within 2 % (the PI gains' integral is summed at the log's
/// 10 Hz, the autopilot's at 20 Hz).
#[test]
fn the_truths_autopilot_is_inferred_from_a_first_dive() {
    let s = setup(&PlanVariant::default());
    let fit = precision_truth::infer_truth_autopilot(&s, 1000);
    let c = &s.controller;
    let close = |got: f64, want: f64, what: &str| {
        assert!(
            (got - want).abs() <= 0.02 * want.abs(),
            "{what}: inferred {got:.5e}, the truth's {want:.5e}"
        );
    };
    for l in &fit.loops {
        let i = l.dof.index();
        let name = l.dof.name();
        close(l.gains.kp, c.kp[i], &format!("{name} kp"));
        if c.ki[i] > 0.0 {
            close(l.gains.ki, c.ki[i], &format!("{name} ki"));
        } else {
            // No integral: what is fitted is noise, far below K_p.
            assert!(l.gains.ki < 1e-3 * c.kp[i], "{name} ki {}", l.gains.ki);
        }
        match l.gains.kd {
            Some(kd) => close(kd, c.kd[i], &format!("{name} kd")),
            None => assert!(!matches!(i, 3 | 4), "{name} is an attitude loop"),
        }
        assert!(l.r_squared > 0.99, "{name} R² {}", l.r_squared);
    }
    let g = fit
        .autopilot
        .restoring_feed_forward
        .expect("ĝ is fed forward");
    close(g.w_minus_b, c.nominal_w_minus_b, "W − B");
    close(
        g.zg_w_minus_zb_b,
        c.nominal_zg_w_minus_zb_b,
        "z_G W − z_B B",
    );
}
