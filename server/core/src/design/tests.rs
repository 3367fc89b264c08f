//! Predicted precision on the project's own simulators: the mechanics
//! (every std finite, the weakest named, errors naming fields) and one
//! analytic property — the Fisher information of independent runs adds, so
//! flying every experiment twice divides each std by √2.

use super::*;
use crate::estimation::NoProgress;
use crate::identification::RunInput;
use crate::planning::examples::{
    supply_vessel, supply_vessel_trial_campaign, surveyor_campaign, surveyor_rov,
};
use crate::planning::generate_plan;
use crate::planning::{ExperimentFamily, Plan, VesselProfile};
use crate::simulation::rov::RovTruth;

fn rov_prediction(repetitions: Option<u32>) -> PrecisionPrediction {
    let profile = surveyor_rov();
    let mut spec = surveyor_campaign(7);
    spec.repetitions = repetitions;
    let plan = generate_plan(&profile, &spec).unwrap();
    let prior = Prior::reference(&profile).unwrap();
    predict_precision(
        &profile,
        &plan,
        &prior,
        PriorSource::Reference,
        &PredictSettings::default(),
        &mut NoProgress,
    )
    .unwrap()
}

#[test]
fn rov_prediction_is_finite_and_names_the_weakest() {
    let p = rov_prediction(None);
    eprintln!(
        "{} of {} determined, {} limited by structure, {:.1} h; weakest {:#?}",
        p.determined,
        p.total,
        p.parameters.iter().filter(|r| r.structure_limited).count(),
        p.ship_hours,
        p.weakest
    );
    assert_eq!(p.realisations, 20);
    assert!(p.parameters.iter().all(|r| r.reported_std.is_some()));
    assert_eq!(p.method, "lambda_kf");
    assert!(p.total > 100, "{} parameters", p.total);
    for r in &p.parameters {
        assert!(r.expected_value.is_finite(), "{}", r.symbol);
        if let Some(sd) = r.predicted_std {
            assert!(sd.is_finite() && sd >= 0.0, "{}: {sd}", r.symbol);
        }
    }
    // Every inertia diagonal is determined by the thesis plan.
    for r in p.parameters.iter().filter(|r| r.group == "M") {
        let diag = ["surge", "sway", "heave", "roll", "pitch", "yaw"]
            .iter()
            .any(|d| r.symbol == format!("M[{d},{d}]"));
        if diag {
            assert!(
                r.determined,
                "{} at {:?}: {:?}",
                r.symbol, r.grid_speed_mps, r.relative_std
            );
        }
    }
    assert!(!p.weakest.is_empty() && p.weakest.len() <= WEAKEST_SHOWN);
    assert!(
        p.geometric_mean_relative_std
            .is_some_and(|g| g > 0.0 && g.is_finite())
    );
    // The Surveyor profile declares no autopilot: the prediction says what
    // it flew instead.
    assert!(
        p.notes.iter().any(|n| n.contains("declares no autopilot")),
        "{:#?}",
        p.notes
    );
}

fn dp_prediction(repetitions: u32) -> PrecisionPrediction {
    let profile = supply_vessel();
    let mut spec = supply_vessel_trial_campaign(3);
    spec.repetitions = Some(repetitions);
    let plan = generate_plan(&profile, &spec).unwrap();
    let prior = Prior::reference(&profile).unwrap();
    // One realisation: the refinement's Cramér–Rao std, free of the spread
    // estimate's own sampling error.
    predict_precision(
        &profile,
        &plan,
        &prior,
        PriorSource::Reference,
        &PredictSettings {
            realisations: 1,
            ..PredictSettings::default()
        },
        &mut NoProgress,
    )
    .unwrap()
}

/// Independent runs add their Fisher information: twice the runs of every
/// manoeuvre, √2 smaller stds (within the noise of one realisation).
#[test]
fn dp_std_falls_by_root_two_when_every_manoeuvre_is_flown_twice() {
    let (one, two) = (dp_prediction(2), dp_prediction(4));
    assert_eq!(one.method, "parallel_ekf");
    assert_eq!(one.total, 9);
    for (a, b) in one.parameters.iter().zip(&two.parameters) {
        let ratio = a.predicted_std.unwrap() / b.predicted_std.unwrap();
        eprintln!(
            "{}: {:.3e} → {:.3e}, ratio {ratio:.3}",
            a.symbol,
            a.predicted_std.unwrap(),
            b.predicted_std.unwrap()
        );
        assert!(
            (ratio / 2f64.sqrt() - 1.0).abs() < 0.2,
            "{}: ratio {ratio}",
            a.symbol
        );
    }
    assert!(two.ship_hours > one.ship_hours);
}

