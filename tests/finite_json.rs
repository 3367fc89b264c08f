//! No inf, NaN or absurd magnitude anywhere the service answers about a
//! campaign and its models. A campaign flown by the Surveyor-like truth
//! (whose restoring a λ model without static runs cannot carry: its roll and
//! pitch simulations are poor) is identified by λ and N4SID, examined by
//! discovery, and joined by a deliberately unstable copy of the λ model
//! (pitch damping of the wrong sign, whose free run blows up). Then every
//! model, export, comparison, run, quality report, coverage, job and
//! discrepancy route is fetched and every JSON number walked: finite, at
//! most 1e15; texts and CSV carry no `inf`, `NaN` or exponent ≥ 16. Every
//! response is also checked against openapi.yaml, where a NaN would show as
//! a `null` in a number field.

mod common;

use common::TestApp;
use common::finite::{assert_clean_text, assert_finite_csv, assert_finite_json, get_finite as get};
use common::flights::flown_campaign;
use common::{identified, run_job};
use seatrial::jobs::{JobRegistry, JobsConfig};
use seatrial_core::simulation::rov::RovTruth;
use serde_json::json;

/// A copy of λ model `mid` whose pitch damping D̄[pitch,pitch] has the
/// wrong sign at every grid speed: A[pitch,pitch] > 0, an unstable model.
async fn unstable_copy(app: &TestApp, mid: &str) -> String {
    use seatrial::storage::models::{Lineage, NewModel, insert};
    let m = get(app, "/api/models/{id}", &[mid]).await;
    let mut doc = m["document"].clone();
    let pitch = doc["dofs"]
        .as_array()
        .unwrap()
        .iter()
        .position(|d| d == "pitch")
        .expect("pitch is modelled");
    let rows = |v: &serde_json::Value| {
        seatrial_core::identification::document::from_rows(
            &serde_json::from_value(v.clone()).unwrap(),
        )
        .unwrap()
    };
    for p in doc["lpv"]["points"].as_array_mut().unwrap() {
        let d = p["d_bar"][pitch][pitch].as_f64().unwrap();
        assert!(d > 0.0, "the identified pitch damping is dissipative");
        p["d_bar"][pitch][pitch] = json!(-d);
        // A = −M⁻¹D̄ follows, as identification stores it.
        let a = -(rows(&p["m"]).try_inverse().unwrap() * rows(&p["d_bar"]));
        p["a"] = json!(seatrial_core::identification::document::to_rows(&a));
    }
    let mut conn = app.state.db.acquire().await.unwrap();
    insert(
        &mut conn,
        NewModel {
            lineage: Lineage::New,
            campaign_id: m["model"]["campaign_id"].as_str().unwrap().into(),
            vessel_id: m["model"]["vessel_id"].as_str().unwrap().into(),
            kind: "lpv".into(),
            method: "lambda_kf".into(),
            name: "unstable pitch".into(),
            settings: json!({}),
            run_ids: vec![],
            validation_run_ids: vec![],
            job_id: None,
            document: doc,
            validation: json!([]),
        },
    )
    .await
    .unwrap()
    .id
}

