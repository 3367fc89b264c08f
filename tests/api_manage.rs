//! Managing data and models (issue 16): what the contract promises about
//! requests — integral floats where integers are meant, names by characters;
//! model versions deleted unless another is derived from them, campaigns
//! renamed; vessels, campaigns and jobs paged with their total. Runs:
//! `api_manage_runs.rs`.

mod common;

use common::TestApp;
use common::manage::{refused, total, vessel_and_campaign};
use serde_json::json;

#[tokio::test]
async fn integral_floats_are_accepted_where_integers_are_meant() {
    let app = TestApp::new().await;
    // JSON: a seed and repetitions written as floats with a zero fraction.
    let (_, cid) = vessel_and_campaign(&app, json!({ "seed": 7489.0, "repetitions": 2.0 })).await;
    let r = app.call("GET", "/api/campaigns/{id}", &[&cid], None).await;
    assert_eq!(r.json["spec"]["seed"], 7489, "{}", r.text);
    assert_eq!(r.json["spec"]["repetitions"], 2, "{}", r.text);
    // A fraction is still refused, naming the field.
    let r = app.call("GET", "/api/vessels", &[], None).await;
    let vid = r.json[0]["id"].as_str().unwrap().to_string();
    let r = app
        .call(
            "POST",
            "/api/campaigns",
            &[],
            Some(json!({ "vessel_id": vid, "name": "x", "seed": 7489.5,
                         "grid": { "unit": "kn", "speeds": [1.0] }, "families": ["dynamic"] })),
        )
        .await;
    assert_eq!(r.status, 400, "{}", r.text);
    assert_eq!(r.json["field"], "seed", "{}", r.text);
    // Query string: `limit=2.0` is the integer 2 (k, limit, offset alike).
    let r = app
        .call(
            "GET",
            "/api/campaigns/{id}/runs?limit=2.0&offset=0.0",
            &[&cid],
            None,
        )
        .await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert_eq!(r.headers["x-total-count"], "0", "{}", r.text);
    // A fraction is refused, naming the parameter.
    let r = app
        .call("GET", "/api/campaigns/{id}/runs?limit=2.5", &[&cid], None)
        .await;
    assert_eq!(r.status, 400, "{}", r.text);
    assert!(r.text.contains("limit"), "{}", r.text);
}

#[tokio::test]
async fn names_are_limited_in_characters_not_bytes() {
    let app = TestApp::new().await;
    // 200 two-byte characters: within the documented 1–200 characters.
    let (_, cid) = vessel_and_campaign(&app, json!({ "name": "é".repeat(200) })).await;
    assert!(!cid.is_empty());
    let r = app.call("GET", "/api/vessels", &[], None).await;
    let vid = r.json[0]["id"].as_str().unwrap().to_string();
    for (name, field) in [("é".repeat(201), "name"), ("  ".to_string(), "name")] {
        let r = app
            .call(
                "POST",
                "/api/campaigns",
                &[],
                Some(json!({ "vessel_id": vid, "name": name,
                             "grid": { "unit": "kn", "speeds": [1.0] }, "families": ["dynamic"] })),
            )
            .await;
        assert_eq!(r.status, 422, "{}", r.text);
        assert_eq!(r.json["field"], field, "{}", r.text);
    }
}

