//! DP identification end to end through REST: the supply vessel's planned
//! SI1–SI3 manoeuvres and validation run are flown by the DP ship truth
//! (Fossen et al. 1995), uploaded, identified by the `parallel_ekf` job, and
//! the stored model is fetched, discretized, exported and compared. Every
//! response is checked against openapi.yaml.

mod common;

use common::flights::{planned_campaign, upload_planned};
use common::{TestApp, dp_profile, rov_profile};
use seatrial::jobs::{JobRegistry, JobsConfig};
use seatrial_core::planning::examples::{supply_vessel, supply_vessel_trial_campaign};
use seatrial_core::planning::generate_plan;
use seatrial_core::simulation::dp_ship::{DpFlightSettings, DpShip, fly_dp_campaign, paper};
use serde_json::{Value, json};

async fn app() -> TestApp {
    TestApp::with_jobs(JobRegistry::production(), JobsConfig::default()).await
}

/// Creates the supply vessel and its trial campaign, flies every planned
/// experiment through the DP truth and uploads the logs.
async fn flown_dp_campaign(app: &TestApp) -> String {
    let spec = supply_vessel_trial_campaign(1995);
    let (cid, plan) =
        planned_campaign(app, dp_profile(), serde_json::to_value(&spec).unwrap()).await;
    let profile = supply_vessel();
    let core_plan = generate_plan(&profile, &spec).unwrap();
    let flown = fly_dp_campaign(
        &profile,
        &DpShip::supply_vessel(),
        &core_plan,
        &DpFlightSettings::supply_vessel(2024),
        |_| true,
    )
    .unwrap();
    assert_eq!(flown.len(), 8);
    for run in flown {
        upload_planned(app, &cid, &plan, &run.code, &run.csv).await;
    }
    cid
}

