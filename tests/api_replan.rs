//! Re-planning is versioned and loses nothing: re-planning an unchanged
//! campaign stores nothing and leaves coverage, run matching and the
//! database as they were; a changed parameter changes only the experiments
//! it affects, and the changes name them and the runs they leave unmatched.
//! Every response is checked against openapi.yaml.

mod common;

use common::flights::{flown_logs, linear_truth, upload_planned};
use common::{Resp, TestApp, ids_by_code, rov_log};
use serde_json::{Value, json};

/// Pages of the database file (WAL included) and its rows of plans,
/// experiments and plan memberships.
async fn footprint(app: &TestApp) -> (i64, i64, i64, i64) {
    let db = &app.state.db;
    let q = |sql: &'static str| async move {
        sqlx::query_scalar::<_, i64>(sql)
            .fetch_one(db)
            .await
            .unwrap()
    };
    (
        q("PRAGMA page_count").await,
        q("SELECT COUNT(*) FROM plan").await,
        q("SELECT COUNT(*) FROM experiment").await,
        q("SELECT COUNT(*) FROM plan_experiment").await,
    )
}

/// Each run's id and the experiment it is matched to.
async fn matching(app: &TestApp, cid: &str) -> Vec<(String, Value)> {
    let r = app
        .call("GET", "/api/campaigns/{id}/runs", &[cid], None)
        .await;
    assert_eq!(r.status, 200, "{}", r.text);
    let mut out: Vec<(String, Value)> = r
        .json
        .as_array()
        .unwrap()
        .iter()
        .map(|r| {
            (
                r["id"].as_str().unwrap().to_string(),
                r["experiment_id"].clone(),
            )
        })
        .collect();
    out.sort_by(|a, b| a.0.cmp(&b.0));
    out
}

/// `POST /api/campaigns/{id}/plan` with an optional body of changes.
async fn replan(app: &TestApp, cid: &str, body: Option<Value>) -> Resp {
    app.call("POST", "/api/campaigns/{id}/plan", &[cid], body)
        .await
}

async fn coverage(app: &TestApp, cid: &str) -> Value {
    let r = app
        .call("GET", "/api/campaigns/{id}/coverage", &[cid], None)
        .await;
    assert_eq!(r.status, 200, "{}", r.text);
    r.json
}

#[tokio::test]
async fn ten_replans_of_an_unchanged_campaign_change_nothing() {
    let app = TestApp::new().await;
    let spec = json!({
        "name": "re-plan",
        "grid": { "unit": "kn", "speeds": [1.0, 2.0] },
        "families": ["static", "dynamic", "validation"],
        "seed": 21
    });
    // A static, dynamic and validation run at each speed, flown by the truth.
    let keep = |c: &str| {
        [
            "STA-1kn-sway+-r1",
            "STA-2kn-pitch--r1",
            "DYN-1kn-yaw-r1",
            "DYN-2kn-sway-r1",
            "VAL-r1",
        ]
        .contains(&c)
    };
    let (cid, plan, logs) = flown_logs(&app, spec, &linear_truth(), keep).await;
    assert_eq!(plan["version"], 1);
    assert_eq!(plan["created"], true);
    assert!(plan["changes"].is_null(), "a first version changes nothing");
    for (code, csv) in &logs {
        upload_planned(&app, &cid, &plan, code, csv).await;
    }
    let cov = coverage(&app, &cid).await;
    let matched = matching(&app, &cid).await;
    assert_eq!(matched.len(), 5);
    assert!(matched.iter().all(|(_, e)| e.is_string()));
    assert_eq!(cov["unassigned_runs"], json!([]));
    assert_eq!(
        cov["covered"].as_u64().unwrap()
            + cov["weak"].as_u64().unwrap()
            + cov["repeat"].as_u64().unwrap(),
        5
    );
    // As a plan stored before versioning would be (no identity, no
    // fingerprints): the first re-plan computes them from what is stored.
    for sql in [
        "UPDATE experiment SET identity = NULL, fingerprint = NULL",
        "UPDATE plan SET fingerprint = NULL",
    ] {
        sqlx::query(sql).execute(&app.state.db).await.unwrap();
    }
    let r = replan(&app, &cid, None).await;
    assert_eq!(r.status, 200, "recognised as unchanged: {}", r.text);
    let before = footprint(&app).await;

    for _ in 0..10 {
        let r = replan(&app, &cid, None).await;
        assert_eq!(r.status, 200, "identical inputs store nothing: {}", r.text);
        assert_eq!(r.json["created"], false);
        assert_eq!(r.json["version"], 1);
        assert_eq!(ids_by_code(&r.json), ids_by_code(&plan));
    }
    assert_eq!(coverage(&app, &cid).await, cov);
    assert_eq!(matching(&app, &cid).await, matched);
    assert_eq!(
        footprint(&app).await,
        before,
        "pages, plans, experiments, memberships"
    );
    let c = app.call("GET", "/api/campaigns/{id}", &[&cid], None).await;
    assert_eq!(c.json["plan_version"], 1);

    // A change that leaves every experiment as it was (the set-up time
    // between runs): a new version sharing every experiment and its runs.
    let r = replan(&app, &cid, Some(json!({ "durations": { "setup_s": 90 } }))).await;
    assert_eq!(r.status, 201, "{}", r.text);
    assert_eq!(r.json["version"], 2);
    let ch = &r.json["changes"];
    assert_eq!(ch["previous_version"], 1);
    let n = plan["experiments"].as_array().unwrap().len();
    assert_eq!(
        ch["counts"],
        json!({ "added": 0, "removed": 0, "changed": 0, "unchanged": n })
    );
    assert_eq!(ids_by_code(&r.json), ids_by_code(&plan));
    let mut cov2 = coverage(&app, &cid).await;
    assert_eq!(cov2["plan_version"], 2);
    cov2["plan_version"] = json!(1);
    assert_eq!(cov2, cov);
    assert_eq!(matching(&app, &cid).await, matched);
    let after = footprint(&app).await;
    assert_eq!((after.1, after.2, after.3), (2, before.2, 2 * before.3));
}

