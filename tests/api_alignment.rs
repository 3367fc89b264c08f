//! Two-file alignment on weak runs, end to end: a campaign's strong runs
//! lend their clock offset to a run whose depth barely moves (pooled), the
//! supervisor sets and clears offsets per run and per campaign, absurd
//! offsets get 422s naming the field, and an identification job reads the
//! weak run with the pooled offset. Every response is checked against
//! openapi.yaml.

mod common;

use common::sim::{self, Rng, SimRun, simulate};
use common::{TestApp, rov_profile, wait_for_job};
use seatrial::jobs::{JobRegistry, JobsConfig};
use serde_json::{Value, json};

/// The campaign's clock offset: control stamps = nav stamps + 7.43 s.
const TRUTH: f64 = 7.43;

async fn campaign(app: &TestApp) -> String {
    let r = app
        .call("POST", "/api/vessels", &[], Some(rov_profile()))
        .await;
    let vid = r.json["id"].as_str().unwrap().to_string();
    let body = json!({
        "vessel_id": vid, "name": "two computers", "seed": 5,
        "grid": { "unit": "kn", "speeds": [1.0] }, "families": ["dynamic"]
    });
    let r = app.call("POST", "/api/campaigns", &[], Some(body)).await;
    assert_eq!(r.status, 201, "{}", r.text);
    r.json["id"].as_str().unwrap().to_string()
}

/// An excitation run: depth moves with heave and a slow dive profile.
fn strong(seed: u64) -> (String, String) {
    let run = simulate(
        seed,
        20.0,
        600.0,
        [400.0, 800.0, 800.0, 600.0, 600.0, 600.0],
        3.0,
        1e-4,
    );
    sim::two_file_csv(&run, TRUTH, 2)
}

/// A run at steady depth: the horizontal DOFs are excited, the depth holds
/// with a 5 mm drift and 2 cm of independent noise on each computer's sensor.
fn weak(seed: u64) -> (String, String) {
    let mut run: SimRun = simulate(
        seed,
        20.0,
        600.0,
        [400.0, 800.0, 0.0, 0.0, 0.0, 600.0],
        3.0,
        1e-4,
    );
    let mut rng = Rng(seed ^ 0xABCD);
    let depth = |rng: &mut Rng| -> Vec<f64> {
        run.t
            .iter()
            .map(|t| 20.0 + 0.005 * (t / 110.0).sin() + 0.02 * rng.normal())
            .collect()
    };
    let (zc, zn) = (depth(&mut rng), depth(&mut rng));
    run.eta[2] = zc;
    let (control, _) = sim::two_file_csv(&run, TRUTH, 2);
    run.eta[2] = zn;
    (control, sim::two_file_csv(&run, TRUTH, 2).1)
}

async fn upload(
    app: &TestApp,
    cid: &str,
    name: &str,
    logs: &(String, String),
    meta: Value,
) -> Value {
    let mut meta = meta;
    meta["name"] = json!(name);
    let meta = meta.to_string();
    let r = app
        .upload_run(
            cid,
            &[
                ("meta", None, &meta),
                ("control", Some("control.csv"), &logs.0),
                ("nav", Some("nav.csv"), &logs.1),
            ],
        )
        .await;
    app.check_contract("POST", "/api/campaigns/{id}/runs", &r);
    assert_eq!(r.status, 201, "{name}: {}", r.text);
    r.json
}

fn alignment(run: &Value) -> &Value {
    &run["summary"]["alignment"]
}

fn used(run: &Value) -> (String, f64) {
    let a = alignment(run);
    (
        a["offset_source"].as_str().unwrap().to_string(),
        a["offset_used_s"].as_f64().unwrap(),
    )
}

fn id(run: &Value) -> String {
    run["id"].as_str().unwrap().to_string()
}

fn view_of<'a>(campaign: &'a Value, run_id: &str) -> &'a Value {
    campaign["runs"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["run_id"] == run_id)
        .unwrap_or_else(|| panic!("{run_id} not in {campaign}"))
}

