//! Flying a planned ROV campaign through the truth simulator and uploading
//! its logs: what the identification and discovery tests share.

#![allow(dead_code)]

use seatrial_core::planning::{CampaignSpec, generate_plan};
use seatrial_core::simulation::rov::RovTruth;
use seatrial_core::simulation::trials::{MeasurementNoise, TrialSettings, fly_experiment};
use serde_json::{Value, json};

use super::{TestApp, rov_profile};

/// The Surveyor-like truth without restoring: what the λ model at each grid
/// speed can represent.
pub fn linear_truth() -> RovTruth {
    let mut truth = RovTruth::surveyor_like();
    truth.restoring = Default::default();
    truth
}

/// A truth the λ model represents exactly at every grid speed: the
/// Surveyor-like truth with diagonal M, constant diagonal damping (its value
/// at 0.75 m/s) and neutral restoring — the clean base of concealed-effect
/// cases.
pub fn diagonal_truth() -> RovTruth {
    use seatrial_core::simulation::rov::LinearDamping;
    let rich = RovTruth::surveyor_like();
    let (mut m, mut d) = (rich.m, rich.damping.at(0.75));
    for x in [&mut m, &mut d] {
        x.fill_lower_triangle(0.0, 1);
        x.fill_upper_triangle(0.0, 1);
    }
    RovTruth::new(m, LinearDamping::constant(d))
}

/// Creates the Surveyor and a campaign on 1 and 2 kn with recursive and
/// validation experiments, flies every planned experiment (≤ 240 s each)
/// through `truth`, and uploads the logs linked to their experiments.
pub async fn flown_campaign(app: &TestApp, truth: &RovTruth) -> String {
    let spec = json!({
        "name": "identification trial",
        "grid": { "unit": "kn", "speeds": [1.0, 2.0] },
        "families": ["recursive", "validation"],
        "repetitions": 2,
        "seed": 11
    });
    let (cid, plan, logs) = flown_logs(app, spec, truth, |_| true).await;
    for (code, csv) in &logs {
        upload_planned(app, &cid, &plan, code, csv).await;
    }
    cid
}

/// Uploads the log `csv` of the planned experiment `code` (its id looked up
/// in the stored `plan`) to campaign `cid`, linked to that experiment.
pub async fn upload_planned(app: &TestApp, cid: &str, plan: &Value, code: &str, csv: &str) {
    let eid = plan["experiments"]
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["code"] == code)
        .and_then(|e| e["id"].as_str())
        .unwrap_or_else(|| panic!("experiment {code} not in the stored plan"));
    let meta = json!({ "experiment_id": eid }).to_string();
    let r = app
        .upload_run(
            cid,
            &[
                ("meta", None, &meta),
                ("file", Some(&format!("{code}.csv")), csv),
            ],
        )
        .await;
    assert_eq!(r.status, 201, "{code}: {}", r.text);
}

/// Creates the Surveyor and a campaign from `spec` (no `vessel_id`), plans
/// it, and flies the planned experiments whose codes `keep` accepts
/// (≤ 240 s each) through `truth`. Returns the campaign id, the stored plan
/// and the `(code, csv)` logs, not uploaded.
pub async fn flown_logs(
    app: &TestApp,
    spec: Value,
    truth: &RovTruth,
    keep: impl Fn(&str) -> bool,
) -> (String, Value, Vec<(String, String)>) {
    let (cid, plan) = planned_campaign(app, rov_profile(), spec.clone()).await;
    let profile = seatrial_core::planning::examples::surveyor_rov();
    let core_spec: CampaignSpec = serde_json::from_value(spec).unwrap();
    let core_plan = generate_plan(&profile, &core_spec).unwrap();
    // A fibre-optic gyro (±0.001 rad/s): roll and pitch are excited by
    // attitude (±10° about level), so p and q move ≈ 0.03 rad/s (std) on a
    // validation run, and a MEMS gyro's ±0.005 rad/s would put their
    // held-out fits at the noise ceiling (≈ 0.75–0.8), where discovery's
    // absolute tolerance of 0.005 in fit is below the fit's own noise.
    let mut noise = MeasurementNoise::default();
    noise.nu[3..6].fill(0.001);
    let settings = TrialSettings {
        max_duration_s: Some(240.0),
        seed: 3,
        noise,
        ..TrialSettings::default()
    };
    let logs = core_plan
        .experiments
        .iter()
        .filter(|p| keep(&p.experiment.code))
        .map(|p| {
            let flown = fly_experiment(&profile, truth, p, &settings).unwrap();
            (p.experiment.code.clone(), flown.csv)
        })
        .collect();
    (cid, plan, logs)
}

/// Creates a vessel of `profile` and a campaign of `spec` (without
/// `vessel_id`) for it, and generates its plan. Returns the campaign id and
/// the stored plan.
pub async fn planned_campaign(app: &TestApp, profile: Value, spec: Value) -> (String, Value) {
    let r = app.call("POST", "/api/vessels", &[], Some(profile)).await;
    assert_eq!(r.status, 201, "{}", r.text);
    let mut body = spec;
    body["vessel_id"] = json!(r.json["id"]);
    let r = app.call("POST", "/api/campaigns", &[], Some(body)).await;
    assert_eq!(r.status, 201, "{}", r.text);
    let cid = r.json["id"].as_str().unwrap().to_string();
    let plan = app
        .call("POST", "/api/campaigns/{id}/plan", &[&cid], None)
        .await;
    assert_eq!(plan.status, 201, "{}", plan.text);
    (cid, plan.json)
}
