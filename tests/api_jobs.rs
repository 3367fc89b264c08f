//! Background jobs over HTTP with a real runner and a real (simple) CPU job
//! kind, `sum` (tests/common/jobs.rs): submission checks, progress,
//! cancellation, SSE, restarts over the same database file, concurrency.
//! Every documented response is validated against openapi.yaml.

mod common;

use std::time::{Duration, Instant};

use common::jobs::{config, registry};
use common::sim::{self, all_columns, simulate};
use common::{TestApp, rov_profile};
use serde_json::{Value, json};

async fn submit(app: &TestApp, settings: Value) -> Value {
    let r = app
        .call(
            "POST",
            "/api/jobs",
            &[],
            Some(json!({ "kind": "sum", "method": "basel", "settings": settings })),
        )
        .await;
    assert_eq!(r.status, 202, "{}", r.text);
    r.json
}

async fn job(app: &TestApp, id: &str) -> Value {
    let r = app.call("GET", "/api/jobs/{id}", &[id], None).await;
    assert_eq!(r.status, 200, "{}", r.text);
    r.json
}

/// Polls until `until` holds (generous timeout: the machine is shared).
async fn wait_for(app: &TestApp, id: &str, until: impl Fn(&Value) -> bool) -> Value {
    let start = Instant::now();
    loop {
        let j = job(app, id).await;
        if until(&j) {
            return j;
        }
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "job {id} stuck: {j}"
        );
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
}

fn terminal(j: &Value) -> bool {
    ["succeeded", "failed", "cancelled", "interrupted"].contains(&j["state"].as_str().unwrap())
}

fn running_with_progress(j: &Value) -> bool {
    j["state"] == "running" && j["progress"].as_f64().unwrap() > 0.0
}

async fn campaign(app: &TestApp, name: &str) -> String {
    let r = app
        .call("POST", "/api/vessels", &[], Some(rov_profile()))
        .await;
    let vid = r.json["id"].as_str().unwrap().to_string();
    let body = json!({
        "vessel_id": vid, "name": name, "seed": 3,
        "grid": { "unit": "kn", "speeds": [1.0] }, "families": ["dynamic"]
    });
    let r = app.call("POST", "/api/campaigns", &[], Some(body)).await;
    assert_eq!(r.status, 201, "{}", r.text);
    r.json["id"].as_str().unwrap().to_string()
}

async fn upload_run(app: &TestApp, cid: &str) -> String {
    let csv = sim::csv(
        &simulate(9, 10.0, 120.0, [300.0; 6], 2.0, 1e-4),
        &all_columns(),
        0.0,
        1,
    );
    let r = app
        .upload_run(cid, &[("file", Some("run.csv"), &csv)])
        .await;
    assert_eq!(r.status, 201, "{}", r.text);
    r.json["id"].as_str().unwrap().to_string()
}