async fn put(app: &TestApp, template: &str, id: &str, body: Value) -> common::Resp {
    app.call("PUT", template, &[id], Some(body)).await
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn weak_runs_take_the_pooled_offset_and_jobs_use_it() {
    let app = TestApp::with_jobs(JobRegistry::production(), JobsConfig::default()).await;
    let cid = campaign(&app).await;

    // A weak run uploaded first has nothing to borrow: its own estimate is
    // used, loudly.
    let early = upload(&app, &cid, "hold 1", &weak(21), json!({})).await;
    assert_eq!(
        alignment(&early)["offset"]["informative"],
        false,
        "{}",
        alignment(&early)
    );
    assert_eq!(used(&early).0, "weak_own");
    assert!(
        early["summary"]["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .any(|w| w["message"]
                .as_str()
                .unwrap()
                .starts_with("THE CLOCK OFFSET IS NOT RELIABLE")),
        "{}",
        early["summary"]["warnings"]
    );

    // Two excitation runs: informative, 7.430 ± a millisecond.
    let s1 = upload(&app, &cid, "dive 1", &strong(1), json!({})).await;
    let s2 = upload(&app, &cid, "dive 2", &strong(2), json!({})).await;
    for s in [&s1, &s2] {
        let o = &alignment(s)["offset"];
        assert_eq!(o["informative"], true, "{o}");
        assert_eq!(used(s).0, "own");
        assert!((used(s).1 - TRUTH).abs() < 0.01, "{o}");
        assert!(o["std_error_s"].as_f64().unwrap() < 0.01, "{o}");
    }

    // A weak run uploaded now takes the pooled offset and reports both.
    let late = upload(&app, &cid, "hold 2", &weak(22), json!({})).await;
    let a = alignment(&late);
    assert_eq!(a["offset"]["informative"], false, "{a}");
    let (source, offset) = used(&late);
    assert_eq!(source, "pooled", "{a}");
    assert!((offset - TRUTH).abs() < 0.05, "pooled offset {offset}: {a}");
    assert_eq!(a["pooled"]["runs"], 2, "{a}");
    assert!(
        a["offset"]["offset_s"].is_number(),
        "the own estimate is reported too"
    );

    // The campaign's view: pooled from the two strong runs; the early weak
    // run kept its report, but a job reads it with the pooled offset now.
    let c = app
        .call("GET", "/api/campaigns/{id}/clock-offset", &[&cid], None)
        .await;
    assert_eq!(c.status, 200, "{}", c.text);
    let pooled = &c.json["pooled"];
    assert!(
        (pooled["offset_s"].as_f64().unwrap() - TRUTH).abs() < 0.05,
        "{pooled}"
    );
    let used_ids: Vec<&str> = pooled["runs_used"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    assert_eq!(used_ids.len(), 2);
    assert!(used_ids.contains(&id(&s1).as_str()) && used_ids.contains(&id(&s2).as_str()));
    let e = view_of(&c.json, &id(&early));
    assert_eq!(e["at_upload"]["source"], "weak_own", "{e}");
    assert_eq!(e["now"]["source"], "pooled", "{e}");
    // The strong runs were merged with their own estimates; the pool holds
    // both, so they are read with it now.
    for s in [&s1, &s2] {
        let v = view_of(&c.json, &id(s));
        assert_eq!(v["at_upload"]["source"], "own", "{v}");
        assert_eq!(v["now"]["source"], "pooled", "{v}");
        assert_eq!(v["now"]["offset_s"], pooled["offset_s"], "{v}");
    }

    // Identification reads the early weak run with the pooled offset.
    let job = json!({
        "kind": "identify", "campaign_id": cid, "method": "n4sid",
        "run_ids": [id(&s1), id(&early), id(&s2)],
        "settings": { "validation_run_ids": [id(&s2)] }
    });
    let r = app.call("POST", "/api/jobs", &[], Some(job)).await;
    assert_eq!(r.status, 202, "{}", r.text);
    let done = wait_for_job(&app, r.json["id"].as_str().unwrap(), 300).await;
    assert_eq!(done["state"], "succeeded", "{done}");
    let clocks = done["result"]["clock_offsets"].as_array().unwrap();
    let early_clock = clocks
        .iter()
        .find(|c| c["run_id"] == id(&early))
        .unwrap_or_else(|| panic!("{done}"));
    assert_eq!(early_clock["source"], "pooled", "{early_clock}");
    assert!(clocks.iter().all(|c| c["source"] == "pooled"), "{clocks:?}");
    assert!((early_clock["offset_s"].as_f64().unwrap() - TRUTH).abs() < 0.05);
    let mid = done["result"]["model_id"].as_str().unwrap();
    let m = app.call("GET", "/api/models/{id}", &[mid], None).await;
    let notes = m.json["document"]["notes"].to_string();
    assert!(
        notes.contains("“hold 1”") && notes.contains("pooled"),
        "{notes}"
    );
}

#[tokio::test]
async fn offsets_set_by_hand_are_used_and_bounded() {
    let app = TestApp::new().await;
    let cid = campaign(&app).await;
    let strong_run = upload(&app, &cid, "dive", &strong(3), json!({})).await;
    let weak_run = upload(&app, &cid, "hold", &weak(23), json!({})).await;
    let wid = id(&weak_run);
    assert_eq!(used(&weak_run).0, "pooled");

    // Per run: set → re-processed with it; clear → back to pooled.
    let r = put(
        &app,
        "/api/runs/{id}/clock-offset",
        &wid,
        json!({ "clock_offset_s": 7.5 }),
    )
    .await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert_eq!(used(&r.json), ("user_run".to_string(), 7.5));
    assert!(alignment(&r.json)["offset_used_std_s"].is_null());
    let v = app
        .call("GET", "/api/runs/{id}/clock-offset", &[&wid], None)
        .await;
    assert_eq!(v.json["clock_offset_s"], 7.5, "{}", v.text);
    assert_eq!(v.json["now"]["source"], "user_run");
    let r = put(
        &app,
        "/api/runs/{id}/clock-offset",
        &wid,
        json!({ "clock_offset_s": null }),
    )
    .await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert_eq!(used(&r.json).0, "pooled");

    // On upload.
    let by_hand = upload(
        &app,
        &cid,
        "hold, set",
        &weak(24),
        json!({ "clock_offset_s": 7.44 }),
    )
    .await;
    assert_eq!(used(&by_hand), ("user_run".to_string(), 7.44));

    // Per campaign: every run without its own hand-set offset uses it in
    // jobs from now on, and new uploads use it.
    let r = put(
        &app,
        "/api/campaigns/{id}/clock-offset",
        &cid,
        json!({ "clock_offset_s": 7.42 }),
    )
    .await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert_eq!(r.json["clock_offset_s"], 7.42);
    let s = view_of(&r.json, &id(&strong_run));
    assert_eq!(
        (
            s["at_upload"]["source"].as_str(),
            s["now"]["source"].as_str()
        ),
        (Some("own"), Some("user_campaign"))
    );
    assert_eq!(view_of(&r.json, &id(&by_hand))["now"]["source"], "user_run");
    let next = upload(&app, &cid, "hold 3", &weak(25), json!({})).await;
    assert_eq!(used(&next), ("user_campaign".to_string(), 7.42));
    let r = put(
        &app,
        "/api/campaigns/{id}/clock-offset",
        &cid,
        json!({ "clock_offset_s": null }),
    )
    .await;
    assert_eq!(r.json["clock_offset_s"], Value::Null);
    assert_eq!(view_of(&r.json, &id(&next))["now"]["source"], "pooled");

    // 422s naming the field; nothing changes.
    for bad in [
        json!(1e12),
        json!(-90_000.0),
        json!("NaN"),
        json!("Infinity"),
    ] {
        for (template, target) in [
            ("/api/runs/{id}/clock-offset", &wid),
            ("/api/campaigns/{id}/clock-offset", &cid),
        ] {
            let r = put(&app, template, target, json!({ "clock_offset_s": bad })).await;
            assert_eq!(r.status, 422, "{template} {bad}: {}", r.text);
            assert_eq!(r.json["field"], "clock_offset_s", "{}", r.text);
        }
    }
    // An offset that leaves the logs without overlap is refused, not stored.
    let r = put(
        &app,
        "/api/runs/{id}/clock-offset",
        &wid,
        json!({ "clock_offset_s": 50_000.0 }),
    )
    .await;
    assert_eq!(r.status, 422, "{}", r.text);
    assert_eq!(r.json["field"], "clock_offset_s");
    assert!(
        r.json["message"]
            .as_str()
            .unwrap()
            .contains("do not overlap"),
        "{}",
        r.text
    );
    let v = app
        .call("GET", "/api/runs/{id}/clock-offset", &[&wid], None)
        .await;
    assert_eq!(v.json["clock_offset_s"], Value::Null);
    // Malformed bodies: 400 naming the field.
    let r = put(
        &app,
        "/api/runs/{id}/clock-offset",
        &wid,
        json!({ "offset": 1.0 }),
    )
    .await;
    assert_eq!(
        (r.status.as_u16(), r.json["field"].as_str()),
        (400, Some("offset"))
    );
    let r = put(&app, "/api/runs/{id}/clock-offset", &wid, json!({})).await;
    assert_eq!(
        (r.status.as_u16(), r.json["field"].as_str()),
        (400, Some("clock_offset_s"))
    );
    // Upload metadata is checked before anything is processed.
    let meta = json!({ "clock_offset_s": 1e9 }).to_string();
    let logs = weak(26);
    let r = app
        .upload_run(
            &cid,
            &[
                ("meta", None, &meta),
                ("control", Some("c.csv"), &logs.0),
                ("nav", Some("n.csv"), &logs.1),
            ],
        )
        .await;
    assert_eq!(
        (r.status.as_u16(), r.json["field"].as_str()),
        (422, Some("meta.clock_offset_s")),
        "{}",
        r.text
    );
    // A single-file run has one clock.
    let single = sim::csv(
        &simulate(4, 10.0, 200.0, [300.0; 6], 2.0, 1e-4),
        &sim::all_columns(),
        0.0,
        1,
    );
    let r = app
        .upload_run(&cid, &[("file", Some("one.csv"), &single)])
        .await;
    assert_eq!(r.status, 201, "{}", r.text);
    let r = put(
        &app,
        "/api/runs/{id}/clock-offset",
        &id(&r.json),
        json!({ "clock_offset_s": 1.0 }),
    )
    .await;
    assert_eq!(
        (r.status.as_u16(), r.json["field"].as_str()),
        (422, Some("clock_offset_s"))
    );
    let r = app
        .call("GET", "/api/runs/{id}/clock-offset", &["no-such-run"], None)
        .await;
    assert_eq!(r.status, 404);
}
