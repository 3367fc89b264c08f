//! Re-planning after a dive through REST: with part of the plan flown and
//! uploaded, the `next_dive` job counts the flown runs' data, proposes the
//! planned runs still to fly within the dive's hours (never one already
//! covered by a good run), serves them at `GET /api/campaigns/{id}/next-dive`
//! and as a printable run sheet. Requests the job cannot use are 422s.

mod common;

use common::TestApp;
use common::finite::assert_finite_json;
use common::flights::{flown_logs, linear_truth, upload_planned};
use seatrial::jobs::{JobRegistry, JobsConfig};
use serde_json::json;

async fn app() -> TestApp {
    TestApp::with_jobs(JobRegistry::production(), JobsConfig::default()).await
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn after_a_dive_the_next_one_flies_what_is_still_short() {
    let app = app().await;
    let spec = json!({
        "name": "two dives",
        "grid": { "unit": "kn", "speeds": [1.0, 2.0] },
        "families": ["dynamic", "recursive", "validation"],
        "seed": 11
    });
    // The first dive flew the 1 kn runs only.
    let (cid, plan, logs) = flown_logs(&app, spec, &linear_truth(), |c| c.contains("-1kn-")).await;
    assert!(!logs.is_empty());
    for (code, csv) in &logs {
        upload_planned(&app, &cid, &plan, code, csv).await;
    }
    let none = app
        .call("GET", "/api/campaigns/{id}/next-dive", &[&cid], None)
        .await;
    assert_eq!(none.status, 404, "{}", none.text);

    common::run_job(
        &app,
        json!({ "kind": "next_dive", "campaign_id": cid, "settings": { "prior": "reference", "dive_hours": 1.5 } }),
    )
    .await;
    let r = app
        .call("GET", "/api/campaigns/{id}/next-dive", &[&cid], None)
        .await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert_finite_json(&r.json, "next dive");
    assert_eq!(r.json["current"], true);
    let p = &r.json["proposal"];
    assert!(p["hours"].as_f64().unwrap() <= 1.5 + 1e-9);
    let proposed: Vec<&str> = p["proposed"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x["code"].as_str().unwrap())
        .collect();
    assert!(!proposed.is_empty());
    // Nothing covered by a good run comes back; the validation run and the
    // 2 kn grid point, never flown, come first.
    let cov = app
        .call("GET", "/api/campaigns/{id}/coverage", &[&cid], None)
        .await;
    for e in cov.json["experiments"].as_array().unwrap() {
        if e["status"] == "covered" {
            assert!(!proposed.contains(&e["code"].as_str().unwrap()), "{e}");
        }
    }
    assert!(proposed[0].starts_with("VAL"), "{proposed:?}");
    assert!(proposed[1].contains("-2kn-"), "{proposed:?}");
    assert_eq!(
        p["relative_std_now"],
        serde_json::Value::Null,
        "2 kn has no data yet"
    );
    assert!(r.json["flown_run_ids"].as_array().unwrap().len() >= logs.len() - 1);

    // The run sheet lists exactly the proposal, in its order.
    let sheet = app
        .call(
            "GET",
            "/api/campaigns/{id}/next-dive/runsheet",
            &[&cid],
            None,
        )
        .await;
    assert_eq!(sheet.status, 200, "{}", sheet.text);
    assert!(
        sheet.text.contains("<h1>Next dive: two dives</h1>"),
        "{}",
        &sheet.text[..400]
    );
    let mut at = 0;
    for code in &proposed {
        let i = sheet.text[at..]
            .find(code)
            .unwrap_or_else(|| panic!("{code} not in order"));
        at += i;
    }

    // A re-plan makes the proposal stale and its run sheet 404.
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
        .call("GET", "/api/campaigns/{id}/next-dive", &[&cid], None)
        .await;
    assert_eq!(r.json["current"], false);
    let sheet = app
        .call(
            "GET",
            "/api/campaigns/{id}/next-dive/runsheet",
            &[&cid],
            None,
        )
        .await;
    assert_eq!(sheet.status, 404, "{}", sheet.text);
    assert!(
        sheet.text.contains("propose the next dive again"),
        "{}",
        sheet.text
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn unusable_next_dive_requests_are_422_naming_the_field() {
    let app = app().await;
    let (cid, _) = common::flights::planned_campaign(
        &app,
        common::rov_profile(),
        json!({ "name": "n", "grid": { "unit": "kn", "speeds": [1.0, 2.0] }, "families": ["dynamic", "validation"], "seed": 2 }),
    )
    .await;
    for (body, field) in [
        (
            json!({ "kind": "next_dive", "campaign_id": cid, "settings": { "dive_hours": 0 } }),
            "settings.dive_hours",
        ),
        (
            json!({ "kind": "next_dive", "campaign_id": cid, "settings": { "dive_hours": 100 } }),
            "settings.dive_hours",
        ),
        (
            json!({ "kind": "next_dive", "campaign_id": cid, "settings": { "hours": 3 } }),
            "settings",
        ),
        (
            json!({ "kind": "next_dive", "campaign_id": cid, "method": "lambda_kf" }),
            "method",
        ),
        (json!({ "kind": "next_dive" }), "campaign_id"),
    ] {
        common::assert_job_refused(&app, body, field).await;
    }
}
