use super::*;
use crate::estimation::NoProgress;
use crate::identification::augmented::pieces_by_speed;
use crate::identification::document::Method;
use crate::identification::lambda_campaign::{LambdaCampaignSettings, identify_lambda_campaign};
use crate::identification::outcome::RunValidation;
use crate::identification::predictor::validate_on_run;
use crate::identification::tests::{force_columns, simulate, to_run};
use crate::planning::dof::Dof;
use crate::planning::examples::surveyor_rov;
use crate::simulation::rov::{LinearDamping, RovTruth};

/// Two grid speeds, two estimation runs and one held-out run each,
/// flown by `truth`; no static runs, so the λ model has no g(η).
fn campaign(truth: &RovTruth) -> Vec<RunInput> {
    let mut runs = Vec::new();
    for (g, u0) in [0.5, 1.0].into_iter().enumerate() {
        for r in 0..3u64 {
            let rec = simulate(truth, vec![u0; 3000], 300 + 10 * g as u64 + r);
            let (id, family) = if r < 2 {
                (format!("dyn-{g}-{r}"), ExperimentFamily::Recursive)
            } else {
                (format!("val-{g}"), ExperimentFamily::Validation)
            };
            runs.push(to_run(&id, family, Some(u0), &rec));
        }
    }
    runs
}

/// The λ model without g(η), constant loads and C(δ)δ, so that the
/// restoring, tether, load and Coriolis effects the cases conceal are
/// missing from it.
fn baseline(runs: &[RunInput]) -> Identified {
    let profile = surveyor_rov();
    let settings = LambdaCampaignSettings {
        estimate_restoring: false,
        constant_loads: false,
        coriolis_second_order: false,
        symmetric_inertia: false,
        quadratic_damping: false,
        extend_above_grid: false,
        ..LambdaCampaignSettings::default()
    };
    identify_lambda_campaign(
        &profile,
        &[0.5, 1.0],
        &force_columns(&profile),
        runs,
        &settings,
        &mut NoProgress,
    )
    .unwrap()
}

fn run(runs: &[RunInput], base: &Identified) -> CampaignDiscovery {
    run_on(
        runs,
        base,
        &base.document,
        &DiscoverCampaignSettings::default(),
    )
    .unwrap()
}

/// Discovery of `doc` on the runs and run roles of `base`.
fn run_on(
    runs: &[RunInput],
    base: &Identified,
    doc: &ModelDocument,
    settings: &DiscoverCampaignSettings,
) -> Result<CampaignDiscovery, IdentifyError> {
    let profile = surveyor_rov();
    discover_campaign(
        doc,
        &profile,
        &force_columns(&profile),
        runs,
        &base.estimation_run_ids,
        &base.validation_run_ids,
        settings,
        &mut NoProgress,
    )
}

fn sim_fits(v: &[RunValidation], ch: &str) -> Vec<f64> {
    v.iter()
        .map(|r| {
            r.report
                .channels
                .iter()
                .find(|c| c.output == ch)
                .and_then(|c| c.fit_simulation)
                .unwrap()
        })
        .collect()
}

