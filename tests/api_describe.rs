//! Runs described without a plan, through REST: a run uploaded without
//! metadata is described from its data (`inferred`, with reasons), metadata
//! wins (`user`), a run matched to a planned experiment says `plan`; PATCH
//! sets and `null` clears user values; refusals are 422s naming the field.
//! An identification over runs uploaded without experiment ids holds out
//! the inferred validation run and keeps static runs out of the estimation.

mod common;

use common::TestApp;
use common::flights::{flown_logs, linear_truth};
use common::wait_for_job;
use seatrial::jobs::{JobRegistry, JobsConfig};
use seatrial_core::planning::KNOT;
use serde_json::{Value, json};

async fn upload(app: &TestApp, cid: &str, code: &str, csv: &str, meta: Option<Value>) -> Value {
    let meta = meta.map(|m| m.to_string());
    let file = format!("{code}.csv");
    let mut parts = vec![("file", Some(file.as_str()), csv)];
    if let Some(m) = &meta {
        parts.insert(0, ("meta", None, m.as_str()));
    }
    let r = app.upload_run(cid, &parts).await;
    app.check_contract("POST", "/api/campaigns/{id}/runs", &r);
    assert_eq!(r.status, 201, "{code}: {}", r.text);
    r.json
}

fn log<'a>(logs: &'a [(String, String)], code: &str) -> &'a str {
    &logs
        .iter()
        .find(|(c, _)| c == code)
        .unwrap_or_else(|| panic!("{code} not flown"))
        .1
}