/// The `data:` payloads of an SSE body.
fn sse_events(text: &str) -> Vec<Value> {
    text.lines()
        .filter_map(|l| l.strip_prefix("data:"))
        .map(|d| serde_json::from_str(d.trim()).unwrap())
        .collect()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_job_runs_with_rising_progress_to_its_result() {
    let app = TestApp::with_jobs(registry(), config(1)).await;
    let n = 2_000_000u64;
    let j = submit(&app, json!({ "n": n, "steps": 40, "step_ms": 25 })).await;
    assert_eq!(j["state"], "queued");
    assert_eq!(j["attempts"], 0);
    let id = j["id"].as_str().unwrap().to_string();
    let mut seen = Vec::new();
    let done = loop {
        let j = job(&app, &id).await;
        if j["state"] == "running" {
            seen.push(j["progress"].as_f64().unwrap());
        }
        if terminal(&j) {
            break j;
        }
        tokio::time::sleep(Duration::from_millis(15)).await;
    };
    assert!(
        seen.windows(2).all(|w| w[0] <= w[1]),
        "progress fell: {seen:?}"
    );
    let between: Vec<f64> = seen
        .iter()
        .copied()
        .filter(|p| *p > 0.0 && *p < 1.0)
        .collect();
    assert!(between.len() >= 3, "too few progress readings: {seen:?}");
    assert_eq!(done["state"], "succeeded", "{done}");
    assert_eq!(done["progress"], 1.0);
    assert_eq!(done["attempts"], 1);
    assert!(done["error"].is_null());
    // Σ 1/k² to n is π²/6 − 1/n + O(1/n²).
    let sum = done["result"]["sum"].as_f64().unwrap();
    let expected = std::f64::consts::PI.powi(2) / 6.0 - 1.0 / n as f64;
    assert!((sum - expected).abs() < 1e-9, "{sum} vs {expected}");
    for t in ["created_at", "started_at", "finished_at", "updated_at"] {
        assert!(done[t].is_string(), "{t} missing: {done}");
    }
    assert!(done["started_at"].as_str() <= done["finished_at"].as_str());
    // Listed, and filtered by state.
    let r = app.raw("GET", "/api/jobs?state=succeeded", None).await;
    app.check_contract("GET", "/api/jobs", &r);
    assert_eq!(r.json.as_array().unwrap().len(), 1);
    let r = app.raw("GET", "/api/jobs?state=running", None).await;
    assert_eq!(r.json.as_array().unwrap().len(), 0);
    let r = app.raw("GET", "/api/jobs?state=done", None).await;
    app.check_contract("GET", "/api/jobs", &r);
    assert_eq!(
        (r.status.as_u16(), &r.json["field"]),
        (400, &json!("state"))
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn cancelling_a_running_job_stops_it_and_a_finished_one_is_a_conflict() {
    let app = TestApp::with_jobs(registry(), config(1)).await;
    let j = submit(&app, json!({ "n": 1000, "steps": 400, "step_ms": 50 })).await;
    let id = j["id"].as_str().unwrap().to_string();
    wait_for(&app, &id, running_with_progress).await;
    let r = app
        .call("POST", "/api/jobs/{id}/cancel", &[&id], None)
        .await;
    assert_eq!(r.status, 202, "{}", r.text);
    assert_eq!(r.json["cancel_requested"], true);
    let asked = Instant::now();
    let done = wait_for(&app, &id, terminal).await;
    assert_eq!(done["state"], "cancelled", "{done}");
    assert!(done["progress"].as_f64().unwrap() < 1.0);
    assert!(done["result"].is_null());
    assert!(
        asked.elapsed() < Duration::from_secs(10),
        "the cancel took {:?}",
        asked.elapsed()
    );
    let r = app
        .call("POST", "/api/jobs/{id}/cancel", &[&id], None)
        .await;
    assert_eq!(r.status, 409, "{}", r.text);
    assert!(
        r.json["message"]
            .as_str()
            .unwrap()
            .contains("already ended (cancelled)"),
        "{}",
        r.text
    );
    // A succeeded job: cancel and retry are conflicts.
    let ok = submit(&app, json!({ "n": 100 })).await;
    let ok = ok["id"].as_str().unwrap().to_string();
    wait_for(&app, &ok, terminal).await;
    let r = app
        .call("POST", "/api/jobs/{id}/cancel", &[&ok], None)
        .await;
    assert_eq!(r.status, 409);
    let r = app.call("POST", "/api/jobs/{id}/retry", &[&ok], None).await;
    assert_eq!(r.status, 409);
    assert!(
        r.json["message"]
            .as_str()
            .unwrap()
            .contains("submit a new job")
    );
    // The cancelled one can be retried, and then completes.
    let r = app.call("POST", "/api/jobs/{id}/retry", &[&id], None).await;
    assert_eq!(r.status, 202, "{}", r.text);
    assert_eq!(r.json["state"], "queued");
    let r = app
        .call("POST", "/api/jobs/{id}/cancel", &[&id], None)
        .await;
    assert!(r.status == 200 || r.status == 202, "{}", r.text);
    for unknown in ["/api/jobs/{id}/cancel", "/api/jobs/{id}/retry"] {
        let r = app.call("POST", unknown, &["nope"], None).await;
        assert_eq!(r.status, 404);
    }
    let r = app.call("GET", "/api/jobs/{id}", &["nope"], None).await;
    assert_eq!(r.status, 404);
}

#[tokio::test]
async fn a_queued_job_is_cancelled_at_once() {
    // No workers: jobs stay queued.
    let app = TestApp::with_jobs(registry(), config(0)).await;
    let j = submit(&app, json!({ "n": 10 })).await;
    let id = j["id"].as_str().unwrap();
    let r = app.call("POST", "/api/jobs/{id}/cancel", &[id], None).await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert_eq!(r.json["state"], "cancelled");
    assert!(r.json["finished_at"].is_string());
    assert_eq!(r.json["attempts"], 0);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_failing_computation_fails_the_job_with_its_reason() {
    let app = TestApp::with_jobs(registry(), config(1)).await;
    let j = submit(&app, json!({ "n": 100, "fail_at": 3 })).await;
    let id = j["id"].as_str().unwrap().to_string();
    let done = wait_for(&app, &id, terminal).await;
    assert_eq!(done["state"], "failed");
    assert_eq!(done["error"]["field"], "settings.fail_at");
    assert!(
        done["error"]["message"]
            .as_str()
            .unwrap()
            .contains("step 3")
    );
    let r = app.call("POST", "/api/jobs/{id}/retry", &[&id], None).await;
    assert_eq!(r.status, 202);
    let again = wait_for(&app, &id, terminal).await;
    assert_eq!(
        (again["state"].as_str(), again["attempts"].as_i64()),
        (Some("failed"), Some(2))
    );
}

#[tokio::test]
async fn bad_submissions_name_the_field_and_queue_nothing() {
    let app = TestApp::with_jobs(registry(), config(0)).await;
    let cid = campaign(&app, "a").await;
    let other = campaign(&app, "b").await;
    let rid = upload_run(&app, &cid).await;
    let post = |body: Value| {
        let app = &app;
        async move { app.call("POST", "/api/jobs", &[], Some(body)).await }
    };
    let cases: Vec<(Value, u16, &str, &str)> = vec![
        (
            json!({ "kind": "identify" }),
            422,
            "kind",
            "registered kinds are: sum",
        ),
        (
            json!({ "kind": "sum", "campaign_id": "nope", "settings": { "n": 5 } }),
            404,
            "campaign_id",
            "no campaign",
        ),
        (
            json!({ "kind": "sum", "run_ids": [rid], "settings": { "n": 5 } }),
            422,
            "campaign_id",
            "give the campaign_id",
        ),
        (
            json!({ "kind": "sum", "campaign_id": cid, "run_ids": [rid, "nope"], "settings": { "n": 5 } }),
            404,
            "run_ids[1]",
            "no run",
        ),
        (
            json!({ "kind": "sum", "campaign_id": other, "run_ids": [rid], "settings": { "n": 5 } }),
            422,
            "run_ids[0]",
            "belongs to campaign",
        ),
        (
            json!({ "kind": "sum", "campaign_id": cid, "run_ids": [rid, rid], "settings": { "n": 5 } }),
            422,
            "run_ids[1]",
            "twice",
        ),
        (
            json!({ "kind": "sum", "method": "euler", "settings": { "n": 5 } }),
            422,
            "method",
            "unknown method",
        ),
        (
            json!({ "kind": "sum", "settings": { "n": 0 } }),
            422,
            "settings.n",
            "n must be",
        ),
        (
            json!({ "kind": "sum", "settings": [1] }),
            422,
            "settings",
            "JSON object",
        ),
        (
            json!({ "kind": "sum", "settings": { "n": 5 }, "colour": 1 }),
            400,
            "colour",
            "unknown field",
        ),
        (
            json!({ "settings": { "n": 5 } }),
            400,
            "kind",
            "missing field",
        ),
    ];
    for (body, status, field, words) in cases {
        let r = post(body.clone()).await;
        assert_eq!(r.status.as_u16(), status, "{body}: {}", r.text);
        assert_eq!(r.json["field"], field, "{body}: {}", r.text);
        assert!(
            r.json["message"].as_str().unwrap().contains(words),
            "{body}: {}",
            r.text
        );
    }
    let r = app.call("GET", "/api/jobs", &[], None).await;
    assert_eq!(r.json, json!([]), "nothing may be queued by a bad request");
    // The good version of the same request is accepted and listed by campaign.
    let r = post(
        json!({ "kind": "sum", "campaign_id": cid, "run_ids": [rid], "settings": { "n": 50 } }),
    )
    .await;
    assert_eq!(r.status, 202, "{}", r.text);
    let r = app
        .raw("GET", &format!("/api/jobs?campaign_id={cid}"), None)
        .await;
    app.check_contract("GET", "/api/jobs", &r);
    assert_eq!(r.json.as_array().unwrap().len(), 1);
    let r = app
        .raw("GET", &format!("/api/jobs?campaign_id={other}"), None)
        .await;
    assert_eq!(r.json, json!([]));
    let r = app.raw("GET", "/api/jobs?campaign_id=nope", None).await;
    app.check_contract("GET", "/api/jobs", &r);
    assert_eq!(
        (r.status.as_u16(), &r.json["field"]),
        (404, &json!("campaign_id"))
    );
}

#[tokio::test]
async fn a_server_without_job_kinds_says_so() {
    let app = TestApp::new().await;
    let r = app
        .call(
            "POST",
            "/api/jobs",
            &[],
            Some(json!({ "kind": "identify" })),
        )
        .await;
    assert_eq!(r.status, 422);
    assert_eq!(r.json["field"], "kind");
    assert!(
        r.json["message"]
            .as_str()
            .unwrap()
            .contains("no job kinds registered")
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_event_stream_follows_progress_to_the_end() {
    let app = TestApp::with_jobs(registry(), config(1)).await;
    let j = submit(&app, json!({ "n": 100_000, "steps": 30, "step_ms": 40 })).await;
    let id = j["id"].as_str().unwrap().to_string();
    let r = tokio::time::timeout(
        Duration::from_secs(60),
        app.call("GET", "/api/jobs/{id}/events", &[&id], None),
    )
    .await
    .expect("the stream ends at the terminal state");
    assert_eq!(r.status, 200);
    assert!(r.content_type.starts_with("text/event-stream"));
    let events = sse_events(&r.text);
    assert!(events.len() >= 4, "{}", r.text);
    let last = events.last().unwrap();
    assert_eq!(last["state"], "succeeded", "{}", r.text);
    assert_eq!(last["progress"], 1.0);
    let running: Vec<f64> = events
        .iter()
        .filter(|e| e["state"] == "running")
        .map(|e| e["progress"].as_f64().unwrap())
        .collect();
    assert!(running.len() >= 3, "{}", r.text);
    assert!(running.windows(2).all(|w| w[0] <= w[1]), "{running:?}");
    for e in &events {
        assert!(e["stage"].is_string() && e["progress"].is_number());
    }
    // A finished job: one event, then the end.
    let r = app.call("GET", "/api/jobs/{id}/events", &[&id], None).await;
    let events = sse_events(&r.text);
    assert_eq!(events.len(), 1);
    assert_eq!(events[0]["state"], "succeeded");
    let r = app
        .call("GET", "/api/jobs/{id}/events", &["nope"], None)
        .await;
    assert_eq!(r.status, 404);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_job_survives_a_killed_server_and_is_interrupted_when_out_of_attempts() {
    let mut cfg = config(1);
    cfg.max_attempts = 2;
    // ≈ 3 s of work in 60 steps.
    let long = json!({ "n": 10_000, "steps": 60, "step_ms": 50 });

    let mut first = TestApp::with_jobs(registry(), cfg.clone()).await;
    let j = submit(&first, long.clone()).await;
    let id = j["id"].as_str().unwrap().to_string();
    wait_for(&first, &id, running_with_progress).await;
    first.runner.take().unwrap().abort(); // killed: nothing is written
    let orphan = job(&first, &id).await;
    assert_eq!(orphan["state"], "running");
    assert_eq!(orphan["attempts"], 1);

    // A new server over the same file re-queues it once the lease expires; it
    // restarts from the beginning and completes.
    let second = first.restart(registry(), cfg.clone()).await;
    let restarted = wait_for(&second, &id, |j| j["attempts"] == 2).await;
    assert!(
        restarted["state"] == "running" || terminal(&restarted),
        "{restarted}"
    );
    let done = wait_for(&second, &id, terminal).await;
    assert_eq!(done["state"], "succeeded", "{done}");
    assert_eq!(done["attempts"], 2);
    assert!(done["result"]["sum"].as_f64().unwrap() > 1.6);

    // Attempts exhausted: killed twice, it becomes interrupted; retry revives it.
    let mut second = second;
    let j = submit(&second, long.clone()).await;
    let id = j["id"].as_str().unwrap().to_string();
    wait_for(&second, &id, running_with_progress).await;
    second.runner.take().unwrap().abort();
    let mut third = second.restart(registry(), cfg.clone()).await;
    let requeued = wait_for(&third, &id, |j| {
        j["attempts"] == 2 && running_with_progress(j)
    })
    .await;
    assert_eq!(requeued["max_attempts"], 2);
    third.runner.take().unwrap().abort();
    let fourth = third.restart(registry(), cfg.clone()).await;
    let gone = wait_for(&fourth, &id, terminal).await;
    assert_eq!(gone["state"], "interrupted", "{gone}");
    assert_eq!(gone["attempts"], 2);
    assert!(gone["error"]["message"].as_str().unwrap().contains("retry"));
    let r = fourth
        .call("POST", "/api/jobs/{id}/retry", &[&id], None)
        .await;
    assert_eq!(r.status, 202, "{}", r.text);
    let done = wait_for(&fourth, &id, terminal).await;
    assert_eq!(done["state"], "succeeded", "{done}");
    assert_eq!(done["attempts"], 3);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_requeued_job_says_it_restarts_from_the_beginning() {
    let cfg = config(1);
    let mut first = TestApp::with_jobs(registry(), cfg.clone()).await;
    let j = submit(&first, json!({ "n": 10_000, "steps": 60, "step_ms": 50 })).await;
    let id = j["id"].as_str().unwrap().to_string();
    wait_for(&first, &id, running_with_progress).await;
    first.runner.take().unwrap().abort();
    // No workers in the new server: the recovered job stays queued to be read.
    let mut idle = cfg.clone();
    idle.workers = 0;
    let second = first.restart(registry(), idle).await;
    let q = wait_for(&second, &id, |j| j["state"] == "queued").await;
    assert!(
        q["stage"]
            .as_str()
            .unwrap()
            .contains("restarts from the beginning"),
        "{q}"
    );
    assert_eq!(q["progress"], 0.0);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn health_answers_while_two_jobs_burn_cpu() {
    let app = TestApp::with_jobs(registry(), config(2)).await;
    let burn = json!({ "n": 1000, "steps": 100, "spin_ms": 40 }); // ≈ 4 s of CPU each
    let a = submit(&app, burn.clone()).await;
    let b = submit(&app, burn).await;
    let (a, b) = (a["id"].as_str().unwrap(), b["id"].as_str().unwrap());
    wait_for(&app, a, running_with_progress).await;
    wait_for(&app, b, running_with_progress).await;
    for _ in 0..5 {
        let r = tokio::time::timeout(
            Duration::from_secs(10),
            app.call("GET", "/api/health", &[], None),
        )
        .await
        .expect("health must answer while jobs compute");
        assert_eq!(r.status, 200);
        // Both still computing: the HTTP side was not starved behind them.
        let r = app.raw("GET", "/api/jobs?state=running", None).await;
        if r.json.as_array().unwrap().len() < 2 {
            break;
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    for id in [a, b] {
        let done = wait_for(&app, id, terminal).await;
        assert_eq!(done["state"], "succeeded", "{done}");
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn event_streams_end_at_shutdown_so_the_server_can_stop() {
    // No workers: the job stays queued and its stream would never end by itself.
    let app = TestApp::with_jobs(registry(), config(0)).await;
    let j = submit(&app, json!({ "n": 10 })).await;
    let id = j["id"].as_str().unwrap().to_string();
    let stop = app.state.jobs.shutdown_token().clone();
    tokio::spawn(async move {
        tokio::time::sleep(Duration::from_millis(500)).await;
        stop.cancel();
    });
    let r = tokio::time::timeout(
        Duration::from_secs(30),
        app.call("GET", "/api/jobs/{id}/events", &[&id], None),
    )
    .await
    .expect("the stream ends at shutdown");
    let events = sse_events(&r.text);
    assert_eq!(events.len(), 1, "{}", r.text);
    assert_eq!(events[0]["state"], "queued");
    // Nothing was recorded by the shutdown.
    assert_eq!(job(&app, &id).await["state"], "queued");
}
