//! Proof of the campaign entry point on the simulated supply vessel: the
//! planned DP manoeuvres flown through the truth, logged as SI CSV, parsed
//! like an upload, identified and validated.

#![allow(clippy::needless_range_loop)] // θ″ and matrix indices read best as indices

use super::*;
use crate::estimation::NoProgress;
use crate::logs::{LogRole, ParseOptions, input_columns, parse_log, to_uniform};
use crate::planning::campaign::ExperimentFamily;
use crate::planning::examples::{supply_vessel, supply_vessel_trial_campaign};
use crate::planning::generate_plan;
use crate::planning::vessel::InputChannels;
use crate::simulation::dp_ship::{DpFlightSettings, DpShip, THETA_NAMES, fly_dp_campaign, paper};

/// The campaign flown with truth noise seed `seed`, as uploaded runs.
pub(crate) fn flown_runs(plan_seed: u64, seed: u64) -> Vec<RunInput> {
    let profile = supply_vessel();
    let plan = generate_plan(&profile, &supply_vessel_trial_campaign(plan_seed)).unwrap();
    runs_of(&profile, &plan, seed)
}

/// `plan` flown with truth noise seed `seed`, parsed like uploads.
fn runs_of(profile: &VesselProfile, plan: &crate::planning::Plan, seed: u64) -> Vec<RunInput> {
    let flown = fly_dp_campaign(
        profile,
        &DpShip::supply_vessel(),
        plan,
        &DpFlightSettings::supply_vessel(seed),
        |_| true,
    )
    .unwrap();
    flown
        .iter()
        .map(|f| {
            let parsed = parse_log(
                f.csv.as_bytes(),
                &ParseOptions::for_vessel(profile, LogRole::Single, None),
            )
            .unwrap();
            let (record, _) = to_uniform(&parsed.table, None).unwrap();
            RunInput {
                run_id: f.code.clone(),
                name: f.code.clone(),
                family: Some(f.family),
                grid_speed_mps: Some(0.0),
                excited_dofs: vec![],
                record,
            }
        })
        .collect()
}

#[test]
fn supply_vessel_profile_carries_the_papers_m_and_t() {
    let p = supply_vessel();
    let prior = p.dp_prior.as_ref().unwrap();
    assert_eq!(prior.length_m, paper::LENGTH_M);
    for i in 0..3 {
        assert_eq!(
            prior.inertia_bis.as_ref().unwrap()[i].as_slice(),
            &paper::M_INERTIA[i]
        );
    }
    let InputChannels::Thrusters { configuration, .. } = &p.inputs else {
        panic!("thrusters")
    };
    for i in 0..3 {
        assert_eq!(configuration[i].as_slice(), &paper::T_CONFIG[i]);
    }
}

#[test]
fn campaign_identifies_the_supply_vessel_within_five_percent() {
    let profile = supply_vessel();
    let runs = flown_runs(1995, 2024);
    let inputs = input_columns(&profile);
    let start = std::time::Instant::now();
    let out = identify_ekf_campaign(
        &profile,
        &inputs,
        &runs,
        &EkfCampaignSettings::default(),
        &mut NoProgress,
    )
    .unwrap();
    eprintln!("identified in {:.2} s", start.elapsed().as_secs_f64());
    let doc = out.document.dp_ship.as_ref().unwrap();
    let mut worst: f64 = 0.0;
    for p in 0..N_THETA {
        let err = doc.theta[p] / paper::THETA[p] - 1.0;
        eprintln!(
            "θ″{} {:>6} {:>10.6} ± {:.1e} truth {:>10.6} err {:>6.2} %",
            p + 1,
            THETA_NAMES[p],
            doc.theta[p],
            doc.theta_std[p],
            paper::THETA[p],
            100.0 * err
        );
        worst = worst.max(err.abs());
    }
    assert!(worst < 0.05, "worst θ″ error {:.2} %", 100.0 * worst);
    assert_eq!(out.document.kind, ModelKind::DpShip);
    assert!(
        out.document.structure_findings.is_empty(),
        "{:?}",
        out.document.structure_findings
    );
    assert_eq!(out.document.parameters.len(), 9);
    assert_eq!(out.estimation_run_ids.len(), 6);
    assert_eq!(out.validation_run_ids, ["VAL-r1", "VAL-r2"]);
    // Held-out validation in SI: k-step predictions of x, y, ψ fit.
    let v = &out.validation[0].report;
    for c in &v.channels {
        eprintln!(
            "{}: 1-step {:?} k-step {:?} restarted {:?} sim {:?}",
            c.output, c.fit_one_step, c.fit_k_step, c.fit_restarted, c.fit_simulation
        );
        assert!(c.fit_k_step.unwrap() > 0.8, "{} k-step fit", c.output);
        // Restarted from the estimator's state every 10 s, the identified
        // ship stays on the recording (no window diverges).
        assert_eq!(c.restarted.diverged, 0, "{}", c.verdict);
        assert!(c.fit_restarted.unwrap() > 0.8, "{} restarted fit", c.output);
    }
    let json = serde_json::to_value(v).unwrap();
    assert!(json.to_string().contains("\"psi\""));
    // The stored document predicts again through the stored-model path.
    let val = runs
        .iter()
        .find(|r| r.family == Some(ExperimentFamily::Validation))
        .unwrap();
    let pred = super::super::predictor::validate_on_run(&out.document, val, &[], 10).unwrap();
    assert_eq!(
        serde_json::to_value(&pred.channels).unwrap(),
        serde_json::to_value(&v.channels).unwrap()
    );
    // SI A and B follow from the Bis ones.
    let t = doc.time_unit_s;
    assert!((doc.a_si[0][0] - doc.a[0][0] / t).abs() < 1e-12);
}