async fn wait_for(app: &TestApp, job_id: &str) -> Value {
    common::wait_for_job(app, job_id, 120).await
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn parallel_ekf_identifies_the_supply_vessel_through_rest() {
    let app = app().await;
    let cid = flown_dp_campaign(&app).await;
    let submit = json!({ "kind": "identify", "campaign_id": cid, "method": "parallel_ekf", "settings": { "sweeps": 2 } });
    let r = app.call("POST", "/api/jobs", &[], Some(submit)).await;
    assert_eq!(r.status, 202, "{}", r.text);
    let job = wait_for(&app, r.json["id"].as_str().unwrap()).await;
    assert_eq!(job["state"], "succeeded", "{job}");
    let mid = job["result"]["model_id"].as_str().unwrap().to_string();

    let m = app.call("GET", "/api/models/{id}", &[&mid], None).await;
    assert_eq!(m.status, 200, "{}", m.text);
    assert_eq!(m.json["model"]["kind"], "dp_ship");
    assert_eq!(m.json["model"]["method"], "parallel_ekf");
    let doc = &m.json["document"];
    assert_eq!(doc["kind"], "dp_ship");
    let theta = doc["dp_ship"]["theta"].as_array().unwrap();
    for (p, (est, truth)) in theta.iter().zip(paper::THETA).enumerate() {
        let err = est.as_f64().unwrap() / truth - 1.0;
        assert!(err.abs() < 0.05, "θ″{}: {est} vs {truth}", p + 1);
    }
    assert_eq!(doc["parameters"].as_array().unwrap().len(), 9);
    assert!(doc["parameters"][0]["std"].as_f64().unwrap() > 0.0);
    // The refinement after the staging is on by default and says what it did.
    let rec = &doc["dp_ship"]["refinement"];
    assert!(rec["applied"].is_boolean(), "{rec}");
    assert_eq!(rec["ekf_theta"].as_array().unwrap().len(), 9, "{rec}");
    assert_eq!(rec["ekf_theta_std"].as_array().unwrap().len(), 9, "{rec}");
    if rec["applied"] == true {
        assert!(rec["iterations"].as_u64().unwrap() >= 1, "{rec}");
        assert_eq!(rec["std_inflation"].as_array().unwrap().len(), 9, "{rec}");
    } else {
        assert!(
            rec["reason"].as_str().is_some_and(|r| !r.is_empty()),
            "{rec}"
        );
    }
    assert_eq!(doc["structure_findings"].as_array().unwrap().len(), 0);
    // Validation on the held-out run in x, y, ψ.
    assert_eq!(m.json["validation_run_ids"].as_array().unwrap().len(), 2);
    let rep = &m.json["validation"][0]["report"];
    let outputs: Vec<&str> = rep["channels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["output"].as_str().unwrap())
        .collect();
    assert_eq!(outputs, ["x", "y", "psi"]);
    for ch in rep["channels"].as_array().unwrap() {
        let fit = ch["fit_k_step"].as_f64().unwrap();
        assert!(fit > 0.8, "{}: k-step fit {fit}", ch["output"]);
    }

    // ZOH matrices of ν (SI) at the controller's h.
    let d = app.call("GET", "/api/models/{id}?h=1", &[&mid], None).await;
    assert_eq!(d.status, 200, "{}", d.text);
    let p = &d.json["discrete"]["points"][0];
    assert_eq!(p["phi"].as_array().unwrap().len(), 3);
    assert_eq!(p["gamma"][0].as_array().unwrap().len(), 6);
    let phi11 = p["phi"][0][0].as_f64().unwrap();
    let want = (paper::A_STATE_SPACE[0][0] / paper::bis_time_unit_s()).exp();
    assert!(
        (phi11 - want).abs() < 0.05 * (1.0 - want),
        "Φ11 {phi11} vs {want}"
    );

    // Exports: CSV parameter table, and the Fossen form with M, D, T, K.
    let csv = app
        .call("GET", "/api/models/{id}/export?format=csv", &[&mid], None)
        .await;
    assert_eq!(csv.status, 200);
    assert_eq!(csv.text.lines().count(), 10);
    let json_export = app
        .call("GET", "/api/models/{id}/export?format=json", &[&mid], None)
        .await;
    assert_eq!(json_export.status, 200);
    let f = app
        .call(
            "GET",
            "/api/models/{id}/export?format=fossen",
            &[&mid],
            None,
        )
        .await;
    assert_eq!(f.status, 200, "{}", f.text);
    assert_eq!(f.json["points"][0]["M"][1][2], -0.0744);
    assert_eq!(f.json["T"][2][4], 0.4554);
    assert_eq!(f.json["K"].as_array().unwrap().len(), 6);
    let d22 = f.json["points"][0]["D"][1][1].as_f64().unwrap();
    assert!(d22 > 0.0, "D″22 {d22}");
    assert!(f.json["units"].as_str().unwrap().contains("76.2"));

    // Side by side on the held-out run: the stored validation again.
    let val = m.json["validation_run_ids"][0]
        .as_str()
        .unwrap()
        .to_string();
    let c = app
        .call(
            "GET",
            "/api/models/compare?a={a}&b={b}&run_id={r}",
            &[&mid, &mid, &val],
            None,
        )
        .await;
    assert_eq!(c.status, 200, "{}", c.text);
    let fit = |m: &Value| m["report"]["channels"][2]["fit_k_step"].as_f64().unwrap();
    let stored = rep["channels"][2]["fit_k_step"].as_f64().unwrap();
    assert!((fit(&c.json["models"][0]) - stored).abs() < 1e-9);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn parallel_ekf_bad_requests_name_the_field() {
    let app = app().await;
    let cid = flown_dp_campaign(&app).await;
    let post = |body: Value| {
        let app = &app;
        async move { app.call("POST", "/api/jobs", &[], Some(body)).await }
    };
    let named = |r: &common::Resp| {
        (
            r.status.as_u16(),
            r.json["field"].as_str().map(String::from),
        )
    };
    let r = post(json!({ "kind": "identify", "campaign_id": cid, "method": "parallel_ekf", "settings": { "sweeps": "two" } })).await;
    assert_eq!(
        named(&r),
        (422, Some("settings.sweeps".into())),
        "{}",
        r.text
    );
    let r = post(json!({ "kind": "identify", "campaign_id": cid, "method": "parallel_ekf", "settings": { "q_thetaa": 0 } })).await;
    assert_eq!(r.status, 422, "{}", r.text);
    assert!(r.json["field"].as_str().unwrap().starts_with("settings"));
    let r = post(json!({ "kind": "identify", "campaign_id": cid, "method": "lambda_kf" })).await;
    assert_eq!(named(&r), (422, Some("method".into())), "{}", r.text);
    // A setting the numerics refuse is refused at submission, naming it.
    let r = post(json!({ "kind": "identify", "campaign_id": cid, "method": "parallel_ekf", "settings": { "theta_init": [1, 2] } })).await;
    assert_eq!(
        named(&r),
        (422, Some("settings.theta_init".into())),
        "{}",
        r.text
    );

    // parallel_ekf on a ROV campaign: 422 naming the method.
    let v = app
        .call("POST", "/api/vessels", &[], Some(rov_profile()))
        .await;
    let spec = json!({
        "vessel_id": v.json["id"], "name": "rov", "grid": { "unit": "kn", "speeds": [1.0, 2.0] },
        "families": ["recursive", "validation"], "seed": 1
    });
    let c = app.call("POST", "/api/campaigns", &[], Some(spec)).await;
    assert_eq!(c.status, 201, "{}", c.text);
    let r =
        post(json!({ "kind": "identify", "campaign_id": c.json["id"], "method": "parallel_ekf" }))
            .await;
    assert_eq!(named(&r), (422, Some("method".into())), "{}", r.text);
}
