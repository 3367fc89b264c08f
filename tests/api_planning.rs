//! The planning API end to end over a real SQLite file: both acceptance
//! campaigns (ROV on {0.5 … 3.5} kn, DP with the three decoupled
//! manoeuvres), exports, and bad input on every route. Every response is
//! validated against the schema openapi.yaml documents for it.

mod common;

use common::{TestApp, dp_profile, rov_profile};
use serde_json::{Value, json};

async fn create_vessel(app: &TestApp, profile: Value) -> String {
    let r = app.call("POST", "/api/vessels", &[], Some(profile)).await;
    assert_eq!(r.status, 201, "{}", r.text);
    r.json["id"].as_str().unwrap().to_string()
}

fn rov_campaign(vessel_id: &str) -> Value {
    json!({
        "vessel_id": vessel_id,
        "name": "Surveyor LPV 0.5–3.5 kn",
        "grid": { "unit": "kn", "speeds": [0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5] },
        "families": ["static", "dynamic", "recursive", "validation"],
        "seed": 11
    })
}

#[tokio::test]
async fn rov_campaign_is_planned_stored_and_exported() {
    let app = TestApp::new().await;
    let r = app.call("GET", "/api/health", &[], None).await;
    assert_eq!(r.json["status"], "ok");

    let vid = create_vessel(&app, rov_profile()).await;
    let r = app.call("GET", "/api/vessels/{id}", &[&vid], None).await;
    assert_eq!(r.json["profile"]["name"], "Surveyor ROV");
    assert_eq!(r.json["profile"]["limits"]["roll"]["max_velocity"], 0.3);
    let r = app.call("GET", "/api/vessels", &[], None).await;
    assert_eq!(r.json.as_array().unwrap().len(), 1);

    let r = app
        .call("POST", "/api/campaigns", &[], Some(rov_campaign(&vid)))
        .await;
    assert_eq!(r.status, 201, "{}", r.text);
    let cid = r.json["id"].as_str().unwrap().to_string();
    // Entered in knots, stored in SI.
    let si: Vec<f64> = serde_json::from_value(r.json["grid_speeds_mps"].clone()).unwrap();
    assert!((si[6] - 3.5 * 1852.0 / 3600.0).abs() < 1e-12);
    let r = app.call("GET", "/api/campaigns", &[], None).await;
    assert_eq!(r.json.as_array().unwrap().len(), 1);
    let r = app
        .raw("GET", &format!("/api/campaigns?vessel_id={vid}"), None)
        .await;
    app.check_contract("GET", "/api/campaigns", &r);
    assert_eq!(r.json.as_array().unwrap().len(), 1);
    app.call("GET", "/api/campaigns/{id}", &[&cid], None).await;

    // No plan yet.
    let r = app
        .call("GET", "/api/campaigns/{id}/plan", &[&cid], None)
        .await;
    assert_eq!(r.status, 404);
    assert!(r.json["message"].as_str().unwrap().contains("no plan yet"));

    let r = app
        .call("POST", "/api/campaigns/{id}/plan", &[&cid], None)
        .await;
    assert_eq!(r.status, 201, "{}", r.text);
    let mut plan = r.json.clone();
    assert_eq!(plan["created"], true);
    plan.as_object_mut().unwrap().remove("created");
    assert_eq!(plan["version"], 1);
    assert_eq!(plan["totals"]["experiments"], 77 + 42 + 7 + 1);
    assert_eq!(plan["totals"]["per_family"]["static"], 77);
    let r = app
        .call("GET", "/api/campaigns/{id}/plan", &[&cid], None)
        .await;
    assert_eq!(r.json, plan, "the stored plan reads back as generated");

    // One dynamic experiment: JSON export and CSV agree sample for sample.
    let exp = plan["experiments"]
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["code"] == "DYN-2kn-sway-r1")
        .unwrap();
    let eid = exp["id"].as_str().unwrap();
    let r = app
        .call(
            "GET",
            "/api/campaigns/{id}/plan/experiments/{eid}",
            &[&cid, eid],
            None,
        )
        .await;
    assert_eq!(r.status, 200);
    let js = r.json;
    let t = js["t"].as_array().unwrap();
    assert_eq!(t.len() as f64, exp["duration_s"].as_f64().unwrap() * 20.0);
    assert_eq!(js["spectra"][0]["name"], "v_ref");
    let r = app
        .call(
            "GET",
            "/api/campaigns/{id}/plan/experiments/{eid}/schedule.csv",
            &[&cid, eid],
            None,
        )
        .await;
    assert_eq!(r.status, 200);
    assert!(r.content_type.starts_with("text/csv"));
    let mut lines = r.text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "t,u_ref,v_ref,w_ref,p_ref,q_ref,r_ref"
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), t.len());
    let v = js["columns"][1]["values"].as_array().unwrap();
    for (k, row) in rows.iter().enumerate() {
        assert_eq!(row[2], v[k].as_f64().unwrap());
        assert!(
            (row[1] - 2.0 * 1852.0 / 3600.0).abs() < 1e-12,
            "surge held at 2 kn"
        );
    }
    assert!(
        v.iter().any(|x| x.as_f64().unwrap() > 0.1) && v.iter().any(|x| x.as_f64().unwrap() < -0.1)
    );

    let r = app
        .call("GET", "/api/campaigns/{id}/plan/runsheet", &[&cid], None)
        .await;
    assert!(r.content_type.starts_with("text/html"));
    assert!(r.text.contains("DYN-2kn-sway-r1") && r.text.contains("total trial time"));

    // Regenerating with the same inputs stores nothing: version 1 as it was.
    let r = app
        .call("POST", "/api/campaigns/{id}/plan", &[&cid], None)
        .await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert_eq!(r.json["version"], 1);
    assert_eq!(r.json["created"], false);
    assert_eq!(r.json["experiments"], plan["experiments"]);
}