/// The demo's case: a metacentric righting moment (z_B = −0.2 m) the
/// λ model cannot carry without static runs. Discovery names the roll
/// and pitch restoring at both speeds (z_B·B = 9860 N·m: estimated
/// 9857–9859 in roll, 9388–9676 in pitch), and the augmented model, stored
/// as a document and read back, fits the held-out roll and pitch far
/// better than the baseline did.
#[test]
fn concealed_righting_moment_is_named_at_every_speed_and_the_stored_model_fits() {
    let truth = RovTruth::surveyor_like();
    let runs = campaign(&truth);
    let base = baseline(&runs);
    let out = run(&runs, &base);
    let rep = &out.report;
    assert_eq!(rep.points.len(), 2, "{:?}", rep.skipped);
    for (dof, speeds) in [(Dof::Roll, 2), (Dof::Pitch, 2)] {
        let e = rep
            .effects
            .iter()
            .find(|e| matches!(e.effect, Effect::Restoring { dof: d, .. } if d == dof))
            .unwrap_or_else(|| panic!("no {dof:?} restoring in {:#?}", rep.summary));
        assert_eq!(e.grid_speeds_mps.len(), speeds, "{:?}", rep.summary);
    }
    // Ranked by the speeds that chose them, then by held-out evidence: the
    // gain each term brought where it was chosen, as its hypothesis says.
    for e in &rep.effects {
        assert_eq!(e.held_out_gains.len(), e.grid_speeds_mps.len());
        for (speed, gain) in e.grid_speeds_mps.iter().zip(&e.held_out_gains) {
            let p = rep
                .points
                .iter()
                .find(|p| p.grid_speed_mps == *speed)
                .unwrap();
            let h = p
                .report
                .hypotheses
                .iter()
                .find(|h| h.effect == e.effect)
                .unwrap();
            assert_eq!(h.cv_gain, Some(*gain));
            assert!(*gain >= DiscoverySettings::default().min_cv_gain);
        }
    }
    for w in rep.effects.windows(2) {
        let key = |e: &EffectAcrossGrid| (e.grid_speeds_mps.len(), e.evidence());
        let (a, b) = (key(&w[0]), key(&w[1]));
        assert!(
            a.0 > b.0 || (a.0 == b.0 && a.1 >= b.1),
            "{a:?} before {b:?}"
        );
    }
    let aug = out.augmented.as_ref().expect("an augmented model");
    assert_eq!(aug.document.method, Method::Discovery);
    assert_eq!(aug.validation_run_ids, base.validation_run_ids);
    for ch in ["p", "q"] {
        let (before, after) = (
            sim_fits(&base.validation, ch),
            sim_fits(&aug.validation, ch),
        );
        for (b, a) in before.iter().zip(&after) {
            // The truth also has speed-dependent damping (u·ν products)
            // left unexplained, which caps pitch near 0.7.
            assert!(*a > 0.65 && a - b > 0.5, "{ch}: {before:?} → {after:?}");
        }
    }
    // Through JSON, as the store keeps it: the same validation again.
    let doc: ModelDocument =
        serde_json::from_value(serde_json::to_value(&aug.document).unwrap()).unwrap();
    let inputs = force_columns(&surveyor_rov());
    let val = runs.iter().find(|r| r.run_id == "val-1").unwrap();
    let again = validate_on_run(&doc, val, &inputs, 10).unwrap();
    let stored = &aug
        .validation
        .iter()
        .find(|v| v.run_id == "val-1")
        .unwrap()
        .report;
    for (a, b) in again.channels.iter().zip(&stored.channels) {
        assert!((a.fit_simulation.unwrap() - b.fit_simulation.unwrap()).abs() < 1e-9);
    }
    assert!(
        aug.document
            .parameters
            .iter()
            .any(|p| p.group.starts_with("discovered:"))
    );
}

/// A truth the baseline can represent: nothing is named, no new model.
#[test]
fn a_model_that_fits_gets_no_false_alarm_and_no_new_version() {
    // Diagonal M, constant diagonal D, neutral restoring: what the
    // λ model at each grid speed represents exactly.
    let rich = RovTruth::surveyor_like();
    let diag = |m: &nalgebra::Matrix6<f64>| nalgebra::Matrix6::from_diagonal(&m.diagonal());
    let truth = RovTruth::new(
        diag(&rich.m),
        LinearDamping::constant(diag(&rich.damping.at(0.75))),
    );
    let runs = campaign(&truth);
    let base = baseline(&runs);
    let out = run(&runs, &base);
    assert!(out.report.effects.is_empty(), "{:?}", out.report.summary);
    assert!(out.augmented.is_none());
    assert!(out.report.summary[0].starts_with("No missing physics"));
}