async fn patch(app: &TestApp, rid: &str, body: Value) -> common::Resp {
    app.call("PATCH", "/api/runs/{id}", &[rid], Some(body))
        .await
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn runs_are_described_by_the_supervisor_the_plan_or_their_data() {
    let app = TestApp::new().await;
    let spec = json!({
        "name": "described", "seed": 4,
        "grid": { "unit": "kn", "speeds": [1.0, 2.0] },
        "families": ["static", "dynamic"]
    });
    let keep = |c: &str| ["DYN-1kn-sway-r1", "STA-2kn-surge-r1", "DYN-2kn-yaw-r1"].contains(&c);
    let (cid, plan, logs) = flown_logs(&app, spec, &linear_truth(), keep).await;

    // No metadata: everything inferred, with reasons.
    let run = upload(&app, &cid, "a", log(&logs, "DYN-1kn-sway-r1"), None).await;
    let rid = run["id"].as_str().unwrap().to_string();
    let d = &run["description"];
    for f in ["role", "grid_speed_mps", "excited_dofs", "signal"] {
        assert_eq!(d[f]["source"], "inferred", "{f}: {d}");
        assert!(!d[f]["reason"].as_str().unwrap().is_empty(), "{f}: {d}");
    }
    assert_eq!(d["role"]["value"], "dynamic");
    assert_eq!(d["family"], "dynamic");
    assert_eq!(d["excited_dofs"]["value"], json!(["sway"]));
    let g = d["grid_speed_mps"]["value"].as_f64().unwrap();
    assert!((g - KNOT).abs() < 1e-9, "{g}");
    assert!(
        d["grid_speed_mps"]["reason"]
            .as_str()
            .unwrap()
            .contains("1.00 kn"),
        "{d}"
    );
    assert!(d["notes"].is_null());
    assert_eq!(d["inferred"]["dofs"].as_array().unwrap().len(), 6);
    // No plan: no adherence, and no verdict sends the pilot back to a schedule.
    assert_eq!(run["summary"]["adherence"], json!([]));
    for v in run["summary"]["verdicts"].as_array().unwrap() {
        let reason = v["reason"].as_str().unwrap();
        assert!(!reason.contains("planned schedule"), "{reason}");
    }

    // A held run at 2 kn: static, nothing excited.
    let sta = upload(&app, &cid, "b", log(&logs, "STA-2kn-surge-r1"), None).await;
    let d = &sta["description"];
    assert_eq!(d["role"]["value"], "static", "{d}");
    assert_eq!(d["excited_dofs"]["value"], json!([]));
    let g = d["grid_speed_mps"]["value"].as_f64().unwrap();
    assert!((g - 2.0 * KNOT).abs() < 1e-9, "{g}");

    // Metadata wins, the speed in knots is stored in m/s.
    let meta = json!({
        "name": "yaw by team B", "role": "validation", "grid_speed_kn": 1.5,
        "excited_dofs": ["yaw", "sway"], "signal": "square", "notes": "  flown by team B  "
    });
    let user = upload(&app, &cid, "c", log(&logs, "DYN-2kn-yaw-r1"), Some(meta)).await;
    let d = &user["description"];
    for f in ["role", "grid_speed_mps", "excited_dofs", "signal", "notes"] {
        assert_eq!(d[f]["source"], "user", "{f}: {d}");
    }
    assert_eq!(d["role"]["value"], "validation");
    assert_eq!(d["family"], "validation");
    assert!((d["grid_speed_mps"]["value"].as_f64().unwrap() - 1.5 * KNOT).abs() < 1e-12);
    assert_eq!(d["excited_dofs"]["value"], json!(["sway", "yaw"]));
    assert_eq!(d["notes"]["value"], "flown by team B");
    // What the data say is still there to compare with.
    assert_eq!(d["inferred"]["role"], "dynamic");
    assert_eq!(d["inferred"]["excited_dofs"], json!(["yaw"]));

    // Matched to a planned experiment: the plan's values.
    let eid = plan["experiments"]
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["code"] == "DYN-1kn-sway-r1")
        .unwrap()["id"]
        .as_str()
        .unwrap()
        .to_string();
    let planned = upload(
        &app,
        &cid,
        "d",
        log(&logs, "DYN-1kn-sway-r1"),
        Some(json!({ "experiment_id": eid })),
    )
    .await;
    let d = &planned["description"];
    for f in ["role", "grid_speed_mps", "excited_dofs", "signal"] {
        assert_eq!(d[f]["source"], "plan", "{f}: {d}");
        assert!(d[f]["reason"].as_str().unwrap().contains("DYN-1kn-sway-r1"));
    }
    assert_eq!(d["signal"]["value"], "prbs");

    // PATCH: set, then null reverts to the inferred value.
    let r = patch(
        &app,
        &rid,
        json!({ "role": "validation", "grid_speed_mps": 0.6 }),
    )
    .await;
    assert_eq!(r.status, 200, "{}", r.text);
    let d = &r.json["description"];
    assert_eq!(
        (d["role"]["value"].clone(), d["role"]["source"].clone()),
        (json!("validation"), json!("user"))
    );
    assert_eq!(d["grid_speed_mps"]["value"], 0.6);
    assert_eq!(d["excited_dofs"]["source"], "inferred", "untouched");
    let r = patch(&app, &rid, json!({ "notes": "checked" })).await;
    assert_eq!(r.json["description"]["role"]["source"], "user", "kept");
    let r = patch(&app, &rid, json!({ "role": null, "grid_speed_kn": null })).await;
    assert_eq!(r.status, 200, "{}", r.text);
    let d = &r.json["description"];
    assert_eq!(d["role"]["source"], "inferred");
    assert_eq!(d["role"]["value"], "dynamic");
    assert_eq!(d["grid_speed_mps"]["source"], "inferred");
    assert_eq!(d["notes"]["value"], "checked");
    // The runs list carries the same descriptions.
    let list = app
        .call("GET", "/api/campaigns/{id}/runs", &[&cid], None)
        .await;
    let a = list
        .json
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["id"] == rid.as_str())
        .unwrap();
    assert_eq!(a["description"]["notes"]["value"], "checked");
    // A planned run's role can be corrected too: the user wins over the plan.
    let pid = planned["id"].as_str().unwrap();
    let r = patch(&app, pid, json!({ "role": "static" })).await;
    assert_eq!(r.json["description"]["role"]["source"], "user");
    assert_eq!(r.json["description"]["family"], "static");
    let r = patch(&app, pid, json!({ "role": null })).await;
    assert_eq!(r.json["description"]["role"]["source"], "plan");

    // Refusals: 422 naming the field, nothing changed.
    for (body, field) in [
        (json!({ "role": "dynamics" }), "role"),
        (json!({ "grid_speed_mps": -0.1 }), "grid_speed_mps"),
        (json!({ "grid_speed_kn": 9.0 }), "grid_speed_kn"),
        (
            json!({ "grid_speed_mps": 0.5, "grid_speed_kn": 1.0 }),
            "grid_speed_kn",
        ),
        (
            json!({ "excited_dofs": ["surge", "drift"] }),
            "excited_dofs[1]",
        ),
        (
            json!({ "excited_dofs": ["surge", "surge"] }),
            "excited_dofs[1]",
        ),
        (json!({ "signal": "chirp" }), "signal"),
        (json!({ "notes": "x".repeat(2001) }), "notes"),
        (json!({ "colour": "red" }), "colour"),
        (json!({ "grid_speed_mps": "fast" }), "grid_speed_mps"),
    ] {
        let r = patch(&app, &rid, body.clone()).await;
        assert_eq!(r.status, 422, "{body}: {}", r.text);
        assert_eq!(r.json["field"], field, "{body}: {}", r.text);
    }
    let r = patch(&app, &rid, json!({ "notes": "x".repeat(2001) })).await;
    assert_eq!(r.json["limit"], 2000.0);
    let r = patch(&app, &rid, json!({ "grid_speed_kn": 9.0 })).await;
    assert!(
        (r.json["limit"].as_f64().unwrap() - 4.3).abs() < 1e-9,
        "{}",
        r.text
    );
    let r = app.call("GET", "/api/runs/{id}", &[&rid], None).await;
    assert_eq!(r.json["description"]["role"]["source"], "inferred");
    assert_eq!(r.json["description"]["notes"]["value"], "checked");
    let r = patch(&app, "nope", json!({ "role": "static" })).await;
    assert_eq!(r.status, 404);
    let r = app
        .raw(
            "PATCH",
            &format!("/api/runs/{rid}"),
            Some(("application/json", "{\"role\":".into())),
        )
        .await;
    assert_eq!(r.status, 400, "{}", r.text);

    // Upload metadata is checked the same way, before anything is recorded.
    let before = app
        .call("GET", "/api/campaigns/{id}/runs", &[&cid], None)
        .await;
    for (meta, field) in [
        (json!({ "role": "warmup" }), "meta.role"),
        (json!({ "grid_speed_kn": -1 }), "meta.grid_speed_kn"),
        (
            json!({ "excited_dofs": ["sway", "sway"] }),
            "meta.excited_dofs[1]",
        ),
        (json!({ "color": "red" }), "meta.color"),
    ] {
        let m = meta.to_string();
        let r = app
            .upload_run(
                &cid,
                &[("meta", None, &m), ("file", Some("x.csv"), "t\n0\n")],
            )
            .await;
        app.check_contract("POST", "/api/campaigns/{id}/runs", &r);
        assert_eq!(r.status, 422, "{meta}: {}", r.text);
        assert_eq!(r.json["field"], field, "{meta}: {}", r.text);
    }
    let after = app
        .call("GET", "/api/campaigns/{id}/runs", &[&cid], None)
        .await;
    assert_eq!(
        before.json.as_array().unwrap().len(),
        after.json.as_array().unwrap().len()
    );

    // Coverage: the planned run covers its experiment; the others are
    // unassigned, not failures of adherence.
    let c = app
        .call("GET", "/api/campaigns/{id}/coverage", &[&cid], None)
        .await;
    assert_eq!(c.status, 200);
    let unassigned = c.json["unassigned_runs"].as_array().unwrap();
    assert_eq!(unassigned.len(), 3, "{}", c.json);
    assert!(!unassigned.contains(&json!(pid)));
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_dp_vessel_refuses_dofs_and_roles_it_does_not_have() {
    let app = TestApp::new().await;
    let r = app
        .call("POST", "/api/vessels", &[], Some(common::dp_profile()))
        .await;
    let vid = r.json["id"].as_str().unwrap();
    let r = app
        .call(
            "POST",
            "/api/campaigns",
            &[],
            Some(json!({
                "vessel_id": vid, "name": "dp", "grid": { "unit": "kn", "speeds": [0.0] },
                "families": ["dp_surge", "dp_sway_yaw", "dp_azimuth"]
            })),
        )
        .await;
    assert_eq!(r.status, 201, "{}", r.text);
    let cid = r.json["id"].as_str().unwrap();
    for (meta, field) in [
        (
            json!({ "excited_dofs": ["surge", "heave"] }),
            "meta.excited_dofs[1]",
        ),
        (json!({ "role": "static" }), "meta.role"),
    ] {
        let m = meta.to_string();
        let r = app
            .upload_run(
                cid,
                &[("meta", None, &m), ("file", Some("x.csv"), "t\n0\n")],
            )
            .await;
        assert_eq!(r.status, 422, "{meta}: {}", r.text);
        assert_eq!(r.json["field"], field, "{}", r.text);
        assert!(r.json["message"].as_str().unwrap().len() > 10);
    }
}