#[tokio::test]
async fn one_changed_grid_speed_changes_only_its_experiments() {
    let app = TestApp::new().await;
    let spec = json!({
        "name": "grid change",
        "grid": { "unit": "kn", "speeds": [1.0, 2.0] },
        "families": ["static", "dynamic", "validation"],
        "seed": 4
    });
    let (cid, plan, _) = flown_logs(&app, spec, &linear_truth(), |_| false).await;
    let v1 = ids_by_code(&plan);
    let id_of = |code: &str| v1.iter().find(|(c, _)| c == code).unwrap().1.clone();
    let upload = |code: &'static str| {
        let app = &app;
        let cid = &cid;
        let eid = id_of(code);
        async move {
            let meta = json!({ "experiment_id": eid, "name": code }).to_string();
            let r = app
                .upload_run(
                    cid,
                    &[("meta", None, &meta), ("file", Some("run.csv"), &rov_log())],
                )
                .await;
            assert_eq!(r.status, 201, "{}", r.text);
            r.json["id"].as_str().unwrap().to_string()
        }
    };
    let kept_run = upload("DYN-1kn-sway-r1").await;
    let lost_run = upload("DYN-2kn-sway-r1").await;
    let (_, _, experiments_before, _) = footprint(&app).await;

    // 2 kn → 2.5 kn: the 2 kn experiments go, 2.5 kn ones come, the
    // validation run (a staircase over the grid) changes, 1 kn stays.
    let r = replan(
        &app,
        &cid,
        Some(json!({ "grid": { "unit": "kn", "speeds": [1.0, 2.5] } })),
    )
    .await;
    assert_eq!(r.status, 201, "{}", r.text);
    assert_eq!(r.json["version"], 2);
    let ch = &r.json["changes"];
    let at = |prefix: &str| v1.iter().filter(|(c, _)| c.contains(prefix)).count();
    let (one, two) = (at("-1kn-"), at("-2kn-"));
    assert_eq!(one, two);
    assert_eq!(
        ch["counts"],
        json!({ "added": two, "removed": two, "changed": 1, "unchanged": one })
    );
    let codes = |k: &str| -> Vec<String> {
        ch[k]
            .as_array()
            .unwrap()
            .iter()
            .map(|e| e["code"].as_str().unwrap().to_string())
            .collect()
    };
    assert!(codes("removed").iter().all(|c| c.contains("-2kn-")));
    assert!(codes("added").iter().all(|c| c.contains("-2.5kn-")));
    assert_eq!(codes("changed"), ["VAL-r1"]);
    assert_eq!(ch["changed"][0]["replaces"], json!(id_of("VAL-r1")));
    let v2 = ids_by_code(&r.json);
    for (code, id) in v1.iter().filter(|(c, _)| c.contains("-1kn-")) {
        assert!(
            v2.contains(&(code.clone(), id.clone())),
            "{code} keeps its id"
        );
        assert!(ch["unchanged"].as_array().unwrap().contains(&json!(id)));
    }
    assert_eq!(
        ch["unmatched_runs"],
        json!([{
            "run_id": lost_run, "name": "DYN-2kn-sway-r1",
            "experiment_id": id_of("DYN-2kn-sway-r1"), "code": "DYN-2kn-sway-r1",
            "reason": "removed"
        }])
    );
    let cov = coverage(&app, &cid).await;
    assert_eq!(cov["unassigned_runs"], json!([lost_run]));
    let kept = cov["experiments"]
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["code"] == "DYN-1kn-sway-r1")
        .unwrap();
    assert_eq!(kept["runs"][0]["run_id"], json!(kept_run));
    assert_ne!(kept["status"], "missing");
    let (_, plans, experiments, _) = footprint(&app).await;
    assert_eq!(
        (plans, experiments),
        (2, experiments_before + two as i64 + 1)
    );
    let c = app.call("GET", "/api/campaigns/{id}", &[&cid], None).await;
    assert_eq!(c.json["spec"]["grid"]["speeds"], json!([1.0, 2.5]));

    // A longer dynamic run: same identities, new schedules — changed, with
    // the run flown for the old one reported and its replacement named.
    let r = replan(
        &app,
        &cid,
        Some(json!({ "durations": { "dynamic_s": 60 } })),
    )
    .await;
    assert_eq!(r.status, 201, "{}", r.text);
    let ch = &r.json["changes"];
    assert_eq!(ch["previous_version"], 2);
    assert_eq!(ch["counts"]["added"], 0);
    assert_eq!(ch["counts"]["removed"], 0);
    assert!(
        codes_of(&ch["changed"])
            .iter()
            .all(|c| c.starts_with("DYN-"))
    );
    assert_eq!(ch["unmatched_runs"][0]["run_id"], json!(kept_run));
    assert_eq!(ch["unmatched_runs"][0]["reason"], "changed");
    let new_id = ids_by_code(&r.json)
        .into_iter()
        .find(|(c, _)| c == "DYN-1kn-sway-r1")
        .unwrap()
        .1;
    assert_eq!(ch["unmatched_runs"][0]["replaced_by"], json!(new_id));

    // Back to the 30 s dynamic runs: the rows of version 2 come back with
    // their ids, so the run is matched again and nothing new is stored.
    let (_, _, experiments_before, _) = footprint(&app).await;
    let r = replan(
        &app,
        &cid,
        Some(json!({ "durations": { "dynamic_s": 30 } })),
    )
    .await;
    assert_eq!(r.status, 201, "{}", r.text);
    assert_eq!(r.json["version"], 4);
    assert_eq!(footprint(&app).await.2, experiments_before);
    assert!(
        ids_by_code(&r.json).contains(&("DYN-1kn-sway-r1".to_string(), id_of("DYN-1kn-sway-r1")))
    );
    let cov = coverage(&app, &cid).await;
    assert_eq!(cov["unassigned_runs"], json!([lost_run]));

    // A bad change is refused naming the field, and nothing is stored.
    let r = replan(
        &app,
        &cid,
        Some(json!({ "grid": { "unit": "kn", "speeds": [1.0, 9.0] } })),
    )
    .await;
    assert_eq!(r.status, 422, "{}", r.text);
    assert!(
        r.json["field"].as_str().unwrap().starts_with("grid"),
        "{}",
        r.text
    );
    let r = replan(&app, &cid, Some(json!({ "speeds": [1.0] }))).await;
    assert_eq!(r.status, 400, "{}", r.text);
    let c = app.call("GET", "/api/campaigns/{id}", &[&cid], None).await;
    assert_eq!(c.json["plan_version"], 4);
}

fn codes_of(list: &Value) -> Vec<String> {
    list.as_array()
        .unwrap()
        .iter()
        .map(|e| e["code"].as_str().unwrap().to_string())
        .collect()
}