/// `refine: false` is the paper's staging alone; the default adds the
/// prediction-error refinement, whose θ″ the document carries with the
/// EKF's θ″ in a note, and whose std are never larger than half of θ″'s.
#[test]
fn refinement_is_on_by_default_and_the_staging_stays_available() {
    let profile = supply_vessel();
    let runs = flown_runs(1995, 7);
    let inputs = input_columns(&profile);
    let go = |refine| {
        let s = EkfCampaignSettings {
            refine,
            ..Default::default()
        };
        identify_ekf_campaign(&profile, &inputs, &runs, &s, &mut NoProgress)
            .unwrap()
            .document
    };
    let staged = go(false);
    let refined = go(true);
    let note = |d: &ModelDocument| d.notes.iter().any(|n| n.starts_with("Refined after"));
    assert!(!note(&staged), "{:?}", staged.notes);
    assert!(note(&refined), "{:?}", refined.notes);
    assert!(refined.notes.iter().any(|n| n.contains("Cramér–Rao")));
    let (a, b) = (staged.dp_ship.unwrap(), refined.dp_ship.unwrap());
    assert_ne!(a.theta, b.theta);
    // The structured record: none when not asked for; when taken, the
    // EKF's θ″ (the staging's own result) beside the refined ones.
    assert_eq!(a.refinement, None);
    let rec = b.refinement.as_ref().expect("a refinement record");
    assert!(rec.applied && rec.reason.is_none(), "{rec:?}");
    assert_eq!(rec.ekf_theta, a.theta);
    assert_eq!(rec.ekf_theta_std, a.theta_std);
    assert!(rec.iterations >= 1);
    assert_eq!(rec.std_inflation.len(), N_THETA);
    assert!(rec.std_inflation.iter().all(|f| *f >= 1.0 && f.is_finite()));
    assert!(rec.variance_ratio.is_some_and(|v| v > 0.0));
    assert!(rec.held_out_nll_change.is_some_and(|d| d <= 2.0));
    // Without M″ it is not run, and the record says why.
    let mut no_m = profile.clone();
    if let Some(prior) = no_m.dp_prior.as_mut() {
        prior.inertia_bis = None;
    }
    let doc = identify_ekf_campaign(&no_m, &inputs, &runs, &Default::default(), &mut NoProgress)
        .unwrap()
        .document;
    let rec = doc.dp_ship.unwrap().refinement.expect("a record");
    assert!(!rec.applied && rec.iterations == 0, "{rec:?}");
    assert!(rec.reason.is_some_and(|r| r.contains("without M″")));
    for p in 0..N_THETA {
        assert!(b.theta_std[p] > 0.0 && b.theta_std[p] < 0.5 * b.theta[p].abs());
        assert!(
            (b.theta[p] / paper::THETA[p] - 1.0).abs() < 0.15,
            "θ″{}",
            p + 1
        );
    }
}

