//! Managing data (issue 16): runs renamed, excluded, paged and deleted
//! with their files; a deleted run's models keep their provenance.

mod common;

use common::manage::{id, refused, total, vessel_and_campaign};
use common::{TestApp, sim};
use serde_json::json;

async fn upload(app: &TestApp, cid: &str, name: &str, csv: &str) -> common::Resp {
    let meta = json!({ "name": name }).to_string();
    app.upload_run(
        cid,
        &[("meta", None, &meta), ("file", Some("log.csv"), csv)],
    )
    .await
}

fn log(seed: u64) -> String {
    sim::csv(
        &sim::simulate(seed, 10.0, 300.0, [300.0; 6], 2.0, 1e-4),
        &sim::all_columns(),
        0.0,
        1,
    )
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn runs_are_renamed_excluded_paged_and_deleted_with_their_files() {
    // The production job kinds, no worker: submissions are checked, nothing runs.
    let app = TestApp::with_jobs(
        seatrial::jobs::JobRegistry::production(),
        common::jobs::config(0),
    )
    .await;
    let (_, cid) = vessel_and_campaign(&app, json!({})).await;
    let (one, two) = (log(1), log(2));
    let a = id(&upload(&app, &cid, "a", &one).await);
    let b = id(&upload(&app, &cid, "b (same bytes as a)", &one).await);
    let c = id(&upload(&app, &cid, "c", &two).await);
    let r = upload(&app, &cid, "bad", "t,u\n0,x\n").await;
    assert_eq!(r.status, 422, "{}", r.text);
    let bad = r.json["run_id"].as_str().unwrap().to_string();

    // Rename, exclude with a reason, include again.
    let patch = |rid: String, body: serde_json::Value| {
        let app = &app;
        async move {
            app.call("PATCH", "/api/runs/{id}", &[&rid], Some(body))
                .await
        }
    };
    let r = patch(a.clone(), json!({ "name": "  dive 3  " })).await;
    assert_eq!(
        (r.status.as_u16(), r.json["name"].as_str()),
        (200, Some("dive 3")),
        "{}",
        r.text
    );
    let r = patch(a.clone(), json!({ "excluded": true })).await;
    refused(&r, 422, "excluded_reason");
    let r = patch(a.clone(), json!({ "excluded": true, "excluded_reason": "thruster 2 failed", "notes": "kept for the record" })).await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert_eq!(r.json["excluded"], true);
    assert_eq!(r.json["excluded_reason"], "thruster 2 failed");
    assert!(r.json["excluded_at"].is_string(), "{}", r.text);
    assert_eq!(
        r.json["description"]["notes"]["value"], "kept for the record",
        "{}",
        r.text
    );
    let r = app
        .call("GET", "/api/campaigns/{id}/runs", &[&cid], None)
        .await;
    let listed: Vec<bool> = r
        .json
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["excluded"] == true)
        .collect();
    assert_eq!(listed, [true, false, false, false], "{}", r.text);
    for (body, field) in [
        (json!({ "name": "" }), "name"),
        (json!({ "name": "x".repeat(201) }), "name"),
        (json!({ "excluded_reason": "why" }), "excluded_reason"),
        (json!({ "excluded": "yes" }), "excluded"),
        (json!({ "colour": "red" }), "colour"),
    ] {
        let r = patch(b.clone(), body.clone()).await;
        assert_eq!(
            (r.status.as_u16(), r.json["field"].as_str()),
            (422, Some(field)),
            "{body}: {}",
            r.text
        );
        assert!(r.json["message"].as_str().unwrap().len() > 5);
    }
    let r = patch("no-such-run".into(), json!({ "name": "x" })).await;
    assert_eq!(r.status, 404, "{}", r.text);
    let r = patch(a.clone(), json!({ "excluded": false })).await;
    assert_eq!(
        (
            r.json["excluded"].as_bool(),
            r.json["excluded_reason"].is_null()
        ),
        (Some(false), true),
        "{}",
        r.text
    );

    // An excluded run is not used by default: with one usable run left, identify is refused.
    for rid in [&a, &b] {
        patch(
            rid.clone(),
            json!({ "excluded": true, "excluded_reason": "test" }),
        )
        .await;
    }
    let r = app
        .call(
            "POST",
            "/api/jobs",
            &[],
            Some(json!({ "kind": "identify", "campaign_id": cid })),
        )
        .await;
    refused(&r, 422, "run_ids");
    assert!(
        r.json["message"].as_str().unwrap().contains("2 excluded"),
        "{}",
        r.text
    );
    // Named in run_ids, an excluded run is used: the request is accepted.
    let r = app
        .call(
            "POST",
            "/api/jobs",
            &[],
            Some(json!({ "kind": "identify", "campaign_id": cid, "run_ids": [a, c] })),
        )
        .await;
    assert_eq!(r.status, 202, "{}", r.text);
    app.call(
        "POST",
        "/api/jobs/{id}/cancel",
        &[r.json["id"].as_str().unwrap()],
        None,
    )
    .await;

    // Pages with the total in X-Total-Count; rejected uploads listed apart.
    let r = app
        .call("GET", "/api/campaigns/{id}/runs?limit=2", &[&cid], None)
        .await;
    assert_eq!(
        (r.json.as_array().unwrap().len(), total(&r)),
        (2, 4),
        "{}",
        r.text
    );
    let r = app
        .call(
            "GET",
            "/api/campaigns/{id}/runs?limit=2&offset=3",
            &[&cid],
            None,
        )
        .await;
    assert_eq!(r.json.as_array().unwrap().len(), 1, "{}", r.text);
    assert_eq!(r.json[0]["id"], bad.as_str());
    let r = app
        .call(
            "GET",
            "/api/campaigns/{id}/runs?status=rejected",
            &[&cid],
            None,
        )
        .await;
    assert_eq!(
        (r.json.as_array().unwrap().len(), total(&r)),
        (1, 1),
        "{}",
        r.text
    );
    for (q, field) in [
        ("limit=0", "limit"),
        ("limit=1001", "limit"),
        ("status=lost", "status"),
    ] {
        let r = app
            .call(
                "GET",
                &format!("/api/campaigns/{{id}}/runs?{q}"),
                &[&cid],
                None,
            )
            .await;
        assert_eq!(
            (r.status.as_u16(), r.json["field"].as_str()),
            (422, Some(field)),
            "{q}: {}",
            r.text
        );
    }
    let r = app
        .call("GET", "/api/campaigns/{id}/runs", &["nope"], None)
        .await;
    assert_eq!(r.status, 404);

    // Deleting is soft: the files stay, the run leaves the list, it is
    // listed with ?deleted=true, and restore undoes it.
    let sha = {
        let r = app.call("GET", "/api/runs/{id}", &[&a], None).await;
        r.json["files"][0]["sha256"].as_str().unwrap().to_string()
    };
    let r = app
        .call(
            "DELETE",
            "/api/runs/{id}?reason=logged%20twice",
            &[&a],
            None,
        )
        .await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert_eq!(r.json["run"]["delete_reason"], "logged twice", "{}", r.text);
    assert_eq!(r.json["run"]["deleted_by"], "local", "{}", r.text);
    assert!(r.json["run"]["deleted_at"].is_string(), "{}", r.text);
    assert!(app.state.blobs.path(&sha).exists());
    let r = app.call("GET", "/api/runs/{id}", &[&a], None).await;
    assert_eq!(r.status, 200, "a deleted run stays readable: {}", r.text);
    assert_eq!(
        app.call("DELETE", "/api/runs/{id}", &[&a], None)
            .await
            .status,
        404,
        "deleted already"
    );
    let r = app
        .call(
            "GET",
            "/api/campaigns/{id}/runs?deleted=true",
            &[&cid],
            None,
        )
        .await;
    assert_eq!(
        (total(&r), r.json[0]["id"].as_str()),
        (1, Some(a.as_str())),
        "{}",
        r.text
    );
    // Named in run_ids, a deleted run is refused by name and id.
    let r = app
        .call(
            "POST",
            "/api/jobs",
            &[],
            Some(json!({ "kind": "identify", "campaign_id": cid, "run_ids": [c, a] })),
        )
        .await;
    refused(&r, 422, "run_ids[1]");
    let msg = r.json["message"].as_str().unwrap();
    assert!(msg.contains("dive 3") && msg.contains(&a), "{msg}");
    // The audit trail says who, when and why.
    let r = app.call("GET", "/api/audit", &[], None).await;
    let entry = r
        .json
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["method"] == "DELETE" && e["target_id"] == a.as_str() && e["status"] == 200)
        .unwrap_or_else(|| panic!("no audit row: {}", r.text));
    assert_eq!(
        (entry["note"].as_str(), entry["user_name"].as_str()),
        (Some("logged twice"), Some("local"))
    );
    let r = app
        .call("POST", "/api/runs/{id}/restore", &[&a], None)
        .await;
    assert_eq!(
        (r.status.as_u16(), r.json["deleted_at"].is_null()),
        (200, true),
        "{}",
        r.text
    );
    let r = app
        .call("POST", "/api/runs/{id}/restore", &[&a], None)
        .await;
    assert_eq!(r.status, 409, "not deleted: {}", r.text);
    let r = app
        .call("POST", "/api/runs/{id}/restore", &["nope"], None)
        .await;
    assert_eq!(r.status, 404, "{}", r.text);
    let r = app.call("DELETE", "/api/runs/{id}", &[&b], None).await;
    assert_eq!(r.json["run"]["delete_reason"], json!(null), "{}", r.text);
    let r = app
        .call(
            "DELETE",
            &format!("/api/runs/{{id}}?reason={}", "x".repeat(2001)),
            &[&c],
            None,
        )
        .await;
    refused(&r, 422, "reason");
    // A rejected upload is removable too.
    assert_eq!(
        app.call("DELETE", "/api/runs/{id}", &[&bad], None)
            .await
            .status,
        200
    );
    let r = app
        .call("GET", "/api/campaigns/{id}/runs", &[&cid], None)
        .await;
    assert_eq!(total(&r), 2, "{}", r.text);
}