/// The service's flow in-process: the Surveyor's planned campaign on 1
/// and 2 kn (recursive + validation, 2 repetitions, seed 11) flown under
/// the planner's PI control by `truth` (≤ 240 s per run), identified by
/// λ and examined by discovery.
fn flown(truth: &RovTruth) -> (Vec<RunInput>, Identified, CampaignDiscovery) {
    use crate::planning::{CampaignSpec, generate_plan};
    use crate::simulation::trials::{TrialSettings, fly_experiment};
    let profile = surveyor_rov();
    let spec: CampaignSpec = serde_json::from_value(serde_json::json!({
        "name": "identification trial",
        "grid": { "unit": "kn", "speeds": [1.0, 2.0] },
        "families": ["recursive", "validation"],
        "repetitions": 2,
        "seed": 11
    }))
    .unwrap();
    let plan = generate_plan(&profile, &spec).unwrap();
    let settings = TrialSettings {
        max_duration_s: Some(240.0),
        seed: 3,
        noise: fibre_optic_gyro(),
        ..TrialSettings::default()
    };
    let runs: Vec<RunInput> = plan
        .experiments
        .iter()
        .map(|p| {
            let f = fly_experiment(&profile, truth, p, &settings).unwrap();
            to_run(&f.code, f.family, f.grid_speed_mps, &f.record)
        })
        .collect();
    let grid: Vec<f64> = spec.grid.speeds_si();
    let base = identify_lambda_campaign(
        &profile,
        &grid,
        &force_columns(&profile),
        &runs,
        &LambdaCampaignSettings {
            estimate_restoring: false,
            constant_loads: false,
            coriolis_second_order: false,
            symmetric_inertia: false,
            quadratic_damping: false,
            extend_above_grid: false,
            ..LambdaCampaignSettings::default()
        },
        &mut NoProgress,
    )
    .unwrap();
    let out = run(&runs, &base);
    (runs, base, out)
}

/// The default navigation noise with a fibre-optic gyro (±0.001 rad/s).
/// Roll and pitch are excited by attitude (±10° about level), so p and q
/// move ≈ 0.03 rad/s (std) on a validation run: with a MEMS gyro's
/// ±0.005 rad/s their held-out fits sit at the noise ceiling (≈ 0.8),
/// where the gate's absolute tolerance of 0.005 in fit is below the
/// fit's own noise and a heave effect is refused over p, q.
fn fibre_optic_gyro() -> crate::simulation::trials::MeasurementNoise {
    let mut noise = crate::simulation::trials::MeasurementNoise::default();
    noise.nu[3..6].fill(0.001);
    noise
}

/// The diagonal truth the λ model represents exactly at each grid speed.
fn diagonal_truth() -> RovTruth {
    let rich = RovTruth::surveyor_like();
    let diag = |m: &nalgebra::Matrix6<f64>| nalgebra::Matrix6::from_diagonal(&m.diagonal());
    RovTruth::new(
        diag(&rich.m),
        LinearDamping::constant(diag(&rich.damping.at(0.75))),
    )
}

/// The chosen effects at one grid speed, in order.
fn chosen(p: &PointDiscovery) -> Vec<Effect> {
    p.report.findings.iter().map(|f| f.effect).collect()
}

/// Heave thrust capped at 900 N under the planner's PI control: the
/// controller winds up to its own 8000 N limit, so nearly every logged
/// command lies far above the cap. Saturation is named first at both
/// speeds (not the delay or lag a late response also suggests), its
/// level is within 3σ of the truth, and no lag is added on top (the
/// lag's time constant would trade places with the hull's M/D̄).
#[test]
fn saturation_under_pi_control_is_named_with_its_level() {
    let mut truth = diagonal_truth();
    truth.actuators.saturation[2] = 900.0;
    let (_, base, out) = flown(&truth);
    assert_eq!(out.report.points.len(), 2, "{:?}", out.report.skipped);
    for p in &out.report.points {
        let c = chosen(p);
        assert_eq!(
            c,
            [Effect::Saturation { dof: Dof::Heave }],
            "{:#?}",
            p.report.summary
        );
        let s = p.report.findings[0].shape.as_ref().unwrap();
        assert!((s.value - 900.0).abs() < 3.0 * s.std.unwrap(), "{s:?}");
    }
    let aug = out
        .augmented
        .as_ref()
        .unwrap_or_else(|| panic!("{:#?}", out.report.summary.last()));
    for (b, a) in sim_fits(&base.validation, "w")
        .iter()
        .zip(sim_fits(&aug.validation, "w"))
    {
        assert!(a > b + 0.04, "heave free run {b} → {a}");
    }
}

