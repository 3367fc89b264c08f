//! Crash debris (issue 17): a server killed mid-upload leaves a partial
//! file in `blobs/tmp/`, one killed between storing and parsing leaves a
//! run `stored`; the next start removes the first and processes the second.

mod common;

use common::{TestApp, rov_campaign_id as rov_campaign, rov_log as log};
use serde_json::json;

#[tokio::test]
async fn a_restart_sweeps_partial_uploads_and_processes_runs_left_stored() {
    let app = TestApp::new().await;
    let cid = rov_campaign(&app).await;
    let csv = log();
    let meta = json!({ "name": "dive 7", "rate_hz": 5.0 }).to_string();
    let r = app
        .upload_run(
            &cid,
            &[("meta", None, &meta), ("file", Some("dive7.csv"), &csv)],
        )
        .await;
    assert_eq!(r.status, 201, "{}", r.text);
    let accepted = r.json.clone();
    let id = accepted["id"].as_str().unwrap().to_string();
    // A kill between storing and parsing: the run row is `stored`, without
    // summary; a kill mid-upload: a partial file in blobs/tmp.
    sqlx::query("UPDATE run SET status = 'stored', summary = NULL, inferred = NULL WHERE id = $1")
        .bind(&id)
        .execute(&app.state.db)
        .await
        .unwrap();
    sqlx::query("DELETE FROM run_quality WHERE run_id = $1")
        .bind(&id)
        .execute(&app.state.db)
        .await
        .unwrap();
    let tmp = app.state.blobs.path("tmp");
    std::fs::write(tmp.join("0190-partial"), b"t,u\n0,1\n0.1").unwrap();
    let r = app.call("GET", "/api/runs/{id}", &[&id], None).await;
    assert_eq!(r.json["status"], "stored");

    let debris = seatrial::intake::recover(&app.state.db, &app.state.blobs)
        .await
        .unwrap();
    assert_eq!(debris.partial_uploads, 1);
    assert_eq!(debris.stored_runs, std::slice::from_ref(&id));
    assert_eq!(std::fs::read_dir(&tmp).unwrap().count(), 0);
    let r = app.call("GET", "/api/runs/{id}", &[&id], None).await;
    assert_eq!(r.json["status"], "accepted", "{}", r.text);
    // Processed as uploaded: the meta's rate is kept.
    assert_eq!(r.json["summary"]["sample_rate_hz"], 5.0);
    assert_eq!(r.json["summary"], accepted["summary"]);
    let q = app
        .call("GET", "/api/runs/{id}/quality", &[&id], None)
        .await;
    assert_eq!(q.status, 200, "{}", q.text);
    // Nothing left: a second start has nothing to do.
    let again = seatrial::intake::recover(&app.state.db, &app.state.blobs)
        .await
        .unwrap();
    assert_eq!((again.partial_uploads, again.stored_runs.len()), (0, 0));
}

#[tokio::test]
async fn a_run_left_stored_that_does_not_parse_is_rejected_with_its_reason() {
    let app = TestApp::new().await;
    let cid = rov_campaign(&app).await;
    let r = app
        .upload_run(&cid, &[("file", Some("bad.csv"), "t,u\n0,1\n0.1,x\n")])
        .await;
    assert_eq!(r.status, 422);
    let id = r.json["run_id"].as_str().unwrap().to_string();
    sqlx::query("UPDATE run SET status = 'stored', error = NULL WHERE id = $1")
        .bind(&id)
        .execute(&app.state.db)
        .await
        .unwrap();
    seatrial::intake::recover(&app.state.db, &app.state.blobs)
        .await
        .unwrap();
    let r = app.call("GET", "/api/runs/{id}", &[&id], None).await;
    assert_eq!(r.json["status"], "rejected");
    assert!(r.json["error"]["message"].is_string(), "{}", r.text);
}
