//! `openapi.yaml` is a snapshot of the spec generated from the router:
//! this test fails when they differ. `UPDATE_OPENAPI=1 cargo test --release
//! --test openapi` rewrites the snapshot after a deliberate API change.

use std::path::Path;

#[test]
fn openapi_yaml_matches_the_router() {
    let generated = seatrial::http::openapi()
        .to_yaml()
        .expect("spec serializes");
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("openapi.yaml");
    if std::env::var_os("UPDATE_OPENAPI").is_some() {
        std::fs::write(&path, &generated).unwrap();
        return;
    }
    let committed = std::fs::read_to_string(&path).expect("openapi.yaml exists at the top level");
    assert!(
        committed == generated,
        "openapi.yaml is out of date with the router; run UPDATE_OPENAPI=1 cargo test --release --test openapi and review the diff"
    );
}

#[test]
fn every_fixed_route_of_the_contract_is_documented() {
    let spec = serde_json::to_value(seatrial::http::openapi()).unwrap();
    for (method, path) in [
        ("get", "/api/health"),
        ("post", "/api/vessels"),
        ("get", "/api/vessels"),
        ("get", "/api/vessels/{id}"),
        ("post", "/api/campaigns"),
        ("get", "/api/campaigns"),
        ("get", "/api/campaigns/{id}"),
        ("post", "/api/campaigns/{id}/plan"),
        ("get", "/api/campaigns/{id}/plan"),
        (
            "get",
            "/api/campaigns/{id}/plan/experiments/{eid}/schedule.csv",
        ),
        ("post", "/api/jobs"),
        ("get", "/api/jobs"),
        ("get", "/api/jobs/{id}"),
        ("post", "/api/jobs/{id}/cancel"),
        ("post", "/api/jobs/{id}/retry"),
        ("get", "/api/jobs/{id}/events"),
        ("get", "/api/campaigns/{id}/clock-offset"),
        ("put", "/api/campaigns/{id}/clock-offset"),
        ("get", "/api/runs/{id}/clock-offset"),
        ("put", "/api/runs/{id}/clock-offset"),
        ("get", "/api/runs/{id}"),
        ("patch", "/api/runs/{id}"),
    ] {
        assert!(
            spec["paths"][path][method].is_object(),
            "{method} {path} missing from the spec"
        );
    }
}
