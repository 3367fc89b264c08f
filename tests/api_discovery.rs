//! Missing-physics discovery end to end through REST: a campaign flown by a
//! truth with a metacentric righting moment (which a λ model without static
//! runs leaves out), identified, then a `discover` job names the left-out
//! restoring in roll and pitch, stores the augmented model as version 2 of
//! the model, and the report and both models are served. Every response is
//! checked against openapi.yaml.

mod common;

use common::TestApp;
use common::flights::flown_campaign;
use common::{run_job, wait_for_job};
use seatrial::jobs::{JobRegistry, JobsConfig};
use seatrial_core::simulation::rov::RovTruth;
use serde_json::{Value, json};

async fn app() -> TestApp {
    TestApp::with_jobs(JobRegistry::production(), JobsConfig::default()).await
}

/// Identifies campaign `cid` by `method`; the stored model's id. A λ model
/// is fitted without g(η), constant loads and C(δ)δ, so the restoring,
/// tether, load and Coriolis effects the cases conceal are missing from
/// the baseline.
async fn identified(app: &TestApp, cid: &str, method: &str) -> String {
    let settings = if method == "lambda_kf" {
        json!({ "estimate_restoring": false, "constant_loads": false, "coriolis_second_order": false, "symmetric_inertia": false, "quadratic_damping": false, "extend_above_grid": false })
    } else {
        json!({})
    };
    let job = run_job(
        app,
        json!({ "kind": "identify", "campaign_id": cid, "method": method, "settings": settings }),
    )
    .await;
    job["result"]["model_id"].as_str().unwrap().to_string()
}

