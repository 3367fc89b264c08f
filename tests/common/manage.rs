//! Helpers of the data-and-model management tests (`api_manage*.rs`).

use serde_json::json;

use super::{Resp, TestApp, rov_profile};

/// A vessel and a campaign on it; their ids.
pub async fn vessel_and_campaign(app: &TestApp, spec: serde_json::Value) -> (String, String) {
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

/// Asserts a refusal with `status` naming `field`.
pub fn refused(r: &Resp, status: u16, field: &str) {
    assert_eq!(
        (r.status.as_u16(), r.json["field"].as_str()),
        (status, Some(field)),
        "{}",
        r.text
    );
}

pub fn total(r: &Resp) -> i64 {
    r.headers["x-total-count"]
        .to_str()
        .unwrap()
        .parse()
        .unwrap()
}

pub fn id(r: &Resp) -> String {
    r.json["id"].as_str().unwrap().to_string()
}
