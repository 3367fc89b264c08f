//! Bounded cost of reads: a model's answer is serialised and compressed
//! once and stays true to its metadata; reads are gzip-compressed off the
//! async workers when the client accepts it, identical once decoded.

mod common;

use std::io::Read;

use axum::body::Body;
use axum::http::Request;
use common::TestApp;
use serde_json::{Value, json};
use tower::ServiceExt;

/// GET `path` with or without `Accept-Encoding: gzip`: the content encoding
/// and the decoded JSON.
async fn get(app: &TestApp, path: &str, gzip: bool) -> (Option<String>, Value) {
    let mut req = Request::builder().method("GET").uri(path);
    if gzip {
        req = req.header("accept-encoding", "gzip, deflate, br");
    }
    let resp = app
        .router
        .clone()
        .oneshot(req.body(Body::empty()).unwrap())
        .await
        .unwrap();
    assert!(resp.status().is_success(), "{path}: {}", resp.status());
    let encoding = resp
        .headers()
        .get("content-encoding")
        .map(|v| v.to_str().unwrap().to_string());
    let bytes = axum::body::to_bytes(resp.into_body(), usize::MAX)
        .await
        .unwrap();
    let text = if encoding.as_deref() == Some("gzip") {
        let mut s = String::new();
        flate2::read::GzDecoder::new(&bytes[..])
            .read_to_string(&mut s)
            .expect("a gzip body");
        s
    } else {
        String::from_utf8(bytes.to_vec()).unwrap()
    };
    (encoding, serde_json::from_str(&text).expect("JSON"))
}

#[tokio::test]
async fn a_model_is_served_from_one_serialisation_true_to_its_metadata() {
    let app = TestApp::new().await;
    let cid = common::rov_campaign_id(&app).await;
    let vid = app
        .call("GET", "/api/campaigns/{id}", &[&cid], None)
        .await
        .json["vessel_id"]
        .as_str()
        .unwrap()
        .to_string();
    let mid = common::stored_model(&app, &cid, &vid, None, &[]).await;
    let path = format!("/api/models/{mid}");

    let (enc, plain) = get(&app, &path, false).await;
    assert_eq!(enc, None);
    let (enc, packed) = get(&app, &path, true).await;
    assert_eq!(enc.as_deref(), Some("gzip"));
    assert_eq!(plain, packed, "the gzip answer decodes to the plain one");
    let (_, again) = get(&app, &path, true).await;
    assert_eq!(again, plain, "the cached answer is the first one");
    // The contract holds for the cached answer.
    let r = app.call("GET", "/api/models/{id}", &[&mid], None).await;
    assert_eq!(r.json, plain);

    // A rename and a note are seen at once, in both encodings.
    let r = app
        .call(
            "PATCH",
            "/api/models/{id}",
            &[&mid],
            Some(json!({"name": "renamed", "notes": "checked at sea"})),
        )
        .await;
    assert_eq!(r.status, 200, "{}", r.text);
    for gzip in [false, true] {
        let (_, v) = get(&app, &path, gzip).await;
        assert_eq!(v["model"]["name"], "renamed");
        assert_eq!(v["model"]["notes"], "checked at sea");
        assert_eq!(v["document"], plain["document"]);
    }

    // A deleted model (soft delete: still readable by id) is served as
    // deleted in both encodings, whatever was cached; restored, as live.
    let r = app
        .call("DELETE", "/api/models/{id}?reason=duplicate", &[&mid], None)
        .await;
    assert_eq!(r.status, 200, "{}", r.text);
    for gzip in [false, true] {
        let (_, v) = get(&app, &path, gzip).await;
        assert!(v["model"]["deleted_at"].is_string(), "{}", v["model"]);
        assert_eq!(v["model"]["delete_reason"], "duplicate");
    }
    let r = app
        .call("POST", "/api/models/{id}/restore", &[&mid], None)
        .await;
    assert_eq!(r.status, 200, "{}", r.text);
    for gzip in [false, true] {
        let (_, v) = get(&app, &path, gzip).await;
        assert!(v["model"]["deleted_at"].is_null(), "{}", v["model"]);
    }
}

#[tokio::test]
async fn large_reads_are_compressed_when_accepted_and_decode_to_the_same_json() {
    let app = TestApp::new().await;
    let cid = common::rov_campaign_id(&app).await;
    let r = app
        .call("POST", "/api/campaigns/{id}/plan", &[&cid], None)
        .await;
    assert!(r.status.is_success(), "{}", r.text);
    let path = format!("/api/campaigns/{cid}/plan");
    let (enc, plain) = get(&app, &path, false).await;
    assert_eq!(enc, None);
    let (enc, packed) = get(&app, &path, true).await;
    assert_eq!(enc.as_deref(), Some("gzip"), "a plan is kilobytes of JSON");
    assert_eq!(plain, packed);
    // A small answer is sent as it is.
    let (enc, _) = get(&app, "/api/jobs", true).await;
    assert_eq!(enc, None);
}
