//! Test harness: the real router over a fresh SQLite file, driven in-process,
//! with every JSON response validated against the schema `openapi.yaml`
//! documents for its route and status.

#![allow(dead_code)]

pub mod auth;
pub mod finite;
pub mod flights;
pub mod jobs;
pub mod manage;
pub mod sim;

use std::sync::Arc;

use axum::Router;
use axum::body::Body;
use axum::http::{Request, StatusCode};
use serde_json::{Value, json};
use tower::ServiceExt;

pub struct TestApp {
    pub router: Router,
    pub spec: Value,
    pub state: seatrial::http::AppState,
    /// The job runner, when started (`with_jobs`).
    pub runner: Option<seatrial::jobs::RunnerHandle>,
    dir: Arc<tempfile::TempDir>,
}

/// A response: status, content type, body text and parsed JSON (if any).
pub struct Resp {
    pub status: StatusCode,
    pub headers: axum::http::HeaderMap,
    pub content_type: String,
    pub text: String,
    /// The body as received (binary downloads such as `.npz`).
    pub bytes: Vec<u8>,
    pub json: Value,
}

impl TestApp {
    pub async fn new() -> Self {
        Self::with_upload_limit(64 << 20).await
    }

    /// An app whose uploads are limited to `max_upload_bytes`.
    pub async fn with_upload_limit(max_upload_bytes: u64) -> Self {
        let dir = Arc::new(tempfile::tempdir().unwrap());
        let jobs = seatrial::jobs::Jobs::new(
            seatrial::jobs::JobRegistry::new(),
            seatrial::jobs::JobsConfig::default(),
        );
        Self::build(dir, max_upload_bytes, jobs, false).await
    }

    /// An app with these job kinds and a running job runner (unless
    /// `config.workers` is 0, when jobs stay queued).
    pub async fn with_jobs(
        registry: seatrial::jobs::JobRegistry,
        config: seatrial::jobs::JobsConfig,
    ) -> Self {
        let dir = Arc::new(tempfile::tempdir().unwrap());
        let jobs = seatrial::jobs::Jobs::new(registry, config);
        Self::build(dir, 64 << 20, jobs, true).await
    }

    /// A new server over the same database file (a restart): recovery runs
    /// as the runner starts.
    pub async fn restart(
        &self,
        registry: seatrial::jobs::JobRegistry,
        config: seatrial::jobs::JobsConfig,
    ) -> Self {
        let jobs = seatrial::jobs::Jobs::new(registry, config);
        Self::build(self.dir.clone(), 64 << 20, jobs, true).await
    }

    async fn build(
        dir: Arc<tempfile::TempDir>,
        max_upload_bytes: u64,
        jobs: seatrial::jobs::Jobs,
        run: bool,
    ) -> Self {
        let db = seatrial::storage::open(&dir.path().join("t.db"))
            .await
            .unwrap();
        let state = seatrial::http::AppState::with_jobs(
            db,
            &dir.path().join("blobs"),
            max_upload_bytes,
            jobs.clone(),
        )
        .unwrap();
        let runner = if run {
            Some(
                seatrial::jobs::start(jobs, state.job_context())
                    .await
                    .unwrap(),
            )
        } else {
            None
        };
        let web = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("web");
        let spec = serde_json::to_value(seatrial::http::openapi()).unwrap();
        TestApp {
            router: seatrial::http::app(state.clone(), web),
            spec,
            state,
            runner,
            dir,
        }
    }

    /// Sends a request. `template` is the documented path (e.g.
    /// `/api/vessels/{id}`), `args` fill its parameters in order; the
    /// response is validated against the documented schema.
    pub async fn call(
        &self,
        method: &str,
        template: &str,
        args: &[&str],
        body: Option<Value>,
    ) -> Resp {
        let path = auth::fill(template, args);
        let r = self
            .raw(
                method,
                &path,
                body.map(|b| ("application/json", b.to_string())),
            )
            .await;
        // The operation is the path template; a query string is not part of it.
        let operation = template.split('?').next().unwrap_or(template);
        self.check_contract(method, operation, &r);
        r
    }

    /// Uploads a run to campaign `cid` as multipart `parts` (name, file
    /// name, content), without contract checks.
    pub async fn upload_run(&self, cid: &str, parts: &[(&str, Option<&str>, &str)]) -> Resp {
        let (ct, body) = sim::multipart(parts);
        self.raw(
            "POST",
            &format!("/api/campaigns/{cid}/runs"),
            Some((&ct, body)),
        )
        .await
    }

    /// Sends a request without contract checks (for malformed bodies etc.).
    pub async fn raw(&self, method: &str, path: &str, body: Option<(&str, String)>) -> Resp {
        self.raw_with(method, path, &[], body).await
    }