#[tokio::test]
async fn dp_campaign_plans_the_three_decoupled_manoeuvres() {
    let app = TestApp::new().await;
    let vid = create_vessel(&app, dp_profile()).await;
    let body = json!({
        "vessel_id": vid,
        "name": "Supply vessel DP",
        "grid": { "unit": "m/s", "speeds": [0.0] },
        "families": ["dp_surge", "dp_sway_yaw", "dp_azimuth"],
        "repetitions": 2
    });
    let r = app
        .call("POST", "/api/campaigns", &[], Some(body.clone()))
        .await;
    assert_eq!(r.status, 201, "{}", r.text);
    let cid = r.json["id"].as_str().unwrap().to_string();
    let r = app
        .call("POST", "/api/campaigns/{id}/plan", &[&cid], None)
        .await;
    let codes: Vec<&str> = r.json["experiments"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["code"].as_str().unwrap())
        .collect();
    assert_eq!(
        codes,
        [
            "SI1-0m/s-r1",
            "SI1-0m/s-r2",
            "SI2-0m/s-r1",
            "SI2-0m/s-r2",
            "SI3-0m/s-r1",
            "SI3-0m/s-r2"
        ]
    );
    let eid = r.json["experiments"][2]["id"].as_str().unwrap().to_string();
    let r = app
        .call(
            "GET",
            "/api/campaigns/{id}/plan/experiments/{eid}/schedule.csv",
            &[&cid, &eid],
            None,
        )
        .await;
    assert!(
        r.text
            .starts_with("t,thr_1,thr_2,thr_3,thr_4,thr_5,thr_6\n")
    );

    // Without a seed, a random one is drawn and stored (reproducible, not 0 for all).
    let mut seeds = Vec::new();
    for _ in 0..2 {
        let r = app
            .call("POST", "/api/campaigns", &[], Some(body.clone()))
            .await;
        seeds.push(r.json["spec"]["seed"].as_u64().unwrap());
    }
    assert_ne!(seeds[0], seeds[1]);
    assert!(seeds.iter().all(|s| *s < 1 << 53));

    // The parallel estimator needs N ≥ 2.
    let mut one = body.clone();
    one["repetitions"] = json!(1);
    let r = app.call("POST", "/api/campaigns", &[], Some(one)).await;
    assert_eq!(r.status, 422);
    assert_eq!(r.json["field"], "repetitions");
    assert_eq!(r.json["limit"], 2.0);
}