/// A campaign flown as another team would and uploaded without experiment
/// ids: the static runs, the recursive runs and the validation run are told
/// apart from the data, and the identification uses them so.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn identification_uses_the_inferred_roles_of_unplanned_runs() {
    let app = TestApp::with_jobs(JobRegistry::production(), JobsConfig::default()).await;
    let spec = json!({
        "name": "another team", "seed": 11, "repetitions": 2,
        "grid": { "unit": "kn", "speeds": [1.0, 2.0] },
        "families": ["static", "recursive", "validation"]
    });
    let statics = ["STA-1kn-sway+-r1", "STA-2kn-heave+-r1", "STA-2kn-surge-r1"];
    let keep = |c: &str| c.starts_with("REC") || c == "VAL-r1" || statics.contains(&c);
    let (cid, _, logs) = flown_logs(&app, spec, &linear_truth(), keep).await;
    assert_eq!(logs.len(), 8);
    let mut ids = std::collections::BTreeMap::new();
    for (code, csv) in &logs {
        let run = upload(&app, &cid, code, csv, None).await;
        let role = &run["description"]["role"];
        assert_eq!(role["source"], "inferred");
        let want = match &code[..3] {
            "STA" => "static",
            "REC" => "recursive",
            _ => "validation",
        };
        assert_eq!(role["value"], want, "{code}: {role}");
        ids.insert(code.clone(), run["id"].as_str().unwrap().to_string());
    }
    let r = app
        .call(
            "POST",
            "/api/jobs",
            &[],
            Some(json!({ "kind": "identify", "campaign_id": cid, "method": "lambda_kf" })),
        )
        .await;
    assert_eq!(r.status, 202, "{}", r.text);
    let job = wait_for_job(&app, r.json["id"].as_str().unwrap(), 120).await;
    assert_eq!(job["state"], "succeeded", "{job}");
    let mid = job["result"]["model_id"].as_str().unwrap();
    let m = app.call("GET", "/api/models/{id}", &[mid], None).await;
    let mut est: Vec<String> = serde_json::from_value(m.json["run_ids"].clone()).unwrap();
    est.sort();
    // Estimation data: the recursive runs and the static runs (flown at a
    // grid speed, so data at that speed); never the held-out run.
    let mut rec: Vec<String> = ids
        .iter()
        .filter(|(c, _)| !c.starts_with("VAL"))
        .map(|(_, id)| id.clone())
        .collect();
    rec.sort();
    assert_eq!(est, rec, "estimation runs: all but the validation run");
    assert_eq!(m.json["validation_run_ids"], json!([ids["VAL-r1"]]));
    // The λ model has a sub-model at both grid speeds (inferred speeds).
    let points = m.json["document"]["lpv"]["points"].as_array().unwrap();
    assert_eq!(points.len(), 2, "{}", m.json["document"]["notes"]);
}