#[tokio::test]
async fn deleting_a_run_keeps_the_provenance_of_its_models() {
    let app = TestApp::new().await;
    let (vid, cid) = vessel_and_campaign(&app, json!({})).await;
    let run = id(&upload(&app, &cid, "dive 7", &log(7)).await);
    let mid = common::stored_model(&app, &cid, &vid, None, &[&run]).await;
    let r = app
        .call(
            "DELETE",
            "/api/runs/{id}?reason=bad%20depth%20sensor",
            &[&run],
            None,
        )
        .await;
    assert_eq!(r.status, 200, "{}", r.text);
    let used_by = r.json["used_by"].to_string();
    assert!(
        used_by.contains(&mid),
        "the answer names the model: {used_by}"
    );
    // The model still names the run, and the run still reads, marked deleted.
    let m = app.call("GET", "/api/models/{id}", &[&mid], None).await;
    assert_eq!(m.status, 200, "{}", m.text);
    assert!(
        m.text.contains(&run),
        "provenance keeps the run: {}",
        m.text
    );
    let r = app.call("GET", "/api/runs/{id}", &[&run], None).await;
    assert_eq!(
        (r.json["name"].as_str(), r.json["delete_reason"].as_str()),
        (Some("dive 7"), Some("bad depth sensor")),
        "{}",
        r.text
    );
    assert_eq!(
        app.call("GET", "/api/runs/{id}/quality", &[&run], None)
            .await
            .status,
        200
    );
    let r = app
        .call("GET", "/api/campaigns/{id}/runs", &[&cid], None)
        .await;
    assert_eq!(total(&r), 0, "{}", r.text);
}