fn sim_fit(validation: &Value, ch: &str) -> f64 {
    validation[0]["report"]["channels"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["output"] == ch)
        .and_then(|c| c["fit_simulation"].as_f64())
        .unwrap_or(f64::NEG_INFINITY)
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn discovery_names_the_righting_moment_and_stores_the_augmented_model() {
    let app = app().await;
    let cid = flown_campaign(&app, &RovTruth::surveyor_like()).await;
    let mid = identified(&app, &cid, "lambda_kf").await;

    let job = run_job(
        &app,
        json!({ "kind": "discover", "campaign_id": cid, "model_id": mid }),
    )
    .await;
    assert_eq!(job["progress"], 1.0);
    let did = job["result"]["discrepancy_id"]
        .as_str()
        .unwrap()
        .to_string();
    let aug = job["result"]["augmented_model_id"]
        .as_str()
        .expect("an augmented model")
        .to_string();
    assert_eq!(job["result"]["augmented_version"], 2);

    // The report: restoring named in roll and pitch at both grid speeds.
    let d = app
        .call("GET", "/api/discrepancies/{id}", &[&did], None)
        .await;
    assert_eq!(d.status, 200, "{}", d.text);
    assert_eq!(d.json["model"]["id"], mid.as_str());
    assert_eq!(d.json["augmented_model"]["id"], aug.as_str());
    let effects = d.json["report"]["effects"].as_array().unwrap();
    for dof in ["roll", "pitch"] {
        let e = effects
            .iter()
            .find(|e| e["effect"]["effect"] == "restoring" && e["effect"]["dof"] == dof)
            .unwrap_or_else(|| panic!("no {dof} restoring: {}", d.json["report"]["summary"]));
        assert_eq!(
            e["grid_speeds_mps"].as_array().unwrap().len(),
            2,
            "{e}\n{:#}",
            d.json["report"]["summary"]
        );
        // z_B·B of the truth: 0.2 m × (5000 kg · 9.81 + 250 N) = 9860 N·m.
        for m in e["magnitudes"].as_array().unwrap() {
            let v = m[0].as_f64().unwrap();
            assert!((v - 9860.0).abs() < 0.1 * 9860.0, "{dof}: {v}");
        }
    }
    let points = d.json["report"]["points"].as_array().unwrap();
    assert_eq!(points.len(), 2);
    for p in points {
        let rep = &p["report"];
        assert!(!rep["location"]["sentences"].as_array().unwrap().is_empty());
        assert!(!rep["hypotheses"].as_array().unwrap().is_empty());
        assert!(!rep["plots"].as_array().unwrap().is_empty());
    }
    assert!(!d.json["run_names"].as_object().unwrap().is_empty());

    // Listed on the model it examined.
    let l = app
        .call("GET", "/api/models/{id}/discrepancies", &[&mid], None)
        .await;
    assert_eq!(l.status, 200, "{}", l.text);
    assert_eq!(l.json[0]["id"], did.as_str());

    // The augmented model: version 2 of the same lineage, fits roll and
    // pitch on the held-out runs where the baseline failed.
    let base = app.call("GET", "/api/models/{id}", &[&mid], None).await;
    let new = app.call("GET", "/api/models/{id}", &[&aug], None).await;
    assert_eq!(new.status, 200, "{}", new.text);
    assert_eq!(new.json["model"]["version"], 2);
    assert_eq!(new.json["model"]["parent_id"], mid.as_str());
    assert_eq!(new.json["model"]["method"], "discovery");
    assert_eq!(
        new.json["validation_run_ids"],
        base.json["validation_run_ids"]
    );
    for ch in ["p", "q"] {
        let (b, a) = (
            sim_fit(&base.json["validation"], ch),
            sim_fit(&new.json["validation"], ch),
        );
        assert!(a > 0.6 && a - b > 0.3, "{ch}: {b} → {a}");
    }
    // It validates on any run like every stored model, and exports.
    let val = base.json["validation_run_ids"][0].as_str().unwrap();
    let c = app
        .call(
            "GET",
            "/api/models/compare?a={a}&b={b}&run_id={r}",
            &[&mid, &aug, val],
            None,
        )
        .await;
    assert_eq!(c.status, 200, "{}", c.text);
    let csv = app
        .call("GET", "/api/models/{id}/export?format=csv", &[&aug], None)
        .await;
    assert_eq!(csv.status, 200);
    assert!(csv.text.contains("discovered: restoring"), "{}", csv.text);
    // The Fossen export carries every discovered term of every grid point
    // with its coefficients, std, unit and DOF; the state-space export
    // lists them beside the linear part.
    let fossen = app
        .call(
            "GET",
            "/api/models/{id}/export?format=fossen",
            &[&aug],
            None,
        )
        .await;
    assert_eq!(fossen.status, 200, "{}", fossen.text);
    let stored = new.json["document"]["lpv"]["points"].as_array().unwrap();
    let exported = fossen.json["points"].as_array().unwrap();
    assert_eq!(exported.len(), stored.len());
    let mut named = 0;
    for (p, s) in exported.iter().zip(stored) {
        let terms = p["terms"].as_array().unwrap();
        let kept = s["augmentation"]["terms"].as_array().map_or(0, Vec::len);
        assert_eq!(terms.len(), kept, "{p}");
        for (t, k) in terms
            .iter()
            .zip(s["augmentation"]["terms"].as_array().unwrap())
        {
            assert_eq!(t["effect"], k["effect"]);
            let values: Vec<&Value> = t["coefficients"]
                .as_array()
                .unwrap()
                .iter()
                .map(|c| &c["value"])
                .collect();
            let kept: Vec<&Value> = k["coefficients"].as_array().unwrap().iter().collect();
            assert_eq!(values, kept);
            for c in t["coefficients"].as_array().unwrap() {
                assert!(c["std"].as_f64().is_some_and(|s| s >= 0.0), "{c}");
                assert!(!c["unit"].as_str().unwrap().is_empty(), "{c}");
            }
            named += usize::from(t["dof"].is_string());
        }
    }
    assert!(named > 0, "{}", fossen.text);
    let ss = app
        .call(
            "GET",
            "/api/models/{id}/export?format=ss_json",
            &[&aug],
            None,
        )
        .await;
    assert_eq!(ss.status, 200, "{}", ss.text);
    assert!(!ss.json["terms"].as_array().unwrap().is_empty());

    // Discovery on the augmented model continues from its terms: they are
    // carried (not named again), and a further version, if any, keeps them
    // and the model's name.
    let job = run_job(
        &app,
        json!({ "kind": "discover", "campaign_id": cid, "model_id": aug }),
    )
    .await;
    let did2 = job["result"]["discrepancy_id"].as_str().unwrap();
    let d2 = app
        .call("GET", "/api/discrepancies/{id}", &[did2], None)
        .await;
    assert_eq!(d2.status, 200, "{}", d2.text);
    for (p, s) in d2.json["report"]["points"]
        .as_array()
        .unwrap()
        .iter()
        .zip(stored)
    {
        let kept: Vec<&Value> = s["augmentation"]["terms"]
            .as_array()
            .unwrap()
            .iter()
            .map(|t| &t["effect"])
            .collect();
        let carried: Vec<&Value> = p["report"]["carried"].as_array().unwrap().iter().collect();
        assert_eq!(carried, kept);
        for f in p["report"]["findings"].as_array().unwrap() {
            assert!(!kept.contains(&&f["effect"]), "named again: {f}");
        }
    }
    let summary = d2.json["report"]["summary"].to_string();
    match job["result"]["augmented_model_id"].as_str() {
        // Nothing more found, or something named that the held-out gate
        // refused: either way no new version, and the summary says which.
        None => assert!(
            summary.contains("Nothing found beyond the terms the model carries")
                || summary.contains("The augmented model was not stored: "),
            "{summary}"
        ),
        Some(v3) => {
            let v3 = app.call("GET", "/api/models/{id}", &[v3], None).await;
            assert_eq!(v3.json["model"]["version"], 3);
            assert_eq!(v3.json["model"]["name"], new.json["model"]["name"]);
            assert!(
                summary.contains("Continued from the terms the model carries"),
                "{summary}"
            );
        }
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn bad_discover_requests_name_the_field() {
    let app = app().await;
    let cid = flown_campaign(&app, &RovTruth::surveyor_like()).await;
    let black_box = identified(&app, &cid, "n4sid").await;
    let cases = [
        (json!({ "kind": "discover" }), 422, "model_id"),
        (
            json!({ "kind": "discover", "model_id": "nope" }),
            404,
            "model_id",
        ),
        (
            json!({ "kind": "discover", "model_id": black_box }),
            422,
            "model_id",
        ),
    ];
    for (body, status, field) in cases {
        let r = app.call("POST", "/api/jobs", &[], Some(body.clone())).await;
        assert_eq!(r.status.as_u16(), status, "{body}: {}", r.text);
        assert_eq!(r.json["field"], field, "{body}: {}", r.text);
    }
    let mid = identified(&app, &cid, "lambda_kf").await;
    let cases = [
        (
            json!({ "kind": "discover", "model_id": mid, "settings": { "discovery": { "k_step": "ten" } } }),
            "settings.discovery.k_step",
        ),
        (
            json!({ "kind": "discover", "model_id": mid, "settings": { "grid": [1] } }),
            "settings",
        ),
        (
            json!({ "kind": "discover", "model_id": mid, "method": "lasso" }),
            "method",
        ),
    ];
    for (body, field) in cases {
        let r = app.call("POST", "/api/jobs", &[], Some(body.clone())).await;
        assert_eq!(r.status.as_u16(), 422, "{body}: {}", r.text);
        assert!(
            r.json["field"].as_str().unwrap().starts_with(field),
            "{body}: {}",
            r.text
        );
    }
    // A grid speed the model does not have fails the job naming the field.
    let r = app
        .call(
            "POST",
            "/api/jobs",
            &[],
            Some(json!({ "kind": "discover", "model_id": mid, "settings": { "grid_speeds_mps": [0.3] } })),
        )
        .await;
    assert_eq!(r.status, 202, "{}", r.text);
    let job = wait_for_job(&app, r.json["id"].as_str().unwrap(), 60).await;
    assert_eq!(job["state"], "failed", "{job}");
    assert_eq!(
        job["error"]["field"], "settings.grid_speeds_mps[0]",
        "{job}"
    );
    let r = app
        .call("GET", "/api/discrepancies/{id}", &["nope"], None)
        .await;
    assert_eq!(r.status, 404);
    let r = app
        .call("GET", "/api/models/{id}/discrepancies", &["nope"], None)
        .await;
    assert_eq!(r.status, 404);
}

/// More concealed effects through the whole service path (planned campaign
/// flown under PI control by a truth the λ model represents except for the
/// concealed effects, λ identification, discovery job): each effect and its
/// DOF are named ahead of anything else, at every grid speed; the
/// augmented model is stored only when the held-out gate says it is better,
/// and then its free run in the named channel improves on the held-out runs.
/// (The truth here is the project's own ROV simulator.)
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn concealed_effects_are_named_through_the_service() {
    use common::flights::diagonal_truth;
    let mut quadratic = diagonal_truth();
    quadratic.quadratic_damping[1] = 30000.0;
    let mut coriolis = diagonal_truth();
    coriolis.coriolis = true;
    let mut lag = diagonal_truth();
    lag.actuators.time_constants[2] = 0.8;
    let mut delay = diagonal_truth();
    delay.actuators.delay_samples = 4;
    let mut tether = diagonal_truth();
    tether.tether.body_force = [0.0, 400.0, 0.0];
    let mut current = diagonal_truth();
    current.current = seatrial_core::simulation::rov::Current::Constant {
        ned: [0.15, 0.1, 0.0],
    };
    // Heave thrust capped at 900 N: the PI controller winds up to its own
    // 8000 N limit, so saturation must be told from a late response.
    let mut saturation = diagonal_truth();
    saturation.actuators.saturation[2] = 900.0;
    let mut quad_lag = diagonal_truth();
    quad_lag.quadratic_damping[1] = 30000.0;
    quad_lag.actuators.time_constants[2] = 0.8;
    let mut tether_delay = diagonal_truth();
    tether_delay.tether.body_force = [0.0, 400.0, 0.0];
    tether_delay.actuators.delay_samples = 4;
    type Named = (&'static str, Option<&'static str>, &'static str);
    let cases: Vec<(&str, _, Vec<Named>)> = vec![
        (
            "quadratic damping",
            quadratic,
            vec![("quadratic_damping", Some("sway"), "v")],
        ),
        ("Coriolis", coriolis, vec![("coriolis_from_m", None, "u")]),
        (
            "actuator lag",
            lag,
            vec![("actuator_lag", Some("heave"), "w")],
        ),
        (
            "input delay",
            delay,
            vec![("common_input_delay", None, "u")],
        ),
        ("tether", tether, vec![("constant_load", Some("sway"), "v")]),
        ("current", current, vec![("current", None, "v")]),
        (
            "saturation",
            saturation,
            vec![("saturation", Some("heave"), "w")],
        ),
        (
            "quadratic damping + lag",
            quad_lag,
            vec![
                ("actuator_lag", Some("heave"), "w"),
                ("quadratic_damping", Some("sway"), "v"),
            ],
        ),
        (
            "tether + delay",
            tether_delay,
            vec![
                ("common_input_delay", None, "u"),
                ("constant_load", Some("sway"), "v"),
            ],
        ),
    ];
    for (name, truth, named) in cases {
        let t0 = std::time::Instant::now();
        let app = app().await;
        let cid = flown_campaign(&app, &truth).await;
        let mid = identified(&app, &cid, "lambda_kf").await;
        let job = run_job(&app, json!({ "kind": "discover", "model_id": mid })).await;
        let did = job["result"]["discrepancy_id"].as_str().unwrap();
        let d = app
            .call("GET", "/api/discrepancies/{id}", &[did], None)
            .await;
        let summary = d.json["report"]["summary"].as_array().unwrap();
        let verdict = summary.last().and_then(Value::as_str).unwrap_or_default();
        // Only a model better on the held-out runs is stored. The steady
        // current's model may lose 0.01 in heave (its rows include heave
        // through D̄'s couplings): named, tried, refused, and the report says
        // why (flown with a fibre-optic gyro under attitude excitation of
        // roll and pitch, it is stored).
        let aug = job["result"]["augmented_model_id"].as_str();
        match aug {
            // Stored whole, or with the findings of the grid speeds that
            // passed one at a time ("… with the findings at 1 of 2 grid
            // speeds …").
            Some(_) => assert!(
                verdict.starts_with("The augmented model was stored: ")
                    && verdict.contains("on the held-out runs it improves")
                    && verdict.ends_with(")."),
                "{name}: {verdict}"
            ),
            // Roll and pitch are excited by attitude (±10° about level), so
            // p and q carry ≈ 4× less signal than under the former rate
            // excitation and a refit of their rows (sway–roll–yaw couple in
            // the symmetric structure) moves their held-out fits by ≈ 0.01,
            // beyond the gate's 0.005: an effect refused over p or q alone
            // is still named (checked below), though not stored.
            None if name != "current"
                && verdict.starts_with(
                    "The augmented model was not stored: on the held-out runs it is worse than the baseline in p on",
                )
                && !verdict.contains(" in u on")
                && !verdict.contains(", u on")
                && !verdict.contains(" v on")
                && !verdict.contains(" w on")
                && !verdict.contains(" r on") =>
            {
                eprintln!("{name}: refused over roll/pitch only: {verdict}");
                assert!(d.json["augmented_model"].is_null());
            }
            None => {
                assert_eq!(name, "current", "{name} not stored: {verdict}");
                assert!(
                    verdict.starts_with("The augmented model was not stored: on the held-out runs it is worse than the baseline in w on"),
                    "{verdict}"
                );
                assert!(d.json["augmented_model"].is_null());
            }
        }
        let base = app.call("GET", "/api/models/{id}", &[&mid], None).await;
        let new = match aug {
            Some(aug) => Some(app.call("GET", "/api/models/{id}", &[aug], None).await),
            None => None,
        };
        let mut line = String::new();
        // The report lists the effects across the grid; the concealed ones
        // must be the first `named.len()` of them (in any order).
        let effects = d.json["report"]["effects"].as_array().unwrap();
        for (effect, dof, ch) in &named {
            let e = effects
                .iter()
                .take(named.len())
                .find(|e| {
                    e["effect"]["effect"] == *effect
                        && dof.is_none_or(|dof| e["effect"]["dof"] == dof)
                })
                .unwrap_or_else(|| {
                    panic!(
                        "{name}: {effect} {dof:?} not named: {:#}",
                        d.json["report"]["summary"]
                    )
                });
            assert_eq!(e["grid_speeds_mps"].as_array().unwrap().len(), 2, "{name}");
            line += &format!("{} | ", e["label"]);
            if let Some(new) = &new {
                let (b, a) = (
                    sim_fit(&base.json["validation"], ch),
                    sim_fit(&new.json["validation"], ch),
                );
                assert!(a > b, "{name}: {ch} free run {b} → {a}");
                line += &format!("{ch} free run {b:.3} → {a:.3}; ");
            }
        }
        // A steady current must not be called a drifting one (under speed
        // hold its windows disagree with the manoeuvres, which the report
        // must say as uncertainty, not as a random walk).
        for p in d.json["report"]["points"].as_array().unwrap() {
            if let Some(dr) = p["report"]["current_drift"].as_object() {
                assert_eq!(dr["drifts"], false, "{name}: {}", dr["text"]);
            }
        }
        eprintln!(
            "{name}: {line}{verdict} ({:.1} s)",
            t0.elapsed().as_secs_f64()
        );
    }
    // The clean base: nothing named, no new version.
    let app = app().await;
    let cid = flown_campaign(&app, &diagonal_truth()).await;
    let mid = identified(&app, &cid, "lambda_kf").await;
    let job = run_job(&app, json!({ "kind": "discover", "model_id": mid })).await;
    assert!(job["result"]["augmented_model_id"].is_null(), "{job}");
    let did = job["result"]["discrepancy_id"].as_str().unwrap();
    let d = app
        .call("GET", "/api/discrepancies/{id}", &[did], None)
        .await;
    assert!(d.json["report"]["effects"].as_array().unwrap().is_empty());
    assert!(d.json["augmented_model"].is_null());
}