#[test]
fn bad_settings_and_runs_name_the_field() {
    let profile = supply_vessel();
    let runs = flown_runs(1995, 5);
    let inputs = input_columns(&profile);
    let go = |s: &EkfCampaignSettings, runs: &[RunInput]| {
        identify_ekf_campaign(&profile, &inputs, runs, s, &mut NoProgress).unwrap_err()
    };
    let s = EkfCampaignSettings {
        theta_init: Some(vec![0.0; 4]),
        ..Default::default()
    };
    assert_eq!(go(&s, &runs).field(), "settings.theta_init");
    let s = EkfCampaignSettings {
        position_noise_std_m: -1.0,
        ..Default::default()
    };
    assert_eq!(go(&s, &runs).field(), "settings.position_noise_std_m");
    let s = EkfCampaignSettings {
        sweeps: 0,
        ..Default::default()
    };
    assert_eq!(go(&s, &runs).field(), "settings.sweeps");
    // No SI3 run.
    let no_si3: Vec<RunInput> = runs
        .iter()
        .filter(|r| r.family != Some(ExperimentFamily::DpAzimuth))
        .cloned()
        .collect();
    let e = go(&EkfCampaignSettings::default(), &no_si3);
    assert_eq!(e.field(), "run_ids");
    assert!(e.to_string().contains("SI3"), "{e}");
    // A ROV profile is refused naming the method; a DP profile without L names it.
    let rov = crate::planning::examples::surveyor_rov();
    let e = identify_ekf_campaign(&rov, &inputs, &runs, &Default::default(), &mut NoProgress)
        .unwrap_err();
    assert_eq!(e.field(), "method");
    let mut bare = supply_vessel();
    bare.dp_prior = None;
    let e = identify_ekf_campaign(&bare, &inputs, &runs, &Default::default(), &mut NoProgress)
        .unwrap_err();
    assert_eq!(e.field(), "vessel.dp_prior.length_m");
}

#[test]
fn unphysical_estimates_are_reported() {
    let m = Matrix3::from_fn(|i, j| paper::M_INERTIA[i][j]);
    let good = Matrix3::from_fn(|i, j| paper::A_H[i][j]);
    assert!(structure_findings(&m, &good, &paper::K_THRUST).is_empty());
    let mut bad = good;
    bad[(1, 1)] = 0.05;
    let mut k = paper::K_THRUST;
    k[5] = -1e-3;
    let f = structure_findings(&m, &bad, &k);
    assert!(f.iter().any(|s| s.contains("not dissipative")), "{f:?}");
    assert!(f.iter().any(|s| s.contains("not stable")), "{f:?}");
    assert!(f.iter().any(|s| s.contains("K″6")), "{f:?}");
}

/// The campaign path over truth seeds 1–12 (planned PRBS manoeuvres):
/// `cargo test --release -p seatrial-core campaign_seed_sweep -- --ignored --nocapture`.
/// Variants: the default N = 2 × 600 s, more momentum process noise, and
/// more sway–yaw data (N = 4, or 1200 s manoeuvres).
#[test]
#[ignore = "seed sweep, ≈ 20 s in release"]
fn campaign_seed_sweep() {
    let profile = supply_vessel();
    let inputs = input_columns(&profile);
    let variants: [(&str, u32, f64, f64); 4] = [
        ("N = 2 × 600 s", 2, 600.0, 1e-5),
        ("N = 2 × 600 s, q_h (3.2e-5)²", 2, 600.0, 3.16e-5),
        ("N = 4 × 600 s", 4, 600.0, 1e-5),
        ("N = 2 × 1200 s", 2, 1200.0, 1e-5),
    ];
    for (name, reps, dur, q_h) in variants {
        let mut spec = supply_vessel_trial_campaign(1995);
        spec.repetitions = Some(reps);
        spec.durations.dp_manoeuvre_s = dur;
        let plan = generate_plan(&profile, &spec).unwrap();
        let settings = EkfCampaignSettings {
            momentum_noise_std_bis: q_h,
            ..Default::default()
        };
        let mut hits = [0usize; N_THETA];
        let mut covered = 0;
        let mut line = String::new();
        for seed in 1..=12u64 {
            let runs = runs_of(&profile, &plan, seed);
            let out = identify_ekf_campaign(&profile, &inputs, &runs, &settings, &mut NoProgress)
                .unwrap();
            let doc = out.document.dp_ship.unwrap();
            let err: Vec<f64> = (0..N_THETA)
                .map(|p| doc.theta[p] / paper::THETA[p] - 1.0)
                .collect();
            for p in 0..N_THETA {
                hits[p] += usize::from(err[p].abs() < 0.05);
            }
            let rel = doc.theta_std[2] / paper::THETA[2];
            covered += usize::from(err[2].abs() < 3.0 * rel);
            line.push_str(&format!(" {:+.1}%(σ{:.1}%)", 100.0 * err[2], 100.0 * rel));
        }
        eprintln!(
            "{name:>28}: within 5 % per θ″ {hits:?}; θ″3 within 3σ {covered}/12; θ″3 per seed:{line}"
        );
        // The default campaign: every θ″ but the weak θ″3 within 5 % on ≥ 11
        // seeds, and θ″3's σ covers its error on every seed.
        if name == variants[0].0 {
            for (p, &h) in hits.iter().enumerate() {
                assert!(p == 2 || h >= 11, "{name}: θ″{}: {hits:?}", p + 1);
            }
            assert_eq!(covered, 12, "{name}: θ″3's σ covers its error");
        }
    }
}