#[tokio::test]
async fn bad_input_gets_a_clear_4xx_on_every_route() {
    let app = TestApp::new().await;

    // Vessels: malformed JSON, wrong types, missing fields, unknown values, wrong media type, empty and huge bodies.
    let r = app
        .raw(
            "POST",
            "/api/vessels",
            Some(("application/json", "{\"name\": ".into())),
        )
        .await;
    app.check_contract("POST", "/api/vessels", &r);
    assert_eq!(r.status, 400);
    assert!(
        r.json["message"].as_str().unwrap().contains("line 1"),
        "{}",
        r.text
    );

    let mut p = rov_profile();
    p["limits"]["sway"]["max_force"] = json!("6 kN");
    let r = app.call("POST", "/api/vessels", &[], Some(p)).await;
    assert_eq!(
        (r.status.as_u16(), r.json["field"].as_str()),
        (400, Some("limits.sway.max_force"))
    );

    let mut p = rov_profile();
    p.as_object_mut().unwrap().remove("name");
    let r = app.call("POST", "/api/vessels", &[], Some(p)).await;
    assert_eq!(
        (r.status.as_u16(), r.json["field"].as_str()),
        (400, Some("name"))
    );

    let mut p = rov_profile();
    p["dofs"][1] = json!("swaying");
    let r = app.call("POST", "/api/vessels", &[], Some(p)).await;
    assert_eq!(
        (r.status.as_u16(), r.json["field"].as_str()),
        (400, Some("dofs[1]"))
    );

    let mut p = rov_profile();
    p["limits"]["heave"]["max_force"] = json!(-5.0);
    let r = app.call("POST", "/api/vessels", &[], Some(p)).await;
    assert_eq!(
        (r.status.as_u16(), r.json["field"].as_str()),
        (422, Some("limits.heave.max_force"))
    );

    // A declared autopilot: every modeled DOF needs a loop; a rate gain is
    // for roll and pitch only; gains are finite and ≥ 0; DOF keys are names.
    let loops = |skip: &str| {
        let mut l = serde_json::Map::new();
        for d in ["surge", "sway", "heave", "roll", "pitch", "yaw"] {
            if d != skip {
                l.insert(d.into(), json!({ "kp": 100.0, "ki": 10.0 }));
            }
        }
        Value::Object(l)
    };
    for (autopilot, status, field) in [
        (
            json!({ "loops": loops("heave") }),
            422,
            "autopilot.loops.heave",
        ),
        (
            json!({ "loops": { "yaw": { "kp": 1.0, "kd": 2.0 } } }),
            422,
            "autopilot.loops.surge",
        ),
        (
            {
                let mut l = loops("");
                l["yaw"]["kd"] = json!(5.0);
                json!({ "loops": l })
            },
            422,
            "autopilot.loops.yaw.kd",
        ),
        (
            {
                let mut l = loops("");
                l["roll"]["kp"] = json!(-3.0);
                json!({ "loops": l })
            },
            422,
            "autopilot.loops.roll.kp",
        ),
        (
            json!({ "loops": loops(""), "restoring_feed_forward": { "w_minus_b": 1e300, "zg_w_minus_zb_b": 1.0 } }),
            422,
            "autopilot.restoring_feed_forward.w_minus_b",
        ),
    ] {
        let mut p = rov_profile();
        p["autopilot"] = autopilot;
        let r = app.call("POST", "/api/vessels", &[], Some(p)).await;
        app.check_contract("POST", "/api/vessels", &r);
        assert_eq!(
            (r.status.as_u16(), r.json["field"].as_str()),
            (status, Some(field)),
            "{}",
            r.text
        );
    }
    let mut p = rov_profile();
    let mut l = loops("");
    l["rol"] = json!({ "kp": 1.0 });
    p["autopilot"] = json!({ "loops": l });
    let r = app.call("POST", "/api/vessels", &[], Some(p)).await;
    assert_eq!(r.status, 400, "{}", r.text);
    assert!(
        r.json["message"]
            .as_str()
            .unwrap()
            .contains("unknown DOF 'rol'"),
        "{}",
        r.text
    );
    let mut p = dp_profile();
    p["autopilot"] = json!({ "loops": { "surge": { "kp": 1.0 } } });
    let r = app.call("POST", "/api/vessels", &[], Some(p)).await;
    assert_eq!(
        (r.status.as_u16(), r.json["field"].as_str()),
        (422, Some("autopilot"))
    );
    // Declared, it is stored and read back as given.
    let mut p = rov_profile();
    let mut l = loops("");
    l["roll"] = json!({ "kp": 400.0, "kd": 250.0 });
    let autopilot = json!({ "loops": l, "restoring_feed_forward": { "w_minus_b": 12.5, "zg_w_minus_zb_b": 310.0 } });
    p["autopilot"] = autopilot.clone();
    let id = create_vessel(&app, p).await;
    let r = app.call("GET", "/api/vessels/{id}", &[&id], None).await;
    app.check_contract("GET", "/api/vessels/{id}", &r);
    assert_eq!(
        r.json["profile"]["autopilot"]["restoring_feed_forward"],
        autopilot["restoring_feed_forward"]
    );
    assert_eq!(
        r.json["profile"]["autopilot"]["loops"]["roll"],
        json!({ "kp": 400.0, "ki": 0.0, "kd": 250.0 })
    );
    assert_eq!(
        r.json["profile"]["autopilot"]["loops"]["surge"],
        json!({ "kp": 100.0, "ki": 10.0 })
    );

    let mut p = rov_profile();
    p["limits"]["heave"]["max_forse"] = json!(5.0);
    let r = app.call("POST", "/api/vessels", &[], Some(p)).await;
    assert_eq!(r.status, 400, "a typo is not silently ignored: {}", r.text);
    assert!(r.json["message"].as_str().unwrap().contains("max_forse"));

    let r = app
        .raw("POST", "/api/vessels", Some(("text/csv", "a,b".into())))
        .await;
    app.check_contract("POST", "/api/vessels", &r);
    assert_eq!(r.status, 415);
    let r = app
        .raw(
            "POST",
            "/api/vessels",
            Some(("application/json", "".into())),
        )
        .await;
    app.check_contract("POST", "/api/vessels", &r);
    assert_eq!(r.status, 400);
    let huge = format!("{{\"name\": \"{}\"}}", "x".repeat(2 << 20));
    let r = app
        .raw("POST", "/api/vessels", Some(("application/json", huge)))
        .await;
    app.check_contract("POST", "/api/vessels", &r);
    assert_eq!(r.status, 413);

    let r = app.call("GET", "/api/vessels/{id}", &["nope"], None).await;
    assert_eq!(r.status, 404);
    assert!(r.json["message"].as_str().unwrap().contains("nope"));

    // Campaigns: unknown vessel, impossible grid, amplitude and clock over their limits.
    let r = app
        .call("POST", "/api/campaigns", &[], Some(rov_campaign("missing")))
        .await;
    assert_eq!(r.status, 404);
    let vid = create_vessel(&app, rov_profile()).await;
    let mut c = rov_campaign(&vid);
    c["grid"]["speeds"] = json!([0.5, 1.0, 5.0]);
    let r = app.call("POST", "/api/campaigns", &[], Some(c)).await;
    assert_eq!(
        (r.status.as_u16(), r.json["field"].as_str()),
        (422, Some("grid.speeds[2]"))
    );
    assert!((r.json["limit"].as_f64().unwrap() - 4.3 * 1852.0 / 3600.0).abs() < 1e-12);
    assert!(
        r.json["message"]
            .as_str()
            .unwrap()
            .contains("maximum forward speed")
    );

    let mut c = rov_campaign(&vid);
    // Roll is excited by attitude: its amplitude is an angle (rad), at most
    // the profile's max_angle, 10° without one.
    c["excitation"] = json!({ "per_dof": { "roll": { "amplitude": 0.45 } } });
    let r = app.call("POST", "/api/campaigns", &[], Some(c)).await;
    assert_eq!(
        (r.status.as_u16(), r.json["field"].as_str()),
        (422, Some("excitation.per_dof.roll.amplitude"))
    );
    assert!((r.json["limit"].as_f64().unwrap() - 10f64.to_radians()).abs() < 1e-12);

    let mut c = rov_campaign(&vid);
    c["excitation"] = json!({ "per_dof": { "sway": { "clock_period_s": 500.0 } } });
    let r = app.call("POST", "/api/campaigns", &[], Some(c)).await;
    assert_eq!(
        (r.status.as_u16(), r.json["field"].as_str()),
        (422, Some("excitation.per_dof.sway.clock_period_s"))
    );

    let mut c = rov_campaign(&vid);
    c["grid"]["speeds"] = json!([1.0, 1.0]);
    let r = app.call("POST", "/api/campaigns", &[], Some(c)).await;
    assert_eq!(
        (r.status.as_u16(), r.json["field"].as_str()),
        (422, Some("grid.speeds[1]"))
    );

    let mut c = rov_campaign(&vid);
    c["durations"] = json!({ "validation_s": 120.0 });
    let r = app.call("POST", "/api/campaigns", &[], Some(c)).await;
    assert_eq!(
        (r.status.as_u16(), r.json["field"].as_str()),
        (422, Some("durations.validation_s"))
    );

    let mut c = rov_campaign(&vid);
    c["grid"]["speeds"] = json!((0..60).map(|i| 0.01 * f64::from(i)).collect::<Vec<_>>());
    let r = app.call("POST", "/api/campaigns", &[], Some(c)).await;
    assert_eq!(
        (r.status.as_u16(), r.json["field"].as_str()),
        (422, Some("grid.speeds"))
    );

    let mut c = rov_campaign(&vid);
    c["families"] = json!(["dp_surge"]);
    let r = app.call("POST", "/api/campaigns", &[], Some(c)).await;
    assert_eq!(
        (r.status.as_u16(), r.json["field"].as_str()),
        (422, Some("families[0]"))
    );

    // Plans and exports of things that do not exist.
    for (m, t, args) in [
        ("POST", "/api/campaigns/{id}/plan", vec!["nope"]),
        ("GET", "/api/campaigns/{id}/plan", vec!["nope"]),
        ("GET", "/api/campaigns/{id}", vec!["nope"]),
        ("GET", "/api/campaigns/{id}/plan/runsheet", vec!["nope"]),
        (
            "GET",
            "/api/campaigns/{id}/plan/experiments/{eid}",
            vec!["nope", "x"],
        ),
        (
            "GET",
            "/api/campaigns/{id}/plan/experiments/{eid}/schedule.csv",
            vec!["nope", "x"],
        ),
    ] {
        let r = app.call(m, t, &args, None).await;
        assert_eq!(r.status, 404, "{m} {t}");
    }
    let r = app
        .call("POST", "/api/campaigns", &[], Some(rov_campaign(&vid)))
        .await;
    let cid = r.json["id"].as_str().unwrap().to_string();
    app.call("POST", "/api/campaigns/{id}/plan", &[&cid], None)
        .await;
    let r = app
        .call(
            "GET",
            "/api/campaigns/{id}/plan/experiments/{eid}/schedule.csv",
            &[&cid, "x"],
            None,
        )
        .await;
    assert_eq!(r.status, 404);

    let r = app.raw("DELETE", "/api/vessels", None).await;
    assert_eq!(r.status, 405);
    assert!(
        r.json["message"].as_str().unwrap().contains("DELETE"),
        "{}",
        r.text
    );
    let r = app.raw("GET", "/api/vessels/%FF", None).await;
    assert!(r.status.is_client_error(), "{}", r.status);

    let r = app.raw("GET", "/api/no/such/route", None).await;
    assert_eq!(r.status, 404);
    assert!(r.json["message"].is_string());
}