    /// [`raw`](Self::raw) with extra request headers (`Host`, `Origin`, …).
    pub async fn raw_with(
        &self,
        method: &str,
        path: &str,
        headers: &[(&str, &str)],
        body: Option<(&str, String)>,
    ) -> Resp {
        let mut req = Request::builder().method(method).uri(path);
        for (k, v) in headers {
            req = req.header(*k, *v);
        }
        let body = match body {
            Some((ct, b)) => {
                req = req.header("content-type", ct);
                Body::from(b)
            }
            None => Body::empty(),
        };
        let resp = self
            .router
            .clone()
            .oneshot(req.body(body).unwrap())
            .await
            .unwrap();
        let status = resp.status();
        let headers = resp.headers().clone();
        let content_type = headers
            .get("content-type")
            .map(|v| v.to_str().unwrap().to_string())
            .unwrap_or_default();
        let bytes = axum::body::to_bytes(resp.into_body(), usize::MAX)
            .await
            .unwrap();
        let text = match std::str::from_utf8(&bytes) {
            Ok(t) => t.to_string(),
            Err(_) => {
                assert!(
                    content_type.starts_with("application/octet-stream"),
                    "{path}: a {content_type} body that is not UTF-8"
                );
                String::from_utf8_lossy(&bytes).into_owned()
            }
        };
        let json = serde_json::from_str(&text).unwrap_or(Value::Null);
        Resp {
            status,
            headers,
            content_type,
            text,
            bytes: bytes.to_vec(),
            json,
        }
    }

    /// Asserts the route, method and status are documented and that a JSON
    /// body validates against the documented schema.
    pub fn check_contract(&self, method: &str, template: &str, r: &Resp) {
        let op = &self.spec["paths"][template][method.to_lowercase()];
        assert!(op.is_object(), "{method} {template} is not in openapi.yaml");
        let doc = &op["responses"][r.status.as_str()];
        assert!(
            doc.is_object(),
            "{method} {template} answered {} which openapi.yaml does not document: {}",
            r.status,
            r.text
        );
        if r.content_type.starts_with("application/json") {
            let schema = &doc["content"]["application/json"]["schema"];
            assert!(
                schema.is_object(),
                "{method} {template} {}: no JSON schema documented",
                r.status
            );
            let root = json!({ "components": self.spec["components"], "allOf": [schema] });
            let validator = jsonschema::validator_for(&root).expect("schema compiles");
            let errors: Vec<String> = validator
                .iter_errors(&r.json)
                .map(|e| format!("{} at {}", e, e.instance_path()))
                .collect();
            assert!(
                errors.is_empty(),
                "{method} {template} {}: response violates its schema: {errors:#?}",
                r.status
            );
        } else if r.text.is_empty() && r.content_type.is_empty() {
            // No body (204): the documented answer must have no content either.
            assert!(
                doc["content"].as_object().is_none_or(|m| m.is_empty()),
                "{method} {template} {}: answered without a body",
                r.status
            );
        } else {
            let documented: Vec<&String> = doc["content"]
                .as_object()
                .map(|m| m.keys().collect())
                .unwrap_or_default();
            let ct = r.content_type.split(';').next().unwrap_or("");
            assert!(
                documented.iter().any(|d| d.as_str() == ct),
                "{method} {template} {}: content type {ct} not documented ({documented:?})",
                r.status
            );
        }
    }
}

/// The Surveyor ROV profile as JSON.
pub fn rov_profile() -> Value {
    serde_json::to_value(seatrial_core::planning::examples::surveyor_rov()).unwrap()
}

/// A Surveyor ROV and a one-speed dynamic campaign for it; the campaign's id.
pub async fn rov_campaign_id(app: &TestApp) -> String {
    let r = app
        .call("POST", "/api/vessels", &[], Some(rov_profile()))
        .await;
    assert_eq!(r.status, 201, "{}", r.text);
    let body = json!({
        "vessel_id": r.json["id"],
        "name": "trial",
        "grid": { "unit": "kn", "speeds": [1.0] },
        "families": ["dynamic"],
        "seed": 5
    });
    let r = app.call("POST", "/api/campaigns", &[], Some(body)).await;
    assert_eq!(r.status, 201, "{}", r.text);
    r.json["id"].as_str().unwrap().to_string()
}

/// A valid single-file log of that ROV: 60 s at 10 Hz, every column.
pub fn rov_log() -> String {
    let run = sim::simulate(
        1,
        10.0,
        60.0,
        [400.0, 800.0, 800.0, 0.0, 600.0, 600.0],
        3.0,
        1e-4,
    );
    sim::csv(&run, &sim::all_columns(), 100.0, 1)
}

/// Fossen's supply vessel profile as JSON.
pub fn dp_profile() -> Value {
    serde_json::to_value(seatrial_core::planning::examples::supply_vessel()).unwrap()
}

