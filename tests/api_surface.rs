//! A surface vessel's physical 3-DOF model through REST: a DP vessel that
//! logs generalized forces τ, its logs flown by the independent
//! surface-vessel truth (`seatrial_truth::usv`: the supply vessel in SI in
//! a constant current, with its Munk moment, quadratic surge and
//! cross-flow drag) uploaded without a plan and identified by `lambda_kf`:
//! one current for the campaign, the model validated with the heading in
//! the loop; discovery continues from it with the current carried. A
//! vessel logging thruster commands is refused `lambda_kf` at submit.

mod common;

use common::flights::planned_campaign;
use common::{TestApp, dp_profile};
use seatrial::jobs::{JobRegistry, JobsConfig};
use seatrial_core::planning::examples::supply_vessel_trial_campaign;
use seatrial_truth::usv::{self, Current, Effects, SupplyTrial, fly_supply_campaign};
use serde_json::{Value, json};

async fn campaign(app: &TestApp, profile: Value) -> String {
    let mut spec = serde_json::to_value(supply_vessel_trial_campaign(7)).unwrap();
    spec["families"] = json!(["dp_surge", "dp_sway_yaw", "validation"]);
    planned_campaign(app, profile, spec).await.0
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_vessel_logging_forces_gets_a_physical_model_with_its_current() {
    let app = TestApp::with_jobs(JobRegistry::production(), JobsConfig::default()).await;
    let mut profile = dp_profile();
    profile["name"] = json!("supply vessel logging τ, in a current");
    profile["inputs"] = json!({ "kind": "generalized_forces" });
    let cid = campaign(&app, profile).await;
    let (speed, dir) = (0.35, 2.0_f64);
    let effects = Effects::all(Current::Constant {
        speed_mps: speed,
        direction_rad: dir,
    });
    let trial = SupplyTrial {
        effects,
        ..SupplyTrial::default()
    };
    for run in fly_supply_campaign(&usv::supply(), &trial, 3).runs {
        let meta = json!({ "name": run.name });
        let r = app
            .upload_run(
                &cid,
                &[
                    ("meta", None, &meta.to_string()),
                    ("file", Some("log.csv"), &run.csv),
                ],
            )
            .await;
        assert_eq!(r.status, 201, "{}", r.text);
    }
    let job = common::run_job(
        &app,
        json!({ "kind": "identify", "campaign_id": cid, "method": "lambda_kf" }),
    )
    .await;
    let mid = job["result"]["model_id"].as_str().unwrap();
    let m = app.call("GET", "/api/models/{id}", &[mid], None).await;
    assert_eq!(m.status, 200, "{}", m.text);
    let doc = &m.json["document"];
    let current = &doc["lpv"]["current"];
    let est = current["speed_mps"].as_f64().unwrap();
    assert!((est / speed - 1.0).abs() < 0.2, "{current}");
    let beta = current["direction_deg"].as_f64().unwrap();
    let d = (beta - dir.to_degrees()).rem_euclid(360.0);
    assert!(d.min(360.0 - d) < 10.0, "{current}");
    let rows = doc["parameters"].as_array().unwrap();
    let v_c = rows.iter().find(|p| p["symbol"] == "V_c").unwrap();
    assert_eq!(v_c["unit"], "m/s");
    assert!(v_c["std"].as_f64().unwrap() > 0.0);
    // M symmetric positive definite, with the sway–yaw coupling of a ship.
    let mm = &doc["lpv"]["points"][0]["m"];
    let at = |i: usize, j: usize| mm[i][j].as_f64().unwrap();
    assert!((at(1, 2) - at(2, 1)).abs() <= 1e-9 * at(2, 2).abs());
    assert!(at(0, 0) > 0.0 && at(1, 1) * at(2, 2) > at(1, 2) * at(1, 2));
    // Validated on the held-out run with the heading in the loop.
    let report = &m.json["validation"][0]["report"];
    assert_eq!(
        report["inputs"].as_array().unwrap().last().unwrap(),
        "psi",
        "{report:.400}"
    );
    for ch in report["channels"].as_array().unwrap() {
        let fit = ch["fit_simulation"].as_f64().unwrap();
        assert!(fit > 0.6, "{}: free run {fit}", ch["output"]);
    }

    // Discovery continues from the model with its current carried as a
    // term (the logs have no z, φ, θ), and does not name it again.
    let job = common::run_job(
        &app,
        json!({ "kind": "discover", "campaign_id": cid, "model_id": mid }),
    )
    .await;
    let did = job["result"]["discrepancy_id"].as_str().unwrap();
    let d = app
        .call("GET", "/api/discrepancies/{id}", &[did], None)
        .await;
    assert_eq!(d.status, 200, "{}", d.text);
    let report = &d.json["report"];
    let point = &report["points"][0]["report"];
    assert_eq!(
        point["carried"],
        json!([{ "effect": "current" }]),
        "{report:.600}"
    );
    for e in report["effects"].as_array().unwrap() {
        assert_ne!(e["effect"]["effect"], "current", "named again: {e}");
    }
    assert!(
        report["summary"].as_array().unwrap().iter().any(|l| l
            .as_str()
            .unwrap()
            .contains("5 samples of the slowest log (1 Hz)")),
        "{report:.600}"
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_vessel_logging_thruster_commands_is_refused_lambda_kf_at_submit() {
    let app = TestApp::with_jobs(JobRegistry::production(), JobsConfig::default()).await;
    let cid = campaign(&app, dp_profile()).await;
    let r = app
        .call(
            "POST",
            "/api/jobs",
            &[],
            Some(json!({ "kind": "identify", "campaign_id": cid, "method": "lambda_kf" })),
        )
        .await;
    assert_eq!(r.status, 422, "{}", r.text);
    assert!(
        r.text.contains("method") && r.text.contains("parallel_ekf"),
        "{}",
        r.text
    );
}
