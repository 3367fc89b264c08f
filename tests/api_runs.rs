//! Runs end to end: streamed upload stored verbatim, validation errors with
//! line and column, two-file alignment, quality verdicts against simulated
//! truth, plan adherence and campaign coverage. Every documented response is
//! validated against openapi.yaml.

mod common;

use common::sim::{self, all_columns, simulate};
use common::{Resp, TestApp, rov_profile};
use serde_json::{Value, json};

async fn rov_campaign(app: &TestApp, extra: Value) -> (String, String) {
    let r = app
        .call("POST", "/api/vessels", &[], Some(rov_profile()))
        .await;
    let vid = r.json["id"].as_str().unwrap().to_string();
    let mut body = json!({
        "vessel_id": vid,
        "name": "trial",
        "grid": { "unit": "kn", "speeds": [1.0] },
        "families": ["dynamic"],
        "seed": 5
    });
    for (k, v) in extra.as_object().unwrap() {
        body[k] = v.clone();
    }
    let r = app.call("POST", "/api/campaigns", &[], Some(body)).await;
    assert_eq!(r.status, 201, "{}", r.text);
    (vid, r.json["id"].as_str().unwrap().to_string())
}

async fn upload(app: &TestApp, cid: &str, parts: &[(&str, Option<&str>, &str)]) -> Resp {
    let r = app.upload_run(cid, parts).await;
    app.check_contract("POST", "/api/campaigns/{id}/runs", &r);
    r
}

fn verdict<'a>(run: &'a Value, dof: &str) -> &'a Value {
    run["summary"]["verdicts"]
        .as_array()
        .unwrap()
        .iter()
        .find(|v| v["dof"] == dof)
        .unwrap_or_else(|| panic!("no verdict for {dof}: {run}"))
}