/// Submits the job `body` and waits for it (at most two minutes); it must
/// succeed. Its JSON.
pub async fn run_job(app: &TestApp, body: Value) -> Value {
    let r = app.call("POST", "/api/jobs", &[], Some(body)).await;
    assert_eq!(r.status, 202, "{}", r.text);
    let job = wait_for_job(app, r.json["id"].as_str().unwrap(), 120).await;
    assert_eq!(job["state"], "succeeded", "{job}");
    job
}

/// Submits the job `body` and expects a 422 whose field starts with `field`.
pub async fn assert_job_refused(app: &TestApp, body: Value, field: &str) {
    let r = app.call("POST", "/api/jobs", &[], Some(body.clone())).await;
    assert_eq!(r.status, 422, "{body}: {}", r.text);
    let got = r.json["field"].as_str().unwrap_or("");
    assert!(got.starts_with(field), "{body}: field {got}, {}", r.text);
}

/// Identifies campaign `cid` by `method`; the stored model's id.
pub async fn identified(app: &TestApp, cid: &str, method: &str) -> String {
    let job = run_job(
        app,
        json!({ "kind": "identify", "campaign_id": cid, "method": method }),
    )
    .await;
    job["result"]["model_id"].as_str().unwrap().to_string()
}

/// Polls `GET /api/jobs/{id}` until the job ends (at most `seconds`); its JSON.
pub async fn wait_for_job(app: &TestApp, job_id: &str, seconds: u64) -> Value {
    for _ in 0..seconds * 10 {
        let r = app.call("GET", "/api/jobs/{id}", &[job_id], None).await;
        let state = r.json["state"].as_str().unwrap_or("").to_string();
        if ["succeeded", "failed", "cancelled", "interrupted"].contains(&state.as_str()) {
            return r.json;
        }
        tokio::time::sleep(std::time::Duration::from_millis(100)).await;
    }
    panic!("job {job_id} did not finish in {seconds} s");
}

/// A stored one-DOF LPV model (the identify job itself is proven in
/// api_models; model routes only need something to serve): the next version
/// after `after` (else a new lineage), estimated from `run_ids`.
pub async fn stored_model(
    app: &TestApp,
    cid: &str,
    vid: &str,
    after: Option<&str>,
    run_ids: &[&str],
) -> String {
    use seatrial::storage::models::{Lineage, NewModel, insert};
    use seatrial_core::identification::document::{
        LpvDoc, LpvPoint, Method, ModelDocument, ModelKind,
    };
    let one = vec![vec![1.0]];
    let doc = ModelDocument {
        kind: ModelKind::Lpv,
        method: Method::LambdaKf,
        dofs: vec![seatrial_core::planning::Dof::Surge],
        inputs: vec!["γ_X".into()],
        outputs: vec!["u".into()],
        restoring: None,
        lpv: Some(LpvDoc {
            t_lambda_s: 1.0,
            structure: "diagonal".into(),
            coupling: vec![vec![true]],
            points: vec![LpvPoint {
                load: None,
                load_std: None,
                speed_mps: 0.5,
                m: vec![vec![5800.0]],
                m_std: vec![vec![50.0]],
                d_bar: vec![vec![1500.0]],
                d_bar_std: vec![vec![20.0]],
                a: vec![vec![-1500.0 / 5800.0]],
                a_std: one.clone(),
                b: vec![vec![1.0 / 5800.0]],
                b_std: one,
                n_samples: 100,
                run_ids: vec![],
                current_force: None,
                augmentation: None,
            }],
            logged_controller: None,
            extension: None,
            coriolis_second_order: false,
            quadratic_damping: None,
            quadratic_damping_std: None,
            current: None,
        }),
        dp_ship: None,
        state_space: None,
        parameters: vec![],
        structure_findings: vec![],
        notes: vec![],
    };
    let mut conn = app.state.db.acquire().await.unwrap();
    let m = insert(
        &mut conn,
        NewModel {
            lineage: after.map_or(Lineage::New, |p| Lineage::After(p.to_string())),
            campaign_id: cid.into(),
            vessel_id: vid.into(),
            kind: "lpv".into(),
            method: "lambda_kf".into(),
            name: "walk".into(),
            settings: json!({}),
            run_ids: run_ids.iter().map(|r| r.to_string()).collect(),
            validation_run_ids: vec![],
            job_id: None,
            document: serde_json::to_value(&doc).unwrap(),
            validation: json!([]),
        },
    )
    .await
    .unwrap();
    m.id
}

/// A plan response's experiments as (code, id), in plan order.
pub fn ids_by_code(plan: &Value) -> Vec<(String, String)> {
    plan["experiments"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| {
            (
                e["code"].as_str().unwrap().to_string(),
                e["id"].as_str().unwrap().to_string(),
            )
        })
        .collect()
}