#[test]
fn rough_profile_prior_flies_and_predicts() {
    for profile in [surveyor_rov(), supply_vessel()] {
        let prior = Prior::from_profile(&profile).unwrap();
        match (&prior, profile.kind) {
            (Prior::Rov(t), crate::planning::vessel::VesselKind::Rov6) => {
                assert!(t.m.cholesky().is_some());
            }
            (Prior::Dp(s), crate::planning::vessel::VesselKind::Dp3) => {
                assert!(s.theta().iter().all(|v| v.is_finite()));
            }
            _ => panic!("prior of the wrong kind"),
        }
    }
}

/// The information of independent runs adds: flying every experiment twice
/// lowers the D criterion by ln 2 (the same schedules flown again give
/// exactly twice the Gram matrices; the planner's repetitions differ only
/// in their PRBS seeds, so within a few per cent).
#[test]
fn repeating_the_plan_lowers_the_d_criterion_by_ln_2() {
    use super::information::{InformationCache, Scaling, d_criterion, plan_information};
    let profile = surveyor_rov();
    let spec = surveyor_campaign(7);
    let plan = generate_plan(&profile, &spec).unwrap();
    let Prior::Rov(truth) = Prior::reference(&profile).unwrap() else {
        panic!("the Surveyor's prior is an ROV")
    };
    let mut cache = InformationCache::default();
    let info = plan_information(&profile, &plan, &truth, &mut cache).unwrap();
    let flown = cache.flown;
    let scaling = Scaling::of(&info, &plan.grid_speeds()).unwrap();
    let d1 = d_criterion(&profile, &info, &scaling).unwrap();
    // Flying the same plan again is served from the cache.
    let again = plan_information(&profile, &plan, &truth, &mut cache).unwrap();
    assert_eq!(cache.flown, flown);
    assert_eq!(d_criterion(&profile, &again, &scaling).unwrap(), d1);
    let mut twice = spec.clone();
    twice.repetitions = Some(2);
    let plan2 = generate_plan(&profile, &twice).unwrap();
    let info2 = plan_information(&profile, &plan2, &truth, &mut cache).unwrap();
    let d2 = d_criterion(&profile, &info2, &scaling).unwrap();
    let drop = d1 - d2;
    assert!(
        (drop - std::f64::consts::LN_2).abs() < 0.03 * std::f64::consts::LN_2,
        "D fell by {drop}, expected ln 2"
    );
}

/// A two-speed Surveyor campaign: its plan, the reference prior, and the
/// plan's runs flown with sensor noise as the campaign's logs.
fn two_speed_campaign() -> (VesselProfile, Plan, Box<RovTruth>, Vec<RunInput>) {
    use crate::simulation::trials::{TrialSettings, fly_campaign};
    let profile = surveyor_rov();
    let mut spec = surveyor_campaign(3);
    spec.grid.speeds = vec![0.0, 1.5];
    let plan = generate_plan(&profile, &spec).unwrap();
    let Prior::Rov(truth) = Prior::reference(&profile).unwrap() else {
        panic!("an ROV prior")
    };
    let settings = TrialSettings {
        seed: 5,
        ..TrialSettings::default()
    };
    let runs = fly_campaign(&profile, &truth, &plan, &settings, |_| true).unwrap();
    let inputs = runs
        .iter()
        .map(|r| {
            let pe = plan
                .experiments
                .iter()
                .find(|p| p.experiment.seq == r.seq)
                .unwrap();
            super::predict::run_input(&profile, pe, &r.csv).unwrap()
        })
        .collect();
    (profile, plan, truth, inputs)
}

#[test]
fn the_first_dive_flies_validation_then_covers_every_grid_speed() {
    let (profile, plan, truth, _) = two_speed_campaign();
    let dive = propose_next_dive(&profile, &plan, &[], &[], &truth, 3.0, &mut NoProgress).unwrap();
    eprintln!("{dive:#?}");
    assert_eq!(dive.relative_std_now, None);
    assert_eq!(dive.proposed[0].family, ExperimentFamily::Validation);
    assert!(dive.uncovered_speeds_mps.is_empty());
    assert!(dive.hours <= 3.0 + 1e-9);
    let firsts = dive
        .proposed
        .iter()
        .filter(|p| p.reason.starts_with("the first data"))
        .count();
    assert_eq!(firsts, 2, "one run opens each grid speed");
    // After the dive the campaign is within reach of the whole plan.
    let after = dive.relative_std_after.unwrap();
    assert!(after >= 1.0 && after.is_finite(), "{after}");
    // The precision only improves along the proposal.
    for w in dive.proposed[1..].windows(2) {
        if w[0].relative_std_after > 0.0 {
            assert!(w[1].relative_std_after <= w[0].relative_std_after + 1e-12);
        }
    }
}

