//! Experiment design through REST: the `design` job designs the campaign
//! for the most precision within a ship-time budget, exactly as the core
//! does; `GET /api/campaigns/{id}/design` serves it; re-planning with the
//! designed spec adopts it (the plan then takes the design's hours, and the
//! stored design is no longer current). Requests the job cannot use are
//! 422s naming the field. Every response is checked against openapi.yaml.

mod common;

use common::TestApp;
use common::finite::assert_finite_json;
use common::flights::planned_campaign;
use seatrial::jobs::{JobRegistry, JobsConfig};
use seatrial_core::design::{Prior, design_campaign};
use seatrial_core::estimation::NoProgress;
use seatrial_core::planning::CampaignSpec;
use seatrial_core::planning::examples::surveyor_rov;
use serde_json::{Value, json};

async fn app() -> TestApp {
    TestApp::with_jobs(JobRegistry::production(), JobsConfig::default()).await
}

/// A two-speed Surveyor campaign with every family.
fn spec() -> Value {
    json!({
        "name": "design",
        "grid": { "unit": "kn", "speeds": [0.0, 1.5] },
        "families": ["static", "dynamic", "recursive", "validation"],
        "seed": 11
    })
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_design_is_the_cores_and_adopting_it_replans_the_campaign() {
    let app = app().await;
    let (cid, plan) = planned_campaign(&app, common::rov_profile(), spec()).await;
    let none = app
        .call("GET", "/api/campaigns/{id}/design", &[&cid], None)
        .await;
    assert_eq!(none.status, 404, "{}", none.text);
    assert!(none.text.contains("design"), "{}", none.text);

    let job = common::run_job(
        &app,
        json!({ "kind": "design", "campaign_id": cid, "settings": { "prior": "reference" } }),
    )
    .await;
    let r = app
        .call("GET", "/api/campaigns/{id}/design", &[&cid], None)
        .await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert_finite_json(&r.json, "design");
    assert_eq!(r.json["current"], true);
    assert_eq!(r.json["job_id"], job["id"]);
    assert_eq!(r.json["prior"]["kind"], "reference");
    let d = &r.json["design"];
    let plan_hours = plan["totals"]["total_time_s"].as_f64().unwrap() / 3600.0;
    assert!((d["budget_hours"].as_f64().unwrap() - plan_hours).abs() < 1e-9);

    // The same design as the core on the same campaign and prior.
    let c = app.call("GET", "/api/campaigns/{id}", &[&cid], None).await;
    let campaign: CampaignSpec = serde_json::from_value(c.json["spec"].clone()).unwrap();
    let profile = surveyor_rov();
    let Prior::Rov(truth) = Prior::reference(&profile).unwrap() else {
        panic!("an ROV prior")
    };
    let core = design_campaign(&profile, &campaign, &truth, None, &mut NoProgress).unwrap();
    assert_eq!(
        d["design"]["criterion"].as_f64().unwrap(),
        core.design.criterion
    );
    assert_eq!(d["hours_ratio"].as_f64().unwrap(), core.hours_ratio);
    assert!(core.design.criterion < core.current.criterion);
    assert!(d["designed_front"].as_array().unwrap().len() >= 2);
    assert!(d["rule_front"].as_array().unwrap().len() >= 2);

    // Adopt it: re-plan with the designed families, repetitions,
    // excitation and durations.
    let s = &d["spec"];
    let body = json!({
        "families": s["families"],
        "repetitions": s["repetitions"],
        "excitation": s["excitation"],
        "durations": s["durations"],
    });
    let re = app
        .call("POST", "/api/campaigns/{id}/plan", &[&cid], Some(body))
        .await;
    assert_eq!(re.status, 201, "{}", re.text);
    let hours = re.json["totals"]["total_time_s"].as_f64().unwrap() / 3600.0;
    assert!((hours - d["design"]["hours"].as_f64().unwrap()).abs() < 1e-9);
    let r = app
        .call("GET", "/api/campaigns/{id}/design", &[&cid], None)
        .await;
    assert_eq!(r.json["current"], false);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn unusable_design_requests_are_422_naming_the_field() {
    let app = app().await;
    let (cid, _) = planned_campaign(&app, common::rov_profile(), spec()).await;
    for (body, field) in [
        (
            json!({ "kind": "design", "campaign_id": cid, "settings": { "budget_hours": 0 } }),
            "settings.budget_hours",
        ),
        (
            json!({ "kind": "design", "campaign_id": cid, "settings": { "budget_hours": 1e9 } }),
            "settings.budget_hours",
        ),
        (
            json!({ "kind": "design", "campaign_id": cid, "settings": { "budget": 3 } }),
            "settings",
        ),
        (
            json!({ "kind": "design", "campaign_id": cid, "settings": { "prior": "model" } }),
            "model_id",
        ),
        (
            json!({ "kind": "design", "campaign_id": cid, "method": "lambda_kf" }),
            "method",
        ),
        (json!({ "kind": "design" }), "campaign_id"),
    ] {
        common::assert_job_refused(&app, body, field).await;
    }
    // DP ships are designed by another estimator's information: refused.
    let (dp, _) = planned_campaign(
        &app,
        common::dp_profile(),
        serde_json::to_value(seatrial_core::planning::examples::supply_vessel_trial_campaign(1))
            .unwrap(),
    )
    .await;
    let r = app
        .call(
            "POST",
            "/api/jobs",
            &[],
            Some(json!({ "kind": "design", "campaign_id": dp })),
        )
        .await;
    assert_eq!(r.status, 422, "{}", r.text);
    assert_eq!(r.json["field"], "campaign_id");
    // A budget below the shortest plan that covers the grid fails the job
    // naming the budget and the minimum.
    let r = app
        .call(
            "POST",
            "/api/jobs",
            &[],
            Some(json!({ "kind": "design", "campaign_id": cid, "settings": { "budget_hours": 0.1 } })),
        )
        .await;
    assert_eq!(r.status, 202, "{}", r.text);
    let job = common::wait_for_job(&app, r.json["id"].as_str().unwrap(), 120).await;
    assert_eq!(job["state"], "failed", "{job}");
    let err = job["error"].to_string();
    assert!(
        err.contains("settings.budget_hours") && err.contains("shortest plan"),
        "{err}"
    );
}