#[tokio::test]
async fn single_file_run_is_stored_verbatim_and_scored() {
    let app = TestApp::new().await;
    let (_, cid) = rov_campaign(&app, json!({})).await;
    // Roll is never excited: its verdict must say so; the others are driven hard.
    let run = simulate(
        1,
        10.0,
        900.0,
        [400.0, 800.0, 800.0, 0.0, 600.0, 600.0],
        3.0,
        1e-4,
    );
    let csv = sim::csv(&run, &all_columns(), 100.0, 1);
    let r = upload(
        &app,
        &cid,
        &[
            ("meta", None, r#"{"name": "dive 7"}"#),
            ("file", Some("dive7.csv"), &csv),
        ],
    )
    .await;
    assert_eq!(r.status, 201, "{}", r.text);
    let id = r.json["id"].as_str().unwrap().to_string();
    assert_eq!(r.json["status"], "accepted");
    assert_eq!(r.json["name"], "dive 7");
    assert_eq!(r.json["files"][0]["size_bytes"], csv.len());

    // Byte for byte, with its SHA-256.
    let raw = app.call("GET", "/api/runs/{id}/raw", &[&id], None).await;
    assert_eq!(raw.status, 200);
    assert_eq!(raw.text, csv);
    let sha = r.json["files"][0]["sha256"].as_str().unwrap();
    assert_eq!(sha.len(), 64);

    let got = app.call("GET", "/api/runs/{id}", &[&id], None).await;
    assert_eq!(got.json["summary"]["sample_rate_hz"], 10.0);
    for dof in ["surge", "sway", "heave", "pitch", "yaw"] {
        assert_eq!(
            verdict(&got.json, dof)["verdict"],
            "good",
            "{dof}: {}",
            verdict(&got.json, dof)
        );
    }
    let roll = verdict(&got.json, "roll");
    assert_eq!(roll["verdict"], "insufficient", "{roll}");
    assert!(roll["reason"].as_str().unwrap().contains("roll"), "{roll}");

    let q = app
        .call("GET", "/api/runs/{id}/quality", &[&id], None)
        .await;
    assert_eq!(q.status, 200);
    assert!(q.json["freqs_hz"].as_array().unwrap().len() > 100);

    let list = app
        .call("GET", "/api/campaigns/{id}/runs", &[&cid], None)
        .await;
    assert_eq!(list.json.as_array().unwrap().len(), 1);
}

#[tokio::test]
async fn two_file_run_is_aligned_on_the_shared_depth() {
    let app = TestApp::new().await;
    let (_, cid) = rov_campaign(&app, json!({})).await;
    let run = simulate(
        2,
        20.0,
        900.0,
        [400.0, 800.0, 800.0, 600.0, 600.0, 600.0],
        3.0,
        1e-4,
    );
    // Controller computer: 10 Hz, its clock 5.3 s ahead of the navigation computer's.
    let control = sim::csv(
        &run,
        &["tau_X", "tau_Y", "tau_Z", "tau_K", "tau_M", "tau_N", "z"],
        5.3,
        2,
    );
    let nav = sim::csv(
        &run,
        &[
            "u", "v", "w", "p", "q", "r", "x", "y", "z", "phi", "theta", "psi",
        ],
        0.0,
        1,
    );
    let r = upload(
        &app,
        &cid,
        &[
            ("control", Some("ctrl.csv"), &control),
            ("nav", Some("ins.csv"), &nav),
        ],
    )
    .await;
    assert_eq!(r.status, 201, "{}", r.text);
    assert_eq!(r.json["layout"], "split");
    let al = &r.json["summary"]["alignment"];
    let offset = al["offset"]["offset_s"].as_f64().unwrap();
    // nav time + offset = control time.
    assert!((offset - 5.3).abs() < 0.01, "offset {offset}: {al}");
    let id = r.json["id"].as_str().unwrap();
    let raw = app
        .raw("GET", &format!("/api/runs/{id}/raw?file=nav"), None)
        .await;
    assert_eq!(raw.text, nav);
    let raw = app.call("GET", "/api/runs/{id}/raw", &[id], None).await;
    assert_eq!(raw.status, 400, "a split run needs ?file=");
}

#[tokio::test]
async fn invalid_logs_are_kept_and_named_by_line_and_column() {
    let app = TestApp::new().await;
    let (_, cid) = rov_campaign(&app, json!({})).await;
    let run = simulate(3, 10.0, 60.0, [1.0; 6], 2.0, 0.0);
    let good = sim::csv(&run, &all_columns(), 0.0, 1);
    let mut lines: Vec<String> = good.lines().map(str::to_string).collect();
    // Line 42 of the file (header = 1): put text in tau_K, the 5th column.
    let mut cells: Vec<String> = lines[41].split(',').map(str::to_string).collect();
    cells[4] = "abc".into();
    lines[41] = cells.join(",");
    let bad = lines.join("\n") + "\n";
    let r = upload(&app, &cid, &[("file", Some("bad.csv"), &bad)]).await;
    assert_eq!(r.status, 422, "{}", r.text);
    assert_eq!(r.json["line"], 42);
    assert_eq!(r.json["column"], "tau_K");
    assert_eq!(r.json["field"], "file");
    let id = r.json["run_id"].as_str().unwrap().to_string();
    let raw = app.call("GET", "/api/runs/{id}/raw", &[&id], None).await;
    assert_eq!(raw.text, bad, "nothing is lost");
    let got = app.call("GET", "/api/runs/{id}", &[&id], None).await;
    assert_eq!(got.json["status"], "rejected");
    let q = app
        .call("GET", "/api/runs/{id}/quality", &[&id], None)
        .await;
    assert_eq!(q.status, 404);

    // Missing columns are all named.
    let no_roll = sim::csv(
        &run,
        &[
            "tau_X", "tau_Y", "tau_Z", "tau_M", "tau_N", "u", "v", "w", "q", "r", "x", "y", "z",
            "theta", "psi",
        ],
        0.0,
        1,
    );
    let r = upload(&app, &cid, &[("file", Some("a.csv"), &no_roll)]).await;
    assert_eq!(r.status, 422);
    let m = r.json["message"].as_str().unwrap();
    assert!(
        m.contains("tau_K") && m.contains("phi") && m.contains(", p"),
        "{m}"
    );

    // Semicolons, time going backwards, NaN.
    let r = upload(
        &app,
        &cid,
        &[("file", Some("a.csv"), &good.replace(',', ";"))],
    )
    .await;
    assert_eq!(r.status, 422);
    assert!(r.json["message"].as_str().unwrap().contains(';'));
    let mut l2 = lines.clone();
    l2.swap(10, 11);
    let r = upload(
        &app,
        &cid,
        &[("file", Some("a.csv"), &(l2.join("\n") + "\n"))],
    )
    .await;
    assert_eq!(
        (r.status.as_u16(), r.json["line"].as_u64()),
        (422, Some(12))
    );
    let r = upload(
        &app,
        &cid,
        &[("file", Some("a.csv"), &good.replacen("\n0.5,", "\nNaN,", 1))],
    )
    .await;
    assert_eq!(r.status, 422, "{}", r.text);
}

#[tokio::test]
async fn malformed_uploads_get_clear_4xx() {
    let app = TestApp::with_upload_limit(1 << 20).await;
    let (_, cid) = rov_campaign(&app, json!({})).await;
    let r = app
        .raw(
            "POST",
            &format!("/api/campaigns/{cid}/runs"),
            Some(("text/csv", "t,u\n".into())),
        )
        .await;
    app.check_contract("POST", "/api/campaigns/{id}/runs", &r);
    assert_eq!(r.status, 415);
    let r = upload(&app, &cid, &[("meta", None, "{}")]).await;
    assert_eq!(
        (r.status.as_u16(), r.json["field"].as_str()),
        (400, Some("file"))
    );
    let r = upload(&app, &cid, &[("control", Some("c.csv"), "t,z\n0,1\n")]).await;
    assert_eq!(r.status, 400);
    let r = upload(&app, &cid, &[("data", Some("c.csv"), "t,z\n0,1\n")]).await;
    assert_eq!(
        (r.status.as_u16(), r.json["field"].as_str()),
        (400, Some("data"))
    );
    let r = upload(
        &app,
        &cid,
        &[
            ("meta", None, r#"{"experiment": 1}"#),
            ("file", Some("a.csv"), "t\n"),
        ],
    )
    .await;
    // An unknown metadata field: 422 naming it, nothing recorded.
    assert_eq!(r.status, 422, "{}", r.text);
    assert_eq!(r.json["field"], "meta.experiment");
    let r = upload(&app, &cid, &[("file", Some("a.csv"), "")]).await;
    assert_eq!(r.status, 400);
    // Over the limit: 413, and the partial file is not kept.
    let big = "0,1\n".repeat(300_000);
    let r = upload(&app, &cid, &[("file", Some("big.csv"), &big)]).await;
    assert_eq!(r.status, 413, "{}", r.text);
    let r = app.call("GET", "/api/runs/{id}", &["nope"], None).await;
    assert_eq!(r.status, 404);
    let r = upload(&app, "nope", &[("file", Some("a.csv"), "t\n")]).await;
    assert_eq!(r.status, 404);
}

#[tokio::test]
async fn runs_cover_planned_experiments() {
    let app = TestApp::new().await;
    // Force schedules: the logged τ can be compared with the planned τ directly.
    let (_, cid) = rov_campaign(&app, json!({ "excitation": { "quantity": "force" } })).await;
    let plan = app
        .call("POST", "/api/campaigns/{id}/plan", &[&cid], None)
        .await;
    assert_eq!(plan.status, 201, "{}", plan.text);
    let exp = plan.json["experiments"]
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["code"] == "DYN-1kn-sway-r1")
        .unwrap()
        .clone();
    let eid = exp["id"].as_str().unwrap().to_string();
    let sched = app
        .call(
            "GET",
            "/api/campaigns/{id}/plan/experiments/{eid}",
            &[&cid, &eid],
            None,
        )
        .await;
    let planned: Vec<f64> =
        serde_json::from_value(sched.json["columns"][1]["values"].clone()).unwrap();
    assert_eq!(sched.json["columns"][1]["name"], "tau_Y");
    // Fly it: log the planned sway force at 10 Hz (every 2nd sample of the 20 Hz schedule),
    // starting 7 s into the log, and simulate the response.
    let mut run = simulate(
        4,
        10.0,
        planned.len() as f64 / 20.0 + 20.0,
        [0.0; 6],
        1.0,
        1e-4,
    );
    let n = run.t.len();
    let (a, d) = ((-0.1f64 / 3.0).exp(), 4000.0);
    let mut v = 0.0;
    for k in 0..n {
        let j = (k as isize - 70) * 2;
        let tau = if j >= 0 && (j as usize) < planned.len() {
            planned[j as usize]
        } else {
            0.0
        };
        run.tau[1][k] = tau;
        run.nu[1][k] = v;
        v = a * v + (1.0 - a) * tau / d;
    }
    let csv = sim::csv(&run, &all_columns(), 0.0, 1);
    let meta = json!({ "experiment_id": eid }).to_string();
    let r = upload(
        &app,
        &cid,
        &[("meta", None, &meta), ("file", Some("sway.csv"), &csv)],
    )
    .await;
    assert_eq!(r.status, 201, "{}", r.text);
    assert_eq!(r.json["name"], "DYN-1kn-sway-r1");
    let adherence = &r.json["summary"]["adherence"];
    assert!(
        adherence.to_string().contains("true"),
        "followed the plan: {adherence}"
    );
    assert_eq!(
        verdict(&r.json, "sway")["verdict"],
        "good",
        "{}",
        verdict(&r.json, "sway")
    );

    let c = app
        .call("GET", "/api/campaigns/{id}/coverage", &[&cid], None)
        .await;
    assert_eq!(c.status, 200);
    assert_eq!(c.json["covered"], 1, "{}", c.json);
    assert_eq!(c.json["missing"], 5);
    let row = c.json["experiments"]
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["experiment_id"] == eid.as_str())
        .unwrap();
    assert_eq!(row["status"], "covered");

    // An experiment id from elsewhere is refused.
    let r = upload(
        &app,
        &cid,
        &[
            ("meta", None, r#"{"experiment_id": "zzz"}"#),
            ("file", Some("a.csv"), &csv),
        ],
    )
    .await;
    assert_eq!(r.status, 404);
}