/// Coriolis–centripetal forces of a diagonal M, and two pairs of
/// effects, on PI-flown planned runs: named at both speeds with the
/// truth's magnitudes (C(ν) built from the model's own M, refitted to
/// a fixed point, comes out at scale 1).
#[test]
fn coriolis_and_pairs_under_pi_control_are_named() {
    let mut coriolis = diagonal_truth();
    coriolis.coriolis = true;
    let (_, _, out) = flown(&coriolis);
    for p in &out.report.points {
        assert_eq!(
            chosen(p)[0],
            Effect::CoriolisFromM,
            "{:#?}",
            p.report.summary
        );
        let k = &p.report.findings[0].coefficients[0];
        assert!((k.value - 1.0).abs() < 0.05, "{k:?}");
    }
    let mut quad_lag = diagonal_truth();
    quad_lag.quadratic_damping[1] = 30000.0;
    quad_lag.actuators.time_constants[2] = 0.8;
    let mut tether_delay = diagonal_truth();
    tether_delay.tether.body_force = [0.0, 400.0, 0.0];
    tether_delay.actuators.delay_samples = 4;
    for (truth, want) in [
        (
            quad_lag,
            [
                Effect::ActuatorLag { dof: Dof::Heave },
                Effect::QuadraticDamping { dof: Dof::Sway },
            ],
        ),
        (
            tether_delay,
            [
                Effect::CommonInputDelay,
                Effect::ConstantLoad { dof: Dof::Sway },
            ],
        ),
    ] {
        let (_, _, out) = flown(&truth);
        for p in &out.report.points {
            assert_eq!(chosen(p), want, "{:#?}", p.report.summary);
        }
    }
}

#[test]
fn a_run_through_the_grid_is_cut_where_the_speed_changes_grid_point() {
    // 100 s at 0.5, 100 s at 1.0, 100 s at 1.5 m/s, 10 Hz, with ripple.
    let u: Vec<f64> = (0..3000)
        .map(|k| 0.5 * (1 + k / 1000) as f64 + 0.2 * (k as f64 * 0.3).sin())
        .collect();
    let p = pieces_by_speed(&u, 0.1, &[0.5, 1.0, 1.5]);
    assert_eq!(
        p.iter().map(|x| x.2).collect::<Vec<_>>(),
        [0, 1, 2],
        "{p:?}"
    );
    // The 10 s smoothing moves each cut by at most half its window.
    assert_eq!((p[0].0, p[2].1), (0, 3000));
    assert!((p[0].1 as i64 - 1000).abs() <= 50 && (p[1].1 as i64 - 2000).abs() <= 50);
}

#[test]
fn bad_requests_name_the_field() {
    let truth = RovTruth::surveyor_like();
    let runs = campaign(&truth);
    let base = baseline(&runs);
    let go = |s: &DiscoverCampaignSettings, doc: &ModelDocument| {
        run_on(&runs, &base, doc, s)
            .unwrap_err()
            .field()
            .to_string()
    };
    let s = DiscoverCampaignSettings {
        grid_speeds_mps: Some(vec![0.7]),
        ..Default::default()
    };
    assert_eq!(go(&s, &base.document), "settings.grid_speeds_mps[0]");
    let s = DiscoverCampaignSettings {
        validation_run_ids: Some(vec!["dyn-0-0".into()]),
        ..Default::default()
    };
    assert_eq!(go(&s, &base.document), "settings.validation_run_ids");
    let mut ss = base.document.clone();
    ss.kind = ModelKind::StateSpace;
    assert_eq!(go(&Default::default(), &ss), "model_id");
}