/// The supply vessel's SI1–SI3 manoeuvres and validation runs uploaded
/// without experiment ids: the manoeuvre is inferred from the thrusters each
/// run drives, and the parallel EKF stages the runs by it.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_dp_campaign_without_a_plan_is_staged_by_the_thrusters_it_drives() {
    use seatrial_core::planning::examples::{supply_vessel, supply_vessel_trial_campaign};
    use seatrial_core::simulation::dp_ship::{DpFlightSettings, DpShip, fly_dp_campaign};
    let app = TestApp::with_jobs(JobRegistry::production(), JobsConfig::default()).await;
    let spec = supply_vessel_trial_campaign(1995);
    let (cid, _) = common::flights::planned_campaign(
        &app,
        common::dp_profile(),
        serde_json::to_value(&spec).unwrap(),
    )
    .await;
    let profile = supply_vessel();
    let plan = seatrial_core::planning::generate_plan(&profile, &spec).unwrap();
    let flown = fly_dp_campaign(
        &profile,
        &DpShip::supply_vessel(),
        &plan,
        &DpFlightSettings::supply_vessel(2024),
        |_| true,
    )
    .unwrap();
    for f in &flown {
        let run = upload(&app, &cid, &f.code, &f.csv, None).await;
        let d = &run["description"];
        assert_eq!(d["role"]["source"], "inferred");
        assert_eq!(
            d["family"],
            f.family.name(),
            "{}: {}",
            f.code,
            d["role"]["reason"]
        );
    }
    let r = app
        .call(
            "POST",
            "/api/jobs",
            &[],
            Some(json!({ "kind": "identify", "campaign_id": cid, "method": "parallel_ekf" })),
        )
        .await;
    assert_eq!(r.status, 202, "{}", r.text);
    let job = wait_for_job(&app, r.json["id"].as_str().unwrap(), 120).await;
    assert_eq!(job["state"], "succeeded", "{job}");
}