/// Every model route of `mid`.
async fn walk_model(app: &TestApp, mid: &str) {
    let m = get(app, "/api/models/{id}", &[mid]).await;
    get(app, "/api/models/{id}?h=0.1", &[mid]).await;
    let r = app
        .call("GET", "/api/models/{id}/export?format=json", &[mid], None)
        .await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert_finite_json(&r.json, "export json");
    let r = app
        .call("GET", "/api/models/{id}/export?format=csv", &[mid], None)
        .await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert_finite_csv(&r.text, "parameter csv");
    let r = app
        .call("GET", "/api/models/{id}/export?format=fossen", &[mid], None)
        .await;
    if m["document"]["kind"] == "state_space" {
        assert_eq!(r.status, 422, "{}", r.text);
    } else {
        assert_eq!(r.status, 200, "{}", r.text);
        assert_finite_json(&r.json, "export fossen");
    }
    // The state-space exports, continuous (or N4SID's own h) and ZOH.
    let zoh = if m["document"]["kind"] == "state_space" {
        ""
    } else {
        "&h=0.1"
    };
    for h in ["", zoh] {
        let r = app
            .call(
                "GET",
                &format!("/api/models/{{id}}/export?format=ss_json{h}"),
                &[mid],
                None,
            )
            .await;
        assert_eq!(r.status, 200, "{}", r.text);
        assert_finite_json(&r.json, "export ss_json");
        let r = app
            .call(
                "GET",
                &format!("/api/models/{{id}}/export?format=ss_csv{h}"),
                &[mid],
                None,
            )
            .await;
        assert_eq!(r.status, 200, "{}", r.text);
        assert_finite_csv(&r.text, "export ss_csv");
    }
    get(app, "/api/models/{id}/discrepancies", &[mid]).await;
    // The plot data: Bode, poles and zeros, step and impulse, Hankel.
    for route in [
        "/api/models/{id}/frequency-response",
        "/api/models/{id}/poles",
        "/api/models/{id}/step-response?kind=step",
        "/api/models/{id}/step-response?kind=impulse",
        "/api/models/{id}/hankel",
    ] {
        get(app, route, &[mid]).await;
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn every_number_served_about_a_campaign_and_its_models_is_finite() {
    let app = TestApp::with_jobs(JobRegistry::production(), JobsConfig::default()).await;
    let cid = flown_campaign(&app, &RovTruth::surveyor_like()).await;
    let lambda = identified(&app, &cid, "lambda_kf").await;
    let n4sid = identified(&app, &cid, "n4sid").await;
    let job = run_job(
        &app,
        json!({ "kind": "discover", "campaign_id": cid, "model_id": lambda }),
    )
    .await;
    let did = job["result"]["discrepancy_id"]
        .as_str()
        .unwrap()
        .to_string();
    let augmented = job["result"]["augmented_model_id"]
        .as_str()
        .map(String::from);
    let unstable = unstable_copy(&app, &lambda).await;

    // The unstable copy's pitch step is cut where it diverges, in words;
    // its Hankel singular values are said not to exist.
    let step = get(&app, "/api/models/{id}/step-response", &[&unstable]).await;
    let cut: Vec<f64> = step["points"][0]["channels"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|c| c["diverged_at_s"].as_f64())
        .collect();
    assert!(!cut.is_empty(), "the unstable pitch diverges: {step}");
    let hsv = get(&app, "/api/models/{id}/hankel", &[&unstable]).await;
    assert!(
        hsv["points"][0]["undefined"]
            .as_str()
            .unwrap()
            .contains("not stable")
    );
    let mut models = vec![lambda.clone(), n4sid.clone(), unstable.clone()];
    models.extend(augmented.clone());
    for mid in &models {
        walk_model(&app, mid).await;
    }
    get(&app, "/api/discrepancies/{id}", &[&did]).await;
    get(&app, "/api/models?campaign_id={id}", &[&cid]).await;

    // Side by side on the held-out run; the unstable copy's pitch free run
    // diverges: a finding with a time, no fit, a plot that stops.
    let m = get(&app, "/api/models/{id}", &[&lambda]).await;
    let val = m["validation_run_ids"][0].as_str().unwrap().to_string();
    let mut pairs = vec![(lambda.clone(), unstable.clone()), (lambda.clone(), n4sid)];
    pairs.extend(augmented.map(|a| (lambda.clone(), a)));
    for (a, b) in &pairs {
        let c = get(
            &app,
            "/api/models/compare?a={a}&b={b}&run_id={r}",
            &[a, b, &val],
        )
        .await;
        if b == &unstable {
            let q = c["models"][1]["report"]["channels"]
                .as_array()
                .unwrap()
                .iter()
                .find(|ch| ch["output"] == "q")
                .unwrap()
                .clone();
            let d = &q["diverged"]["simulation"];
            assert_eq!(d["dof"], "pitch", "{q:#}");
            assert!(d["t_s"].as_f64().unwrap() > 0.0);
            assert!(q["fit_simulation"].is_null());
            let verdict = q["verdict"].as_str().unwrap();
            assert!(
                verdict.contains("free-run simulation diverged at t = "),
                "{verdict}"
            );
            let sim = q["plot"]["simulated"].as_array().unwrap();
            assert!(sim.last().unwrap().is_null() && sim[0].is_number());
        }
    }

    // Runs, their quality, coverage, the campaign, jobs.
    let runs = get(&app, "/api/campaigns/{id}/runs", &[&cid]).await;
    for run in runs.as_array().unwrap() {
        let rid = run["id"].as_str().unwrap();
        get(&app, "/api/runs/{id}", &[rid]).await;
        get(&app, "/api/runs/{id}/quality", &[rid]).await;
    }
    get(&app, "/api/campaigns/{id}/coverage", &[&cid]).await;
    get(&app, "/api/campaigns/{id}", &[&cid]).await;
    let jobs = get(&app, "/api/jobs?campaign_id={id}", &[&cid]).await;
    for j in jobs.as_array().unwrap() {
        get(&app, "/api/jobs/{id}", &[j["id"].as_str().unwrap()]).await;
    }
}

#[test]
fn the_text_checks_catch_what_they_are_for() {
    let bad = [
        "fit -7.3e35",
        "amplitude ratio 5.48E+12x 1e16",
        "mean NaN",
        "std inf",
    ];
    for s in bad {
        let caught = std::panic::catch_unwind(|| assert_clean_text(s, "text"));
        assert!(caught.is_err(), "{s} must fail");
    }
    for s in [
        "p = 1e-17",
        "fit 87.3 %",
        "inferred from the data",
        "2.5e7 N",
        "campaign '01a215ca-7615-72d5-88e5-42a41279e875' has no plan yet",
        "campaign '01a215cc-40d0-744c-9e87-317c86220b83' has no plan yet",
        "pid28215-f36e72ac/0",
    ] {
        assert_clean_text(s, "text");
    }
    let csv = "group,symbol,grid_speed_mps,value,std,unit\nM,m,0.5,100000000000000000000,1,kg\n";
    assert!(std::panic::catch_unwind(|| assert_finite_csv(csv, "csv")).is_err());
    let walk = json!({ "rms": 1e16 });
    assert!(std::panic::catch_unwind(|| assert_finite_json(&walk, "x")).is_err());
}
