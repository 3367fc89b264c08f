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
        ("delete", "/api/runs/{id}"),
        ("patch", "/api/campaigns/{id}"),
        ("patch", "/api/models/{id}"),
        ("delete", "/api/models/{id}"),
        ("patch", "/api/vessels/{id}"),
        ("post", "/api/runs/{id}/restore"),
        ("post", "/api/models/{id}/restore"),
    ] {
        assert!(
            spec["paths"][path][method].is_object(),
            "{method} {path} missing from the spec"
        );
    }
}

/// The parameters of one operation: (name, in, required).
fn parameters(spec: &serde_json::Value, path: &str, method: &str) -> Vec<(String, String, bool)> {
    spec["paths"][path][method]["parameters"]
        .as_array()
        .map(|ps| {
            ps.iter()
                .map(|p| {
                    (
                        p["name"].as_str().unwrap().to_string(),
                        p["in"].as_str().unwrap().to_string(),
                        p["required"].as_bool().unwrap_or(false),
                    )
                })
                .collect()
        })
        .unwrap_or_default()
}

#[test]
fn path_parameters_are_exactly_the_templates_placeholders() {
    let spec = serde_json::to_value(seatrial::http::openapi()).unwrap();
    for (path, ops) in spec["paths"].as_object().unwrap() {
        let placeholders: Vec<&str> = path
            .split('{')
            .skip(1)
            .filter_map(|s| s.split('}').next())
            .collect();
        for method in ops.as_object().unwrap().keys() {
            let params = parameters(&spec, path, method);
            for (name, place, required) in &params {
                if place == "path" {
                    assert!(
                        placeholders.contains(&name.as_str()),
                        "{method} {path}: `{name}` is declared in: path but the path has no {{{name}}}"
                    );
                    assert!(
                        required,
                        "{method} {path}: path parameter `{name}` not required"
                    );
                } else {
                    assert_eq!(place, "query", "{method} {path}: `{name}` is in {place}");
                }
            }
            for p in &placeholders {
                assert!(
                    params.iter().any(|(n, i, _)| n == p && i == "path"),
                    "{method} {path}: {{{p}}} is not declared as a path parameter"
                );
            }
        }
    }
}

#[test]
fn query_parameters_the_handlers_read_are_in_query() {
    let spec = serde_json::to_value(seatrial::http::openapi()).unwrap();
    // (path, method, parameter, required): every parameter a handler reads
    // from the query string.
    for (path, method, name, required) in [
        ("/api/campaigns", "get", "vessel_id", false),
        ("/api/jobs", "get", "campaign_id", false),
        ("/api/jobs", "get", "state", false),
        ("/api/runs/{id}/raw", "get", "file", false),
        ("/api/models", "get", "campaign_id", false),
        ("/api/models", "get", "lineage_id", false),
        ("/api/models", "get", "limit", false),
        ("/api/models", "get", "offset", false),
        ("/api/campaigns/{id}/runs", "get", "limit", false),
        ("/api/campaigns/{id}/runs", "get", "offset", false),
        ("/api/campaigns/{id}/runs", "get", "status", false),
        ("/api/models/{id}", "delete", "cascade", false),
        ("/api/models/{id}", "delete", "reason", false),
        ("/api/runs/{id}", "delete", "reason", false),
        ("/api/models", "get", "deleted", false),
        ("/api/vessels", "get", "limit", false),
        ("/api/campaigns", "get", "offset", false),
        ("/api/jobs", "get", "limit", false),
        ("/api/campaigns/{id}/runs", "get", "deleted", false),
        ("/api/models/{id}", "get", "h", false),
        ("/api/models/{id}/export", "get", "format", false),
        ("/api/models/compare", "get", "a", true),
        ("/api/models/compare", "get", "b", true),
        ("/api/models/compare", "get", "run_id", true),
        ("/api/models/compare", "get", "k", false),
        ("/api/models/compare", "get", "restart_s", false),
    ] {
        let params = parameters(&spec, path, method);
        let found = params.iter().find(|(n, _, _)| n == name);
        assert_eq!(
            found.map(|(_, i, r)| (i.as_str(), *r)),
            Some(("query", required)),
            "{method} {path}: `{name}` should be a query parameter (required: {required}); got {params:?}"
        );
    }
}

#[test]
fn the_event_stream_is_documented_as_json_job_events() {
    let spec = serde_json::to_value(seatrial::http::openapi()).unwrap();
    let content = &spec["paths"]["/api/jobs/{id}/events"]["get"]["responses"]["200"]["content"];
    let stream = &content["text/event-stream"]["schema"];
    assert_eq!(
        stream["$ref"], "#/components/schemas/JobEvent",
        "the SSE response should reference JobEvent: {content}"
    );
}

#[test]
fn examples_and_limits_are_what_the_server_accepts() {
    let spec = serde_json::to_value(seatrial::http::openapi()).unwrap();
    let schemas = &spec["components"]["schemas"];
    // The method is documented by the enum of identify's methods, whose
    // example the server accepts.
    let method = serde_json::to_string(&schemas["JobRequest"]["properties"]["method"]).unwrap();
    assert!(
        method.contains("#/components/schemas/IdentifyMethod"),
        "{method}"
    );
    let example = &schemas["IdentifyMethod"]["example"];
    assert!(
        matches!(
            example.as_str(),
            Some("lambda_kf" | "parallel_ekf" | "n4sid")
        ),
        "IdentifyMethod example {example}"
    );
    assert!(
        !method.contains("`lambda`") && !method.contains("`ekf`"),
        "{method}"
    );
    let kinds = serde_json::to_string(&schemas["JobKind"]).unwrap();
    assert!(
        kinds.contains("identify") && kinds.contains("discover"),
        "{kinds}"
    );
    let methods = serde_json::to_string(&schemas["IdentifyMethod"]).unwrap();
    for m in ["lambda_kf", "parallel_ekf", "n4sid"] {
        assert!(methods.contains(m), "{methods}");
    }
    for (schema, field) in [
        ("VesselProfile", "name"),
        ("NewCampaign", "name"),
        ("CampaignSpec", "name"),
        ("RunManage", "name"),
        ("ModelChange", "name"),
        ("CampaignChange", "name"),
    ] {
        let p = &schemas[schema]["properties"][field];
        assert_eq!(
            (p["minLength"].as_u64(), p["maxLength"].as_u64()),
            (Some(1), Some(200)),
            "{schema}.{field}: {p}"
        );
    }
    for (schema, field) in [
        ("VesselProfile", "dofs"),
        ("SpeedGrid", "speeds"),
        ("NewCampaign", "families"),
    ] {
        let p = &schemas[schema]["properties"][field];
        assert_eq!(p["minItems"].as_u64(), Some(1), "{schema}.{field}: {p}");
    }
    let format = serde_json::to_string(&spec["paths"]["/api/models/{id}/export"]["get"]).unwrap();
    assert!(format.contains("ExportFormat"), "{format}");
    assert!(
        serde_json::to_string(&schemas["ExportFormat"])
            .unwrap()
            .contains("fossen")
    );
}
