//! Predicted precision through REST: the `precision` job flies the
//! campaign's current plan with a prior and stores the table the core
//! computes; `GET /api/campaigns/{id}/precision` serves it and says when
//! the plan has changed since. Requests the job cannot use are 422s naming
//! the field. Every response is checked against openapi.yaml.

mod common;

use common::TestApp;
use common::finite::assert_finite_json;
use common::flights::planned_campaign;
use seatrial::jobs::{JobRegistry, JobsConfig};
use seatrial_core::design::{PredictSettings, Prior, PriorSource, predict_precision};
use seatrial_core::estimation::NoProgress;
use seatrial_core::planning::examples::{supply_vessel, supply_vessel_trial_campaign};
use seatrial_core::planning::generate_plan;
use serde_json::{Value, json};

async fn app() -> TestApp {
    TestApp::with_jobs(JobRegistry::production(), JobsConfig::default()).await
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_supply_vessels_plan_is_predicted_as_the_core_predicts_it() {
    let app = app().await;
    let spec = supply_vessel_trial_campaign(1995);
    let (cid, _) = planned_campaign(
        &app,
        common::dp_profile(),
        serde_json::to_value(&spec).unwrap(),
    )
    .await;

    let none = app
        .call("GET", "/api/campaigns/{id}/precision", &[&cid], None)
        .await;
    assert_eq!(none.status, 404, "{}", none.text);
    assert!(none.text.contains("precision"), "{}", none.text);

    let job = common::run_job(
        &app,
        json!({ "kind": "precision", "campaign_id": cid, "settings": { "prior": "reference", "seed": 4, "realisations": 6 } }),
    )
    .await;
    assert_eq!(job["result"]["prediction"]["method"], "parallel_ekf");

    let r = app
        .call("GET", "/api/campaigns/{id}/precision", &[&cid], None)
        .await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert_finite_json(&r.json, "precision");
    assert_eq!(r.json["current"], true);
    assert_eq!(r.json["plan_version"], 1);
    assert_eq!(r.json["prediction"]["prior"]["kind"], "reference");
    assert_eq!(r.json["prediction"]["realisations"], 6);

    // The same numbers as the core on the same plan, prior and seed.
    let profile = supply_vessel();
    let plan = generate_plan(&profile, &spec).unwrap();
    let core = predict_precision(
        &profile,
        &plan,
        &Prior::reference(&profile).unwrap(),
        PriorSource::Reference,
        &PredictSettings {
            seed: 4,
            realisations: 6,
            ..PredictSettings::default()
        },
        &mut NoProgress,
    )
    .unwrap();
    let rows = r.json["prediction"]["parameters"].as_array().unwrap();
    assert_eq!(rows.len(), core.parameters.len());
    assert_eq!(r.json["prediction"]["determined"], core.determined);
    for (row, c) in rows.iter().zip(&core.parameters) {
        assert_eq!(row["symbol"], c.symbol.as_str());
        let sd = row["predicted_std"].as_f64().unwrap();
        let want = c.predicted_std.unwrap();
        assert!(
            (sd - want).abs() <= 1e-12 * want.abs(),
            "{}: {sd} vs {want}",
            c.symbol
        );
    }

    // A re-plan that changes the plan makes the stored prediction stale.
    let re = app
        .call(
            "POST",
            "/api/campaigns/{id}/plan",
            &[&cid],
            Some(json!({ "durations": { "setup_s": 90 } })),
        )
        .await;
    assert_eq!(re.status, 201, "{}", re.text);
    let r = app
        .call("GET", "/api/campaigns/{id}/precision", &[&cid], None)
        .await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert_eq!(r.json["current"], false);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn unusable_precision_requests_are_422_naming_the_field() {
    let app = app().await;
    let spec = supply_vessel_trial_campaign(1995);
    let (cid, _) = planned_campaign(
        &app,
        common::dp_profile(),
        serde_json::to_value(&spec).unwrap(),
    )
    .await;
    for (body, field) in [
        (
            json!({ "kind": "precision", "campaign_id": cid, "settings": { "prior": "model" } }),
            "model_id",
        ),
        (
            json!({ "kind": "precision", "campaign_id": cid, "settings": { "priors": "model" } }),
            "settings",
        ),
        (
            json!({ "kind": "precision", "campaign_id": cid, "method": "lambda_kf" }),
            "method",
        ),
        (
            json!({ "kind": "precision", "campaign_id": cid, "settings": { "seed": -1 } }),
            "settings.seed",
        ),
        (
            json!({ "kind": "precision", "campaign_id": cid, "settings": { "realisations": 0 } }),
            "settings.realisations",
        ),
        (json!({ "kind": "precision" }), "campaign_id"),
    ] {
        common::assert_job_refused(&app, body, field).await;
    }
    // A plan without a validation run cannot be identified, so not predicted.
    let (bare, _) = planned_campaign(
        &app,
        common::rov_profile(),
        json!({ "name": "no validation", "grid": { "unit": "kn", "speeds": [1.0] }, "families": ["dynamic"], "seed": 5 }),
    )
    .await;
    let r = app
        .call(
            "POST",
            "/api/jobs",
            &[],
            Some(json!({ "kind": "precision", "campaign_id": bare })),
        )
        .await;
    assert_eq!(r.status, 422, "{}", r.text);
    assert_eq!(r.json["field"], "campaign_id");
    assert!(r.text.contains("no validation run"), "{}", r.text);
    // A prior model of another vessel is refused.
    let other = planned_campaign(
        &app,
        common::rov_profile(),
        json!({ "name": "rov", "grid": { "unit": "kn", "speeds": [1.0] }, "families": ["dynamic"], "seed": 5 }),
    )
    .await
    .0;
    let c = app
        .call("GET", "/api/campaigns/{id}", &[&other], None)
        .await;
    let vid = c.json["vessel_id"].as_str().unwrap().to_string();
    let mid = common::stored_model(&app, &other, &vid, None, &[]).await;
    let r = app
        .call(
            "POST",
            "/api/jobs",
            &[],
            Some(json!({ "kind": "precision", "campaign_id": cid, "model_id": mid })),
        )
        .await;
    assert_eq!(r.status, 422, "{}", r.text);
    assert_eq!(r.json["field"], "model_id");
    assert!(r.text.contains("another vessel"), "{}", r.text);
}

/// An ROV whose profile declares no autopilot: after a dive, the precision
/// job infers the autopilot from the flown runs of the plan (logged as its
/// computer read them) and flies the prediction through it; the inferred
/// gains are the ones that flew the runs.
#[tokio::test]
async fn after_a_dive_the_autopilot_is_inferred_from_the_flown_runs() {
    use seatrial_core::planning::examples::surveyor_rov;
    use seatrial_core::planning::{Autopilot, AutopilotLoop, CampaignSpec, RestoringFeedForward};
    use seatrial_core::simulation::rov::RovTruth;
    use seatrial_core::simulation::trials::{Feedback, TrialSettings, fly_experiment};

    let app = app().await;
    let spec = json!({ "name": "first dive", "grid": { "unit": "kn", "speeds": [1.0, 2.0] }, "families": ["dynamic", "validation"], "seed": 5 });
    let (cid, plan) = planned_campaign(&app, common::rov_profile(), spec.clone()).await;

    // The team's autopilot, which the service is not told about.
    let truth = RovTruth::surveyor_like();
    let mut flying = surveyor_rov();
    let loops = flying
        .dofs
        .iter()
        .map(|&d| {
            let m = truth.m[(d.index(), d.index())];
            let l = if d.index() == 3 || d.index() == 4 {
                let kp = m * 1.44 + 1500.0;
                AutopilotLoop {
                    kp,
                    ki: 0.0,
                    kd: Some(1.6 * (kp * m).sqrt()),
                }
            } else {
                AutopilotLoop {
                    kp: 0.8 * m,
                    ki: 0.2 * m,
                    kd: None,
                }
            };
            (d, l)
        })
        .collect();
    let declared = Autopilot {
        loops,
        restoring_feed_forward: Some(RestoringFeedForward {
            w_minus_b: 40.0,
            zg_w_minus_zb_b: 2500.0,
        }),
    };
    flying.autopilot = Some(declared.clone());
    let core_spec: CampaignSpec = serde_json::from_value(spec).unwrap();
    let core_plan = generate_plan(&flying, &core_spec).unwrap();
    let settings = TrialSettings {
        seed: 9,
        feedback: Feedback::Measured,
        ..TrialSettings::default()
    };
    for p in &core_plan.experiments {
        let flown = fly_experiment(&flying, &truth, p, &settings).unwrap();
        common::flights::upload_planned(&app, &cid, &plan, &p.experiment.code, &flown.csv).await;
    }

    let job = common::run_job(
        &app,
        json!({ "kind": "precision", "campaign_id": cid, "settings": { "prior": "reference", "realisations": 2 } }),
    )
    .await;
    let result = &job["result"];
    let inferred = &result["inferred_autopilot"];
    assert!(inferred.is_object(), "{result:#}");
    for (d, want) in &declared.loops {
        let got = &inferred["autopilot"]["loops"][d.name()];
        // The integral is summed from the 10 Hz log, the autopilot's at
        // 20 Hz: K_i is the least determined gain.
        let close = |g: &Value, w: f64, what: &str| {
            let g = g.as_f64().unwrap_or(f64::NAN);
            let tol = if what == "ki" { 0.05 } else { 0.02 };
            assert!(
                (g - w).abs() <= tol * w.abs().max(1e-9),
                "{} {what}: {g} vs {w}",
                d.name()
            );
        };
        close(&got["kp"], want.kp, "kp");
        if want.ki > 0.0 {
            close(&got["ki"], want.ki, "ki");
        }
        if let Some(kd) = want.kd {
            close(&got["kd"], kd, "kd");
        }
    }
    let ff = &inferred["autopilot"]["restoring_feed_forward"];
    assert!(
        (ff["zg_w_minus_zb_b"].as_f64().unwrap() - 2500.0).abs() < 50.0,
        "{ff}"
    );
    let notes = result["prediction"]["notes"].to_string();
    assert!(notes.contains("inferred from"), "{notes}");
    let r = app
        .call("GET", "/api/campaigns/{id}/precision", &[&cid], None)
        .await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert_finite_json(&r.json, "precision");
}
