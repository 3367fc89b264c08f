//! Managing data and models (issue 16): what the contract promises about
//! requests — integral floats where integers are meant, names by characters.

mod common;

use common::{TestApp, rov_profile};
use serde_json::json;

/// A vessel and a campaign on it; their ids.
async fn vessel_and_campaign(app: &TestApp, spec: serde_json::Value) -> (String, String) {
    let r = app
        .call("POST", "/api/vessels", &[], Some(rov_profile()))
        .await;
    assert_eq!(r.status, 201, "{}", r.text);
    let vid = r.json["id"].as_str().unwrap().to_string();
    let mut body = json!({
        "vessel_id": vid, "name": "manage", "seed": 3,
        "grid": { "unit": "kn", "speeds": [1.0] },
        "families": ["dynamic"]
    });
    for (k, v) in spec.as_object().unwrap() {
        body[k] = v.clone();
    }
    let r = app.call("POST", "/api/campaigns", &[], Some(body)).await;
    assert_eq!(r.status, 201, "{}", r.text);
    (vid, r.json["id"].as_str().unwrap().to_string())
}

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
