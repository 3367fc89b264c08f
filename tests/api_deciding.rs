//! Discovery's deciding experiments as planned runs through REST: a
//! re-plan with `deciding` (an ambiguity's `experiment`, as the discovery
//! report gives it) adds one run per heading after the plan's own, which
//! keep their ids; the same re-plan again stores nothing; a proposal beyond
//! the vessel is a 422 naming the field; `deciding: []` removes them.
//! Every response is checked against openapi.yaml.

mod common;

use common::{TestApp, ids_by_code, rov_campaign_id};
use seatrial_core::planning::Dof;
use seatrial_core::planning::examples::deciding_proposal;
use serde_json::{Value, json};

/// A sway-deciding proposal for the Surveyor (90 s legs at `headings`).
fn proposal(headings: Vec<f64>) -> Value {
    let v = seatrial_core::planning::examples::surveyor_rov();
    let mut p = deciding_proposal(&v, Dof::Sway, 0.5, headings);
    p.grid_speed_mps = 0.5;
    p.duration_s = 90.0;
    p.separates[0] = "quadratic damping (sway)".into();
    serde_json::to_value(p).unwrap()
}

#[tokio::test]
async fn a_deciding_experiment_joins_the_plan_and_leaves_it_without_touching_the_rest() {
    let app = TestApp::new().await;
    let cid = rov_campaign_id(&app).await;
    let plan = |body: Option<Value>| {
        let (app, cid) = (&app, &cid);
        async move {
            app.call("POST", "/api/campaigns/{id}/plan", &[cid], body)
                .await
        }
    };
    let v1 = plan(None).await;
    assert_eq!(v1.status, 201, "{}", v1.text);
    let before = ids_by_code(&v1.json);

    let v2 = plan(Some(json!({ "deciding": [proposal(vec![0.0, 90.0])] }))).await;
    assert_eq!(v2.status, 201, "{}", v2.text);
    let after = ids_by_code(&v2.json);
    assert_eq!(after.len(), before.len() + 2);
    assert_eq!(
        &after[..before.len()],
        &before[..],
        "the plan's own runs keep their ids"
    );
    let codes: Vec<&str> = after[before.len()..]
        .iter()
        .map(|(c, _)| c.as_str())
        .collect();
    assert_eq!(codes, ["DEC1-sway-000", "DEC1-sway-090"]);
    let dec = &v2.json["experiments"][before.len()];
    assert_eq!(dec["separates"][1], "Coriolis from M");
    assert!(dec["instruction"].as_str().unwrap().contains("heading 0°"));
    let added = v2.json["changes"]["added"].as_array().unwrap();
    assert_eq!(added.len(), 2, "{}", v2.json["changes"]);

    // Its schedule exports like any planned run's.
    let eid = &after[before.len()].1;
    let csv = app
        .call(
            "GET",
            "/api/campaigns/{id}/plan/experiments/{eid}/schedule.csv",
            &[&cid, eid],
            None,
        )
        .await;
    assert_eq!(csv.status, 200, "{}", csv.text);
    assert!(csv.text.lines().next().unwrap().contains("tau_Y"));

    // The same proposal again: nothing new.
    let again = plan(Some(json!({ "deciding": [proposal(vec![0.0, 90.0])] }))).await;
    assert_eq!(again.status, 200, "{}", again.text);
    assert_eq!(again.json["created"], false);

    // Beyond the vessel: named.
    let mut bad = proposal(vec![0.0]);
    bad["channels"][0]["offset"] = json!(1e9);
    let r = plan(Some(json!({ "deciding": [bad] }))).await;
    assert_eq!(r.status, 422, "{}", r.text);
    assert_eq!(r.json["field"], "deciding[0].channels[0].offset");

    // Removed: the plan's own runs, with their ids.
    let v3 = plan(Some(json!({ "deciding": [] }))).await;
    assert_eq!(v3.status, 201, "{}", v3.text);
    assert_eq!(ids_by_code(&v3.json), before);
}