/// Discovery on a model from an earlier discovery starts from its terms.
/// The first pass names both concealed restoring moments (roll, pitch) and
/// the heave load; a pass on its result finds nothing further and stores
/// nothing. A pass on
/// that model with the pitch term taken out keeps the roll term (refitted,
/// not named again) and names pitch again; the version it would store
/// carries both, with one set of parameter rows per term and speed.
#[test]
fn discovery_continues_from_an_augmented_model() {
    // What the λ model represents exactly at each speed, with W − B and the
    // metacentric moments of the Surveyor-like vehicle concealed.
    let mut truth = diagonal_truth();
    truth.restoring = RovTruth::surveyor_like().restoring;
    let runs = campaign(&truth);
    let base = baseline(&runs);
    let go = |doc: &ModelDocument| {
        run_on(&runs, &base, doc, &DiscoverCampaignSettings::default()).unwrap()
    };
    let roll = Effect::Restoring {
        dof: Dof::Roll,
        shape: crate::discrepancy::RestoringShape::CosThetaSinPhi,
    };
    let is_pitch = |e: &Effect| {
        matches!(
            e,
            Effect::Restoring {
                dof: Dof::Pitch,
                ..
            }
        )
    };

    let first = go(&base.document);
    let v = first
        .augmented
        .as_ref()
        .unwrap_or_else(|| panic!("{:#?}", first.report.summary));
    let again = go(&v.document);
    assert!(
        again.report.effects.is_empty(),
        "{:#?}",
        again.report.summary
    );
    assert!(again.augmented.is_none());
    assert!(
        again.report.summary[0].starts_with("Nothing found beyond the terms the model carries"),
        "{:?}",
        again.report.summary
    );

    let mut roll_only = v.document.clone();
    for pt in &mut roll_only.lpv.as_mut().unwrap().points {
        let a = pt.augmentation.as_mut().unwrap();
        assert!(a.terms.iter().any(|t| t.effect == roll), "{:?}", a.terms);
        a.terms.retain(|t| !is_pitch(&t.effect));
    }
    let second = go(&roll_only);
    for p in &second.report.points {
        assert!(p.report.carried.contains(&roll), "{:?}", p.report.carried);
        assert!(!chosen(p).contains(&roll), "{:#?}", p.report.summary);
        assert!(chosen(p).iter().any(is_pitch), "{:#?}", p.report.summary);
        assert!(p.report.summary[0].starts_with("Started from the terms the model carries"));
    }
    let v2 = second
        .augmented
        .as_ref()
        .unwrap_or_else(|| panic!("{:#?}", second.report.summary));
    for pt in &v2.document.lpv.as_ref().unwrap().points {
        let terms = &pt.augmentation.as_ref().unwrap().terms;
        assert!(
            terms.iter().any(|t| t.effect == roll) && terms.iter().any(|t| is_pitch(&t.effect))
        );
        for t in terms {
            let rows = v2
                .document
                .parameters
                .iter()
                .filter(|r| {
                    r.group == format!("discovered: {}", t.effect.label())
                        && r.grid_speed_mps == Some(pt.speed_mps)
                })
                .count();
            assert_eq!(rows, t.coefficients.len(), "{:?}", t.effect);
        }
    }
    // Pitch regains on the held-out runs what taking its term out lost.
    for (a, b) in sim_fits(&v.validation, "q")
        .iter()
        .zip(sim_fits(&v2.validation, "q"))
    {
        assert!(
            (a - b).abs() < 0.02,
            "pitch: {a} (first) vs {b} (continued)"
        );
    }
}