#[test]
fn after_a_dive_the_flown_runs_count_and_are_not_proposed_again() {
    let (profile, plan, truth, runs) = two_speed_campaign();
    // The first half of the plan was flown (the validation run among them
    // or not, as the plan orders it).
    let half = runs.len() / 2;
    let flown = &runs[..half];
    let done: Vec<String> = flown.iter().map(|r| r.run_id.clone()).collect();
    let dive =
        propose_next_dive(&profile, &plan, flown, &done, &truth, 2.0, &mut NoProgress).unwrap();
    assert_eq!(dive.flown_runs, half);
    assert!(dive.proposed.iter().all(|p| !done.contains(&p.code)));
    assert!(!dive.proposed.is_empty());
    let (now, after) = (dive.relative_std_now, dive.relative_std_after.unwrap());
    if let Some(now) = now {
        assert!(after < now, "{after} vs {now}");
    }
    // Everything flown: nothing left to propose, and the campaign's own
    // data reach the plan's precision (noise aside: within 10 %).
    let all: Vec<String> = runs.iter().map(|r| r.run_id.clone()).collect();
    let done_all =
        propose_next_dive(&profile, &plan, &runs, &all, &truth, 2.0, &mut NoProgress).unwrap();
    assert!(done_all.proposed.is_empty());
    let now = done_all.relative_std_now.unwrap();
    assert!(
        (now - 1.0).abs() < 0.1,
        "flown data against the plan's: {now}"
    );
    // No hours, no dive.
    assert!(propose_next_dive(&profile, &plan, &[], &[], &truth, 0.0, &mut NoProgress).is_err());
}

/// A deciding run of discovery in the plan is proposed right after the
/// validation run, with its reason; once flown it is not proposed again.
#[test]
fn a_deciding_run_comes_after_validation_until_it_is_flown() {
    use crate::planning::Dof;
    use crate::planning::examples::deciding_proposal;
    let (profile, _, truth, _) = two_speed_campaign();
    let mut spec = surveyor_campaign(3);
    spec.grid.speeds = vec![0.0, 1.5];
    spec.deciding = vec![deciding_proposal(&profile, Dof::Sway, 0.5, vec![0.0])];
    let plan = generate_plan(&profile, &spec).unwrap();
    let dive = propose_next_dive(&profile, &plan, &[], &[], &truth, 3.0, &mut NoProgress).unwrap();
    assert_eq!(dive.proposed[0].family, ExperimentFamily::Validation);
    assert_eq!(dive.proposed[1].code, "DEC1-sway-000");
    assert!(
        dive.proposed[1].reason.starts_with("a deciding run"),
        "{}",
        dive.proposed[1].reason
    );
    let done = vec!["DEC1-sway-000".to_string()];
    let later =
        propose_next_dive(&profile, &plan, &[], &done, &truth, 3.0, &mut NoProgress).unwrap();
    assert!(later.proposed.iter().all(|p| p.code != "DEC1-sway-000"));
}

/// A DP vessel outside the paper's layout is flown through the project's
/// DP simulator with its own T″ and predicted like any other: a vessel
/// that logs τ (one coefficient, no SI3) and one with four thrusters, each
/// with a finite std for every θ″ its layout has.
#[test]
fn dp_vessels_of_other_layouts_are_predicted() {
    use crate::planning::campaign::ExperimentFamily as F;
    use crate::planning::vessel::InputChannels;
    let mut forces = supply_vessel();
    forces.inputs = InputChannels::GeneralizedForces;
    let four = crate::planning::examples::supply_vessel_azimuths_tunnels();
    for (profile, total) in [(forces, 6), (four, 9)] {
        let mut spec = supply_vessel_trial_campaign(3);
        spec.families = vec![F::DpSurge, F::DpSwayYaw, F::Validation];
        let plan = generate_plan(&profile, &spec).unwrap();
        let prior = Prior::from_profile(&profile).unwrap();
        let p = predict_precision(
            &profile,
            &plan,
            &prior,
            PriorSource::Profile,
            &PredictSettings {
                realisations: 1,
                ..PredictSettings::default()
            },
            &mut NoProgress,
        )
        .unwrap();
        assert_eq!(p.total, total, "{:#?}", p.parameters);
        for row in &p.parameters {
            let s = row.predicted_std.unwrap();
            assert!(s.is_finite() && s > 0.0, "{}: {s}", row.symbol);
        }
    }
}
