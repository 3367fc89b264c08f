//! Identification end to end through REST: a planned ROV campaign is flown
//! by the truth simulator, its logs uploaded, an `identify` job runs to
//! completion in the background, and the stored model is fetched, exported,
//! discretized and versioned. Every response is checked against openapi.yaml.

mod common;

use common::TestApp;
use common::flights::{flown_campaign, linear_truth};
use common::wait_for_job;
use seatrial::jobs::{JobRegistry, JobsConfig};
use serde_json::{Value, json};

async fn app() -> TestApp {
    TestApp::with_jobs(JobRegistry::production(), JobsConfig::default()).await
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn identify_job_stores_a_validated_versioned_lpv_model() {
    let app = app().await;
    let cid = flown_campaign(&app, &linear_truth()).await;
    let submit =
        json!({ "kind": "identify", "campaign_id": cid, "method": "lambda_kf", "settings": {} });
    let r = app
        .call("POST", "/api/jobs", &[], Some(submit.clone()))
        .await;
    assert_eq!(r.status, 202, "{}", r.text);
    let job = wait_for_job(&app, r.json["id"].as_str().unwrap(), 60).await;
    assert_eq!(job["state"], "succeeded", "{job}");
    assert_eq!(job["progress"], 1.0);
    let mid = job["result"]["model_id"].as_str().unwrap().to_string();

    let m = app.call("GET", "/api/models/{id}", &[&mid], None).await;
    assert_eq!(m.status, 200, "{}", m.text);
    let doc = &m.json["document"];
    assert_eq!(doc["kind"], "lpv");
    let points = doc["lpv"]["points"].as_array().unwrap();
    assert_eq!(points.len(), 2, "one sub-model per grid speed");
    // M of the truth is speed independent: surge mass 5800 kg at both points.
    for p in points {
        let m11 = p["m"][0][0].as_f64().unwrap();
        assert!(
            (m11 - 5800.0).abs() < 0.15 * 5800.0,
            "M[surge,surge] = {m11}"
        );
        assert!(p["m_std"][0][0].as_f64().unwrap() > 0.0);
    }
    assert_eq!(m.json["model"]["version"], 1);
    assert!(!m.json["validation_run_ids"].as_array().unwrap().is_empty());
    // Validation on the held-out run: fits for every channel, residual tests.
    let rep = &m.json["validation"][0]["report"];
    for ch in rep["channels"].as_array().unwrap() {
        let fit = ch["fit_one_step"].as_f64().unwrap();
        assert!(fit > 0.5, "{}: 1-step fit {fit}", ch["output"]);
        assert!(ch["fit_simulation"].is_number() || ch["fit_simulation"].is_null());
        // The model of a linear truth never diverges; restarted every 10 s
        // from the measured ν it stays on the recording.
        assert_eq!(ch["restarted"]["diverged"], 0, "{}", ch["verdict"]);
        assert!(ch["diverged"]["simulation"].is_null(), "{}", ch["verdict"]);
        let restarted = ch["fit_restarted"].as_f64().unwrap();
        assert!(
            restarted > 0.5,
            "{}: restarted fit {restarted}",
            ch["output"]
        );
    }

    // ZOH matrices at the controller's h.
    let d = app
        .call("GET", "/api/models/{id}?h=0.05", &[&mid], None)
        .await;
    assert_eq!(d.status, 200, "{}", d.text);
    assert_eq!(d.json["discrete"]["points"].as_array().unwrap().len(), 2);
    let bad = app
        .call("GET", "/api/models/{id}?h=-1", &[&mid], None)
        .await;
    assert_eq!(bad.status, 422);
    assert_eq!(bad.json["field"], "h");
    let bad = app
        .call("GET", "/api/models/{id}?h=abc", &[&mid], None)
        .await;
    assert_eq!(bad.status, 400, "{}", bad.text);

    // Exports.
    let csv = app
        .call("GET", "/api/models/{id}/export?format=csv", &[&mid], None)
        .await;
    assert_eq!(csv.status, 200);
    assert!(
        csv.text
            .starts_with("group,symbol,grid_speed_mps,value,std,unit\n")
    );
    assert!(csv.text.lines().count() > 12);
    let fossen = app
        .call(
            "GET",
            "/api/models/{id}/export?format=fossen",
            &[&mid],
            None,
        )
        .await;
    assert_eq!(fossen.status, 200, "{}", fossen.text);
    assert_eq!(fossen.json["points"].as_array().unwrap().len(), 2);
    assert_eq!(fossen.json["points"][0]["M"].as_array().unwrap().len(), 6);
    // The MATLAB script: the stored matrices, read back number for number.
    let script = app
        .call(
            "GET",
            "/api/models/{id}/export?format=matlab",
            &[&mid],
            None,
        )
        .await;
    assert_eq!(script.status, 200, "{}", script.text);
    let line = script
        .text
        .lines()
        .find(|l| l.starts_with("model.lpv.M(:,:,1) = ["))
        .expect("M of the first grid point");
    let inner = &line[line.find('[').unwrap() + 1..line.rfind(']').unwrap()];
    let read: Vec<Vec<f64>> = inner
        .split(';')
        .map(|r| r.split_whitespace().map(|x| x.parse().unwrap()).collect())
        .collect();
    let stored: Vec<Vec<f64>> =
        serde_json::from_value(m.json["document"]["lpv"]["points"][0]["m"].clone()).unwrap();
    assert_eq!(read, stored);
    assert!(
        script
            .text
            .contains("model.dofs = {'surge', 'sway', 'heave', 'roll', 'pitch', 'yaw'};")
    );
    let unknown = app
        .call("GET", "/api/models/{id}/export?format=xlsx", &[&mid], None)
        .await;
    assert_eq!(unknown.status, 400);
    assert_eq!(unknown.json["field"], "format");

    // Re-identification continues the lineage as version 2.
    let r = app.call("POST", "/api/jobs", &[], Some(submit)).await;
    let job2 = wait_for_job(&app, r.json["id"].as_str().unwrap(), 60).await;
    assert_eq!(job2["result"]["version"], 2, "{job2}");
    let list = app
        .call("GET", "/api/models?campaign_id={id}", &[&cid], None)
        .await;
    assert_eq!(list.json.as_array().unwrap().len(), 2);
    assert_eq!(list.json[0]["parent_id"], mid.as_str());

    // Side by side on the held-out run: same data, same method → same fits.
    let mid2 = job2["result"]["model_id"].as_str().unwrap().to_string();
    let val = m.json["validation_run_ids"][0]
        .as_str()
        .unwrap()
        .to_string();
    let c = app
        .call(
            "GET",
            "/api/models/compare?a={a}&b={b}&run_id={r}",
            &[&mid, &mid2, &val],
            None,
        )
        .await;
    assert_eq!(c.status, 200, "{}", c.text);
    let (fa, fb) = (&c.json["models"][0], &c.json["models"][1]);
    assert_eq!(fa["run_used_for_estimation"], false);
    let fit = |m: &Value| m["report"]["channels"][0]["fit_one_step"].as_f64().unwrap();
    assert!((fit(fa) - fit(fb)).abs() < 1e-12);
    // And equal to the validation stored at identification.
    let stored = m.json["validation"][0]["report"]["channels"][0]["fit_one_step"]
        .as_f64()
        .unwrap();
    assert!((fit(fa) - stored).abs() < 1e-9, "{} vs {stored}", fit(fa));
    // Restarted every 5 s instead of 10: twice the windows; a period that is
    // not a positive number of seconds is refused.
    let c5 = app
        .call(
            "GET",
            "/api/models/compare?a={a}&b={b}&run_id={r}&restart_s=5",
            &[&mid, &mid2, &val],
            None,
        )
        .await;
    assert_eq!(c5.status, 200, "{}", c5.text);
    let (r10, r5) = (&fa["report"], &c5.json["models"][0]["report"]);
    assert_eq!(
        (r10["restart_s"].as_f64(), r5["restart_s"].as_f64()),
        (Some(10.0), Some(5.0))
    );
    let windows = |r: &Value| r["channels"][0]["restarted"]["windows"].as_u64().unwrap();
    assert!(
        windows(r5) >= 2 * windows(r10) - 1,
        "{} vs {}",
        windows(r5),
        windows(r10)
    );
    let r = app
        .call(
            "GET",
            "/api/models/compare?a={a}&b={b}&run_id={r}&restart_s=0",
            &[&mid, &mid2, &val],
            None,
        )
        .await;
    assert_eq!(
        (r.status.as_u16(), r.json["field"].as_str()),
        (422, Some("restart_s"))
    );
    let r = app
        .call(
            "GET",
            "/api/models/compare?a={a}&b={b}&run_id={r}",
            &["nope", &mid2, &val],
            None,
        )
        .await;
    assert_eq!(
        (r.status.as_u16(), r.json["field"].as_str()),
        (404, Some("a"))
    );
    let r = app
        .call("GET", "/api/models/compare?a={a}", &[&mid], None)
        .await;
    assert_eq!(r.status, 400, "{}", r.text);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn n4sid_job_and_bad_requests_name_the_field() {
    let app = app().await;
    let cid = flown_campaign(&app, &linear_truth()).await;
    let bad = |body: Value| {
        let app = &app;
        async move { app.call("POST", "/api/jobs", &[], Some(body)).await }
    };
    let r = bad(json!({ "kind": "identify", "campaign_id": cid, "method": "least_squares" })).await;
    assert_eq!(
        (r.status.as_u16(), r.json["field"].as_str()),
        (422, Some("method")),
        "{}",
        r.text
    );
    let r = bad(json!({ "kind": "identify", "campaign_id": cid, "settings": { "structure": "triangular" } })).await;
    assert_eq!(
        (r.status.as_u16(), r.json["field"].as_str()),
        (422, Some("settings.structure")),
        "{}",
        r.text
    );
    let r = bad(json!({ "kind": "identify", "method": "n4sid" })).await;
    assert_eq!(
        (r.status.as_u16(), r.json["field"].as_str()),
        (422, Some("campaign_id")),
        "{}",
        r.text
    );
    // A job that fails in the numerics names the setting too.
    let r =
        bad(json!({ "kind": "identify", "campaign_id": cid, "settings": { "t_lambda_s": 0.01 } }))
            .await;
    assert_eq!(r.status, 202);
    let job = wait_for_job(&app, r.json["id"].as_str().unwrap(), 60).await;
    assert_eq!(job["state"], "failed");
    assert_eq!(job["error"]["field"], "settings.t_lambda_s", "{job}");

    let r = bad(json!({ "kind": "identify", "campaign_id": cid, "method": "n4sid", "settings": { "order": 6 } })).await;
    assert_eq!(r.status, 202, "{}", r.text);
    let job = wait_for_job(&app, r.json["id"].as_str().unwrap(), 60).await;
    assert_eq!(job["state"], "succeeded", "{job}");
    let mid = job["result"]["model_id"].as_str().unwrap().to_string();
    let m = app.call("GET", "/api/models/{id}", &[&mid], None).await;
    assert_eq!(m.json["document"]["state_space"]["order"], 6);
    let f = app
        .call(
            "GET",
            "/api/models/{id}/export?format=fossen",
            &[&mid],
            None,
        )
        .await;
    assert_eq!(f.status, 422, "a black box has no Fossen form");
    assert_eq!(f.json["field"], "format");
}