/// A run uploaded as `csv` named `name`; its id.
#[tokio::test]
async fn model_versions_are_deleted_unless_derived_from_and_campaigns_renamed() {
    let app = TestApp::new().await;
    let (vid, cid) = vessel_and_campaign(&app, json!({})).await;
    let v1 = common::stored_model(&app, &cid, &vid, None, &[]).await;
    let v2 = common::stored_model(&app, &cid, &vid, Some(&v1), &[]).await;

    let r = app.call("GET", "/api/models?limit=1", &[], None).await;
    assert_eq!(
        (r.json.as_array().unwrap().len(), total(&r)),
        (1, 2),
        "{}",
        r.text
    );
    assert_eq!(r.json[0]["id"], v2.as_str(), "newest first");

    // v2 was derived from v1: 409 naming it, unless cascade.
    let r = app.call("DELETE", "/api/models/{id}", &[&v1], None).await;
    assert_eq!(r.status, 409, "{}", r.text);
    let msg = r.json["message"].as_str().unwrap();
    assert!(msg.contains(&v2) && msg.contains("cascade"), "{msg}");
    let r = app
        .call("DELETE", "/api/models/{id}?reason=duplicate", &[&v2], None)
        .await;
    assert_eq!(
        (r.status.as_u16(), r.json["deleted"].clone()),
        (200, json!([v2])),
        "{}",
        r.text
    );
    // Soft: readable by id, marked; out of the list, in ?deleted=true.
    let r = app.call("GET", "/api/models/{id}", &[&v2], None).await;
    assert_eq!(
        (r.status.as_u16(), r.json["model"]["delete_reason"].as_str()),
        (200, Some("duplicate")),
        "{}",
        r.text
    );
    let r = app.call("GET", "/api/models", &[], None).await;
    assert_eq!(total(&r), 1, "{}", r.text);
    let r = app.call("GET", "/api/models?deleted=true", &[], None).await;
    assert_eq!(
        (total(&r), r.json[0]["id"].as_str()),
        (1, Some(v2.as_str())),
        "{}",
        r.text
    );
    // Undo, then delete again.
    let r = app
        .call("POST", "/api/models/{id}/restore", &[&v2], None)
        .await;
    assert_eq!(
        (r.status.as_u16(), r.json["deleted_at"].is_null()),
        (200, true),
        "{}",
        r.text
    );
    let r = app.call("GET", "/api/models/{id}", &[&v2], None).await;
    assert!(r.json["model"]["deleted_at"].is_null(), "{}", r.text);
    assert_eq!(
        app.call("POST", "/api/models/{id}/restore", &[&v2], None)
            .await
            .status,
        409
    );
    assert_eq!(
        app.call("DELETE", "/api/models/{id}", &[&v2], None)
            .await
            .status,
        200
    );
    let v3 = common::stored_model(&app, &cid, &vid, Some(&v1), &[]).await;
    let r = app
        .call("DELETE", "/api/models/{id}?cascade=true", &[&v1], None)
        .await;
    assert_eq!(
        (r.status.as_u16(), r.json["deleted"].clone()),
        (200, json!([v1, v3])),
        "{}",
        r.text
    );
    assert_eq!(
        app.call("DELETE", "/api/models/{id}", &[&v1], None)
            .await
            .status,
        404,
        "deleted already"
    );
    let r = app
        .call("DELETE", "/api/models/{id}?cascade=maybe", &[&v1], None)
        .await;
    assert_eq!(r.status, 400, "{}", r.text);

    // Rename and annotate a model.
    let m = common::stored_model(&app, &cid, &vid, None, &[]).await;
    let r = app
        .call(
            "PATCH",
            "/api/models/{id}",
            &[&m],
            Some(json!({ "name": "Surveyor, final", "notes": "for the DP tuning" })),
        )
        .await;
    assert_eq!(
        (r.json["name"].as_str(), r.json["notes"].as_str()),
        (Some("Surveyor, final"), Some("for the DP tuning")),
        "{}",
        r.text
    );
    let r = app
        .call(
            "PATCH",
            "/api/models/{id}",
            &[&m],
            Some(json!({ "notes": null })),
        )
        .await;
    assert_eq!(
        (r.json["name"].as_str(), r.json["notes"].is_null()),
        (Some("Surveyor, final"), true),
        "{}",
        r.text
    );
    let r = app
        .call(
            "PATCH",
            "/api/models/{id}",
            &[&m],
            Some(json!({ "name": " " })),
        )
        .await;
    refused(&r, 422, "name");
    let r = app
        .call(
            "PATCH",
            "/api/models/{id}",
            &["nope"],
            Some(json!({ "name": "x" })),
        )
        .await;
    assert_eq!(r.status, 404, "{}", r.text);

    // Rename a campaign and a vessel (names trimmed); an unknown field is refused.
    for (route, id, name) in [
        ("/api/campaigns/{id}", &cid, "/spec/name"),
        ("/api/vessels/{id}", &vid, "/profile/name"),
    ] {
        let r = app
            .call(
                "PATCH",
                route,
                &[id],
                Some(json!({ "name": " March trials " })),
            )
            .await;
        assert_eq!(
            r.json.pointer(name),
            Some(&json!("March trials")),
            "{}",
            r.text
        );
        let r = app.call("GET", route, &[id], None).await;
        assert_eq!(
            r.json.pointer(name),
            Some(&json!("March trials")),
            "{}",
            r.text
        );
        for (body, field) in [
            (json!({ "name": "" }), "name"),
            (json!({ "name": "x", "dofs": [] }), "dofs"),
        ] {
            let r = app.call("PATCH", route, &[id], Some(body)).await;
            assert!(
                r.status.is_client_error() && r.json["field"] == field,
                "{route} {field}: {}",
                r.text
            );
        }
        let r = app
            .call("PATCH", route, &["nope"], Some(json!({ "name": "x" })))
            .await;
        assert_eq!(r.status, 404, "{}", r.text);
    }
}

#[tokio::test]
async fn vessels_campaigns_and_jobs_are_paged_with_their_total() {
    let app = TestApp::new().await;
    vessel_and_campaign(&app, json!({})).await;
    vessel_and_campaign(&app, json!({})).await;
    for (path, len, all) in [
        ("/api/vessels?limit=1", 1, 2),
        ("/api/campaigns?limit=1&offset=1", 1, 2),
        ("/api/campaigns?offset=2", 0, 2),
        ("/api/jobs?limit=5", 0, 0),
    ] {
        let r = app.call("GET", path, &[], None).await;
        assert_eq!(
            (r.json.as_array().map(Vec::len), total(&r)),
            (Some(len), all),
            "{path}: {}",
            r.text
        );
    }
    for path in ["/api/vessels?limit=0", "/api/jobs?limit=1001"] {
        let r = app.call("GET", path, &[], None).await;
        refused(&r, 422, "limit");
    }
}
