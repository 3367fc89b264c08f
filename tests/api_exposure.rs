//! Safe to expose (issue 17): Host allow-list against DNS rebinding, the
//! Origin rule on writes, security headers on every response, and only the
//! web UI's files served.

mod common;

use axum::http::{HeaderMap, StatusCode};
use common::TestApp;
use serde_json::Value;

async fn send(
    app: &TestApp,
    method: &str,
    path: &str,
    headers: &[(&str, &str)],
    body: Option<Value>,
) -> (StatusCode, HeaderMap, Value) {
    let body = body.map(|b| ("application/json", b.to_string()));
    let r = app.raw_with(method, path, headers, body).await;
    (r.status, r.headers, r.json)
}

fn vessel() -> Value {
    common::rov_profile()
}

#[tokio::test]
async fn a_foreign_host_is_misdirected_and_local_names_are_served() {
    let app = TestApp::new().await;
    for host in ["evil.example", "evil.example:8080", "127.0.0.1.nip.io"] {
        let (status, _, body) = send(&app, "GET", "/api/health", &[("host", host)], None).await;
        assert_eq!(status, StatusCode::MISDIRECTED_REQUEST, "{host}: {body}");
        assert_eq!(body["status"], 421);
        assert_eq!(body["field"], "Host");
        assert!(
            body["message"].as_str().unwrap().contains("DNS rebinding"),
            "{body}"
        );
        // The web page is no more reachable under that name than the API.
        let (status, _, _) = send(&app, "GET", "/", &[("host", host)], None).await;
        assert_eq!(status, StatusCode::MISDIRECTED_REQUEST);
    }
    for host in [
        "localhost:8080",
        "LOCALHOST",
        "127.0.0.1:1234",
        "[::1]:8080",
    ] {
        let (status, _, body) = send(&app, "GET", "/api/health", &[("host", host)], None).await;
        assert_eq!(status, StatusCode::OK, "{host}: {body}");
    }
}

#[tokio::test]
async fn a_configured_host_is_served() {
    let mut app = TestApp::new().await;
    app.state.exposure = std::sync::Arc::new(
        seatrial::http::exposure::Exposure::local(None).allow_hosts(&["trials.example.org"]),
    );
    let web = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("web");
    app.router = seatrial::http::app(app.state.clone(), web);
    let (status, _, _) = send(
        &app,
        "GET",
        "/api/health",
        &[("host", "trials.example.org:8443")],
        None,
    )
    .await;
    assert_eq!(status, StatusCode::OK);
    let (status, _, _) = send(
        &app,
        "GET",
        "/api/health",
        &[("host", "evil.example")],
        None,
    )
    .await;
    assert_eq!(status, StatusCode::MISDIRECTED_REQUEST);
}

#[tokio::test]
async fn a_cross_origin_write_is_forbidden_and_a_same_origin_write_goes_through() {
    let app = TestApp::new().await;
    let host = ("host", "127.0.0.1:8080");
    for origin in ["http://evil.example", "null", "http://127.0.0.1:9999"] {
        let (status, _, body) = send(
            &app,
            "POST",
            "/api/vessels",
            &[host, ("origin", origin)],
            Some(vessel()),
        )
        .await;
        assert_eq!(status, StatusCode::FORBIDDEN, "{origin}: {body}");
        assert_eq!(body["field"], "Origin");
        assert!(body["message"].as_str().unwrap().contains(origin), "{body}");
    }
    // Nothing was created.
    let (_, _, list) = send(&app, "GET", "/api/vessels", &[host], None).await;
    assert_eq!(list.as_array().map(Vec::len), Some(0), "{list}");
    // Fetch metadata without Origin.
    let (status, _, _) = send(
        &app,
        "POST",
        "/api/vessels",
        &[host, ("sec-fetch-site", "cross-site")],
        Some(vessel()),
    )
    .await;
    assert_eq!(status, StatusCode::FORBIDDEN);
    // A cross-origin read is not a write.
    let (status, _, _) = send(
        &app,
        "GET",
        "/api/vessels",
        &[host, ("origin", "http://evil.example")],
        None,
    )
    .await;
    assert_eq!(status, StatusCode::OK);
    // The service's own page, and a REST client without Origin.
    let (status, _, body) = send(
        &app,
        "POST",
        "/api/vessels",
        &[host, ("origin", "http://127.0.0.1:8080")],
        Some(vessel()),
    )
    .await;
    assert_eq!(status, StatusCode::CREATED, "{body}");
    let (status, _, body) = send(&app, "POST", "/api/vessels", &[host], Some(vessel())).await;
    assert_eq!(status, StatusCode::CREATED, "{body}");
}

#[tokio::test]
async fn a_configured_origin_may_write() {
    let mut app = TestApp::new().await;
    app.state.exposure = std::sync::Arc::new(
        seatrial::http::exposure::Exposure::local(None)
            .allow_origins(&["https://ops.example.org/"]),
    );
    let web = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("web");
    app.router = seatrial::http::app(app.state.clone(), web);
    let (status, _, body) = send(
        &app,
        "POST",
        "/api/vessels",
        &[
            ("host", "localhost:8080"),
            ("origin", "https://ops.example.org"),
        ],
        Some(vessel()),
    )
    .await;
    assert_eq!(status, StatusCode::CREATED, "{body}");
}

#[tokio::test]
async fn every_response_carries_the_security_headers() {
    let app = TestApp::new().await;
    let cases: [(&str, &[(&str, &str)]); 5] = [
        ("/api/health", &[]),
        ("/api/vessels/nope", &[]),
        ("/", &[]),
        ("/package.json", &[]),
        ("/api/health", &[("host", "evil.example")]),
    ];
    for (path, headers) in cases {
        let (status, h, _) = send(&app, "GET", path, headers, None).await;
        let get = |n: &str| h.get(n).map(|v| v.to_str().unwrap().to_string());
        let csp = get("content-security-policy").unwrap_or_default();
        assert!(csp.contains("default-src 'self'"), "{path} {status}: {csp}");
        assert!(csp.contains("frame-ancestors 'none'"), "{path}: {csp}");
        assert!(!csp.contains("unsafe-inline"), "{path}: {csp}");
        assert_eq!(get("x-content-type-options").as_deref(), Some("nosniff"));
        assert_eq!(get("x-frame-options").as_deref(), Some("DENY"));
        assert_eq!(get("referrer-policy").as_deref(), Some("no-referrer"));
        if path.starts_with("/api/") {
            assert_eq!(get("cache-control").as_deref(), Some("no-store"), "{path}");
        }
    }
}

#[tokio::test]
async fn only_the_web_ui_files_are_served() {
    let app = TestApp::new().await;
    for path in ["/", "/index.html", "/app.js", "/style.css"] {
        let (status, _, _) = send(&app, "GET", path, &[], None).await;
        assert_eq!(status, StatusCode::OK, "{path}");
    }
    for path in [
        "/package.json",
        "/package-lock.json",
        "/node_modules/.package-lock.json",
        "/node_modules/uplot/package.json",
        "/node_modules/playwright-core/package.json",
        "/tests/harness.mjs",
        "/tests/sim.mjs",
        "/tests/",
        "/..%2fCargo.toml",
    ] {
        let (status, _, body) = send(&app, "GET", path, &[], None).await;
        assert_eq!(status, StatusCode::NOT_FOUND, "{path}: {body}");
    }
}
