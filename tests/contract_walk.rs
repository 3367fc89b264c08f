//! Walks every operation openapi.yaml documents, with real ids and bodies,
//! and validates each answer against its schema: nothing documented is dead,
//! nothing answered is undocumented.

mod common;

use common::sim::{self, all_columns, multipart, simulate};
use common::{TestApp, rov_profile};
use serde_json::{Value, json};

/// Submits a `sum` job.
async fn job(app: &TestApp, settings: Value) -> String {
    let r = app
        .call(
            "POST",
            "/api/jobs",
            &[],
            Some(json!({ "kind": "sum", "settings": settings })),
        )
        .await;
    assert_eq!(r.status, 202, "{}", r.text);
    r.json["id"].as_str().unwrap().to_string()
}

/// A stored one-DOF LPV model of a new lineage, from no run.
async fn stored_model(app: &TestApp, cid: &str, vid: &str) -> String {
    common::stored_model(app, cid, vid, None, &[]).await
}

/// A stored discovery report (nothing named) on model `mid`.
async fn stored_discrepancy(app: &TestApp, cid: &str, mid: &str) -> String {
    use seatrial::storage::discrepancies::{NewDiscrepancy, insert};
    let mut conn = app.state.db.acquire().await.unwrap();
    insert(
        &mut conn,
        NewDiscrepancy {
            model_id: mid.into(),
            augmented_model_id: None,
            campaign_id: cid.into(),
            job_id: None,
            settings: json!({}),
            run_ids: vec![],
            validation_run_ids: vec![],
            summary: vec!["No missing physics named.".into()],
            report: json!({ "summary": ["No missing physics named."], "effects": [], "points": [], "skipped": [] }),
        },
    )
    .await
    .unwrap()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn every_documented_operation_is_exercised_and_answers() {
    let registry = common::jobs::registry()
        .with("precision", seatrial::jobs::precision::Precision)
        .with("design", seatrial::jobs::design::Design)
        .with("next_dive", seatrial::jobs::next_dive::NextDiveJob);
    let app = TestApp::with_jobs(registry, common::jobs::config(1)).await;
    let r = app
        .call("POST", "/api/vessels", &[], Some(rov_profile()))
        .await;
    let vid = r.json["id"].as_str().unwrap().to_string();
    let campaign = json!({
        "vessel_id": vid, "name": "walk", "seed": 3,
        "grid": { "unit": "kn", "speeds": [1.0, 2.0] },
        "families": ["static", "dynamic", "validation"]
    });
    let r = app
        .call("POST", "/api/campaigns", &[], Some(campaign.clone()))
        .await;
    let cid = r.json["id"].as_str().unwrap().to_string();
    let r = app
        .call("POST", "/api/campaigns/{id}/plan", &[&cid], None)
        .await;
    let eid = r.json["experiments"][0]["id"].as_str().unwrap().to_string();
    let csv = sim::csv(
        &simulate(9, 10.0, 300.0, [300.0; 6], 2.0, 1e-4),
        &all_columns(),
        0.0,
        1,
    );
    let (ct, body) = multipart(&[("file", Some("walk.csv"), &csv)]);
    let r = app
        .raw(
            "POST",
            &format!("/api/campaigns/{cid}/runs"),
            Some((&ct, body.clone())),
        )
        .await;
    assert_eq!(r.status, 201, "{}", r.text);
    let rid = r.json["id"].as_str().unwrap().to_string();
    // A two-file run, for the clock-offset routes.
    let split = simulate(10, 10.0, 300.0, [300.0; 6], 2.0, 1e-4);
    let (control, nav) = sim::two_file_csv(&split, 4.0, 1);
    let r = app
        .upload_run(
            &cid,
            &[
                ("control", Some("c.csv"), &control),
                ("nav", Some("n.csv"), &nav),
            ],
        )
        .await;
    assert_eq!(r.status, 201, "{}", r.text);
    let split_rid = r.json["id"].as_str().unwrap().to_string();
    // A finished job (its event stream ends at once).
    let jid = job(&app, json!({ "n": 100 })).await;
    for _ in 0..3000 {
        let r = app.call("GET", "/api/jobs/{id}", &[&jid], None).await;
        if r.json["state"] == "succeeded" {
            break;
        }
        tokio::time::sleep(std::time::Duration::from_millis(10)).await;
    }
    let long = json!({ "n": 1000, "steps": 100, "step_ms": 50 });
    let mid = stored_model(&app, &cid, &vid).await;
    let did = stored_discrepancy(&app, &cid, &mid).await;

    // An account, and a token of it (local mode: the local admin makes them).
    let walker = json!({ "name": "walker", "role": "admin", "password": "walker-password" });
    let r = app.call("POST", "/api/users", &[], Some(walker)).await;
    let uid = r.json["id"].as_str().unwrap().to_string();
    let token = |name: &str| json!({ "name": name, "user_id": uid });
    let r = app
        .call("POST", "/api/auth/tokens", &[], Some(token("walk")))
        .await;
    let bearer = format!("Bearer {}", r.json["token"].as_str().unwrap());

    let paths = app.spec["paths"].as_object().unwrap().clone();
    let mut walked = 0;
    for (template, ops) in &paths {
        for (method, _) in ops.as_object().unwrap() {
            let args: Vec<&str> = if template.contains("{eid}") {
                vec![&cid, &eid]
            } else if template.starts_with("/api/vessels/") {
                vec![&vid]
            } else if template.starts_with("/api/runs/") && template.ends_with("/clock-offset") {
                vec![&split_rid]
            } else if template.starts_with("/api/runs/") {
                vec![&rid]
            } else if template.starts_with("/api/jobs/") {
                vec![&jid]
            } else if template.starts_with("/api/users/") {
                vec![&uid]
            } else if template.starts_with("/api/discrepancies/") {
                vec![&did]
            } else if template.starts_with("/api/models/") {
                vec![&mid]
            } else if template.contains("{id}") {
                vec![&cid]
            } else {
                vec![]
            };
            let r = match (method.as_str(), template.as_str()) {
                ("post", "/api/campaigns/{id}/runs") => {
                    let r = app
                        .raw(
                            "POST",
                            &format!("/api/campaigns/{cid}/runs"),
                            Some((&ct, body.clone())),
                        )
                        .await;
                    app.check_contract("POST", template, &r);
                    r
                }
                ("post", "/api/auth/login") => {
                    let body = json!({ "name": "walker", "password": "walker-password" });
                    app.call("POST", template, &[], Some(body)).await
                }
                // One's own password: the account's token, not the local admin.
                ("post", "/api/auth/password") => {
                    let body = json!({ "current_password": "walker-password",
                                       "new_password": "walker-password" });
                    let r = app
                        .raw_with(
                            "POST",
                            template,
                            &[("authorization", &bearer)],
                            Some(("application/json", body.to_string())),
                        )
                        .await;
                    app.check_contract("POST", template, &r);
                    r
                }
                ("post", "/api/auth/tokens") => {
                    app.call("POST", template, &[], Some(token("walked"))).await
                }
                ("get", "/api/auth/tokens") => {
                    app.call("GET", "/api/auth/tokens?all=true", &[], None).await
                }
                ("delete", "/api/auth/tokens/{id}") => {
                    let r = app
                        .call("POST", "/api/auth/tokens", &[], Some(token("gone")))
                        .await;
                    let id = r.json["id"].as_str().unwrap().to_string();
                    app.call("DELETE", template, &[&id], None).await
                }
                ("post", "/api/users") => {
                    let body = json!({ "name": "walked", "role": "viewer", "password": "12345678" });
                    app.call("POST", template, &[], Some(body)).await
                }
                ("patch", "/api/users/{id}") => {
                    app.call("PATCH", template, &args, Some(json!({ "disabled": false })))
                        .await
                }
                ("post", "/api/jobs") => {
                    app.call(
                        "POST",
                        template,
                        &args,
                        Some(json!({ "kind": "sum", "settings": { "n": 10 } })),
                    )
                    .await
                }
                // Only a queued or running job can be cancelled.
                ("post", "/api/jobs/{id}/cancel") => {
                    let id = job(&app, long.clone()).await;
                    app.call("POST", template, &[&id], None).await
                }
                // Only a failed, cancelled or interrupted job can be retried.
                ("post", "/api/jobs/{id}/retry") => {
                    let id = job(&app, long.clone()).await;
                    app.call("POST", "/api/jobs/{id}/cancel", &[&id], None)
                        .await;
                    let mut r = app.call("POST", template, &[&id], None).await;
                    // A running job is cancelled at its next progress report.
                    for _ in 0..500 {
                        if r.status != 409 {
                            break;
                        }
                        tokio::time::sleep(std::time::Duration::from_millis(10)).await;
                        r = app.call("POST", template, &[&id], None).await;
                    }
                    app.call("POST", "/api/jobs/{id}/cancel", &[&id], None)
                        .await;
                    r
                }
                // A prediction exists once a precision job has run.
                ("get", "/api/campaigns/{id}/precision") => {
                    let body = json!({ "kind": "precision", "campaign_id": cid, "settings": { "prior": "reference", "realisations": 1 } });
                    let r = app.call("POST", "/api/jobs", &[], Some(body)).await;
                    assert_eq!(r.status, 202, "{}", r.text);
                    let done = common::wait_for_job(&app, r.json["id"].as_str().unwrap(), 120).await;
                    assert_eq!(done["state"], "succeeded", "{done}");
                    app.call("GET", template, &args, None).await
                }
                // A design exists once a design job has run.
                ("get", "/api/campaigns/{id}/design") => {
                    let body = json!({ "kind": "design", "campaign_id": cid, "settings": { "prior": "reference" } });
                    let r = app.call("POST", "/api/jobs", &[], Some(body)).await;
                    assert_eq!(r.status, 202, "{}", r.text);
                    let done = common::wait_for_job(&app, r.json["id"].as_str().unwrap(), 120).await;
                    assert_eq!(done["state"], "succeeded", "{done}");
                    app.call("GET", template, &args, None).await
                }
                // A next-dive proposal (and its run sheet) exists once a
                // next_dive job has run.
                ("get", "/api/campaigns/{id}/next-dive" | "/api/campaigns/{id}/next-dive/runsheet") => {
                    let body = json!({ "kind": "next_dive", "campaign_id": cid, "settings": { "prior": "reference", "dive_hours": 1 } });
                    let r = app.call("POST", "/api/jobs", &[], Some(body)).await;
                    assert_eq!(r.status, 202, "{}", r.text);
                    let done = common::wait_for_job(&app, r.json["id"].as_str().unwrap(), 120).await;
                    assert_eq!(done["state"], "succeeded", "{done}");
                    app.call("GET", template, &args, None).await
                }
                ("get", "/api/models/compare") => {
                    app.call(
                        "GET",
                        "/api/models/compare?a={a}&b={b}&run_id={r}",
                        &[&mid, &mid, &rid],
                        None,
                    )
                    .await
                }
                ("put", t) if t.ends_with("/clock-offset") => {
                    app.call(
                        "PUT",
                        template,
                        &args,
                        Some(json!({ "clock_offset_s": 4.0 })),
                    )
                    .await
                }
                ("patch", "/api/runs/{id}") => {
                    app.call(
                        "PATCH",
                        template,
                        &args,
                        Some(json!({ "role": "dynamic", "grid_speed_kn": 1.0, "notes": "walked", "name": "walked", "excluded": false })),
                    )
                    .await
                }
                // Deleting and restoring need a run of their own (restoring, deleted first).
                ("delete", "/api/runs/{id}") | ("post", "/api/runs/{id}/restore") => {
                    let r = app
                        .raw(
                            "POST",
                            &format!("/api/campaigns/{cid}/runs"),
                            Some((&ct, body.clone())),
                        )
                        .await;
                    let id = r.json["id"].as_str().unwrap().to_string();
                    if method == "post" {
                        app.call("DELETE", "/api/runs/{id}", &[&id], None).await;
                    }
                    app.call(&method.to_uppercase(), template, &[&id], None)
                        .await
                }
                // Vessels and campaigns too: one of their own (restoring, deleted first).
                (
                    "delete" | "post",
                    "/api/vessels/{id}" | "/api/vessels/{id}/restore" | "/api/campaigns/{id}"
                    | "/api/campaigns/{id}/restore",
                ) => {
                    let (create, body) = if template.starts_with("/api/vessels") {
                        ("/api/vessels", rov_profile())
                    } else {
                        ("/api/campaigns", campaign.clone())
                    };
                    let r = app.call("POST", create, &[], Some(body)).await;
                    let id = r.json["id"].as_str().unwrap().to_string();
                    let item = format!("{create}/{{id}}");
                    if method == "post" {
                        app.call("DELETE", &item, &[&id], None).await;
                    }
                    app.call(&method.to_uppercase(), template, &[&id], None)
                        .await
                }
                ("delete", "/api/models/{id}") => {
                    let id = stored_model(&app, &cid, &vid).await;
                    app.call("DELETE", template, &[&id], None).await
                }
                ("patch", "/api/campaigns/{id}" | "/api/vessels/{id}") => {
                    app.call("PATCH", template, &args, Some(json!({ "name": "walked" })))
                        .await
                }
                ("post", "/api/models/{id}/restore") => {
                    let id = stored_model(&app, &cid, &vid).await;
                    app.call("DELETE", "/api/models/{id}", &[&id], None).await;
                    app.call("POST", template, &[&id], None).await
                }
                ("patch", "/api/models/{id}") => {
                    app.call(
                        "PATCH",
                        template,
                        &args,
                        Some(json!({ "name": "walked", "notes": "renamed" })),
                    )
                    .await
                }
                ("post", "/api/vessels") => {
                    app.call("POST", template, &args, Some(rov_profile())).await
                }
                ("post", "/api/campaigns") => {
                    app.call("POST", template, &args, Some(campaign.clone()))
                        .await
                }
                _ => {
                    app.call(&method.to_uppercase(), template, &args, None)
                        .await
                }
            };
            assert!(
                r.status.is_success(),
                "{method} {template}: {} {}",
                r.status,
                r.text
            );
            walked += 1;
        }
    }
    assert!(walked >= 25, "walked {walked} operations");
}
