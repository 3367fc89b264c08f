//! Deleting vessels and campaigns (soft, with undo) and purging deleted runs
//! for good (issue 16).

mod common;

use common::{Resp, TestApp, rov_profile, sim};
use serde_json::json;

/// A vessel named `name` with one campaign; their ids.
async fn vessel_and_campaign(app: &TestApp, name: &str) -> (String, String) {
    let mut profile = rov_profile();
    profile["name"] = json!(name);
    let r = app.call("POST", "/api/vessels", &[], Some(profile)).await;
    assert_eq!(r.status, 201, "{}", r.text);
    let vid = id(&r);
    let r = app
        .call(
            "POST",
            "/api/campaigns",
            &[],
            Some(json!({
                "vessel_id": vid, "name": format!("{name} trials"), "seed": 3,
                "grid": { "unit": "kn", "speeds": [1.0] }, "families": ["dynamic"]
            })),
        )
        .await;
    assert_eq!(r.status, 201, "{}", r.text);
    (vid, id(&r))
}

fn id(r: &Resp) -> String {
    r.json["id"].as_str().unwrap().to_string()
}

/// The ids of a list answer.
fn ids(r: &Resp) -> Vec<String> {
    assert_eq!(r.status, 200, "{}", r.text);
    r.json
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x["id"].as_str().unwrap().to_string())
        .collect()
}

/// A run uploaded into campaign `cid` as `name`; its id.
async fn run(app: &TestApp, cid: &str, name: &str) -> String {
    run_from(app, cid, name, 7).await
}

/// A run of simulation `seed` uploaded into campaign `cid` as `name`; its id.
async fn run_from(app: &TestApp, cid: &str, name: &str, seed: u64) -> String {
    let csv = sim::csv(
        &sim::simulate(seed, 10.0, 300.0, [300.0; 6], 2.0, 1e-4),
        &sim::all_columns(),
        0.0,
        1,
    );
    let meta = json!({ "name": name }).to_string();
    let r = app
        .upload_run(
            cid,
            &[("meta", None, &meta), ("file", Some("log.csv"), &csv)],
        )
        .await;
    assert_eq!(r.status, 201, "{}", r.text);
    id(&r)
}

/// Sends `method template` for `id` and asserts the answer's `status`.
async fn expect(app: &TestApp, method: &str, template: &str, id: &str, status: u16) -> Resp {
    let r = app.call(method, template, &[id], None).await;
    assert_eq!(r.status, status, "{method} {template}: {}", r.text);
    r
}

/// Asserts a 409 whose message holds every one of `names`.
fn conflict_naming(r: &Resp, names: &[&str]) {
    assert_eq!(r.status, 409, "{}", r.text);
    let msg = r.json["message"].as_str().unwrap();
    for n in names {
        assert!(msg.contains(n), "{n} not in: {msg}");
    }
}

#[tokio::test]
async fn campaigns_are_deleted_and_restored_keeping_their_runs_and_models_readable() {
    // A job kind to submit (no worker: nothing runs).
    let app = TestApp::with_jobs(common::jobs::registry(), common::jobs::config(0)).await;
    let (vid, cid) = vessel_and_campaign(&app, "Surveyor").await;
    let (_, other) = vessel_and_campaign(&app, "Otter").await;
    let rid = run(&app, &cid, "dive 1").await;
    let mid = common::stored_model(&app, &cid, &vid, None, &[&rid]).await;

    let r = app
        .call(
            "DELETE",
            "/api/campaigns/{id}?reason=wrong%20grid",
            &[&cid],
            None,
        )
        .await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert_eq!(r.json["delete_reason"], "wrong grid", "{}", r.text);
    assert_eq!(r.json["deleted_by"], "local", "{}", r.text);
    // Out of the lists, in the deleted list, readable by id with its runs and models.
    let r = app.call("GET", "/api/campaigns", &[], None).await;
    assert_eq!(ids(&r), vec![other.clone()]);
    assert_eq!(r.headers["x-total-count"], "1");
    let r = app
        .call("GET", "/api/campaigns?deleted=true", &[], None)
        .await;
    assert_eq!(ids(&r), vec![cid.clone()]);
    let r = app.call("GET", "/api/campaigns/{id}", &[&cid], None).await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert!(r.json["deleted_at"].is_string(), "{}", r.text);
    for (path, id) in [("/api/runs/{id}", &rid), ("/api/models/{id}", &mid)] {
        let r = app.call("GET", path, &[id], None).await;
        assert_eq!(r.status, 200, "{path}: {}", r.text);
    }
    let m = app.call("GET", "/api/models/{id}", &[&mid], None).await;
    assert!(
        m.text.contains(&rid),
        "provenance names the run: {}",
        m.text
    );
    // The models list leaves its models out, as it does the campaign; the
    // campaign's own list still has them.
    let r = app.call("GET", "/api/models", &[], None).await;
    assert!(!r.text.contains(&mid), "{}", r.text);
    assert_eq!(r.headers["x-total-count"], "0");
    let r = app
        .call("GET", "/api/models?campaign_id={id}", &[&cid], None)
        .await;
    assert!(r.text.contains(&mid), "{}", r.text);
    // A second delete is a 404; nothing new goes under it (409 naming it).
    let r = app
        .call("DELETE", "/api/campaigns/{id}", &[&cid], None)
        .await;
    assert_eq!(r.status, 404, "{}", r.text);
    let r = app
        .call("POST", "/api/campaigns/{id}/plan", &[&cid], None)
        .await;
    conflict_naming(&r, &["Surveyor trials", &cid]);
    let r = app
        .call(
            "POST",
            "/api/jobs",
            &[],
            Some(json!({ "kind": "sum", "campaign_id": cid, "settings": {} })),
        )
        .await;
    conflict_naming(&r, &["Surveyor trials", &cid]);
    // A deleted run or model under it is not restored before the campaign.
    expect(&app, "DELETE", "/api/runs/{id}", &rid, 200).await;
    let r = app
        .call("POST", "/api/runs/{id}/restore", &[&rid], None)
        .await;
    conflict_naming(&r, &["dive 1", &rid, "campaign 'Surveyor trials'", &cid]);
    // The audit trail keeps the reason.
    let r = app.call("GET", "/api/audit", &[], None).await;
    let entry = r
        .json
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["method"] == "DELETE" && e["target_id"] == cid.as_str() && e["status"] == 200)
        .unwrap_or_else(|| panic!("no audit row: {}", r.text))
        .clone();
    assert_eq!(entry["note"], "wrong grid", "{entry}");
    // Restore: back in the lists; then the run can be restored too.
    let r = app
        .call("POST", "/api/campaigns/{id}/restore", &[&cid], None)
        .await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert!(r.json["deleted_at"].is_null(), "{}", r.text);
    let r = app.call("GET", "/api/campaigns", &[], None).await;
    assert_eq!(ids(&r), vec![cid.clone(), other.clone()]);
    let r = app.call("GET", "/api/models", &[], None).await;
    assert!(r.text.contains(&mid), "{}", r.text);
    let r = app
        .call("POST", "/api/campaigns/{id}/restore", &[&cid], None)
        .await;
    conflict_naming(&r, &["Surveyor trials", &cid, "not deleted"]);
    let r = app
        .call("POST", "/api/runs/{id}/restore", &[&rid], None)
        .await;
    assert_eq!(r.status, 200, "{}", r.text);
    let r = app
        .call("POST", "/api/campaigns/{id}/restore", &["nope"], None)
        .await;
    assert_eq!(r.status, 404, "{}", r.text);
}

#[tokio::test]
async fn deleting_a_vessel_hides_its_campaigns_and_guards_restores_under_it() {
    let app = TestApp::new().await;
    let (vid, cid) = vessel_and_campaign(&app, "Surveyor").await;
    let (other_v, other_c) = vessel_and_campaign(&app, "Otter").await;
    let rid = run(&app, &cid, "dive 1").await;
    let mid = common::stored_model(&app, &cid, &vid, None, &[&rid]).await;
    // Delete the campaign, then the vessel.
    expect(&app, "DELETE", "/api/campaigns/{id}", &cid, 200).await;
    let r = app
        .call("DELETE", "/api/vessels/{id}?reason=sold", &[&vid], None)
        .await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert_eq!(r.json["delete_reason"], "sold", "{}", r.text);
    let r = app.call("GET", "/api/vessels", &[], None).await;
    assert_eq!(ids(&r), vec![other_v.clone()]);
    let r = app
        .call("GET", "/api/vessels?deleted=true", &[], None)
        .await;
    assert_eq!(ids(&r), vec![vid.clone()]);
    let r = app.call("GET", "/api/vessels/{id}", &[&vid], None).await;
    assert_eq!(r.json["delete_reason"], "sold", "{}", r.text);
    // Restoring the campaign under the deleted vessel: 409 naming the vessel.
    let r = app
        .call("POST", "/api/campaigns/{id}/restore", &[&cid], None)
        .await;
    conflict_naming(&r, &["Surveyor trials", &cid, "vessel 'Surveyor'", &vid]);
    // The model stays readable; a new campaign on the vessel is refused.
    let r = app.call("GET", "/api/models/{id}", &[&mid], None).await;
    assert_eq!(r.status, 200, "{}", r.text);
    let r = app
        .call(
            "POST",
            "/api/campaigns",
            &[],
            Some(json!({ "vessel_id": vid, "name": "again", "seed": 1,
                         "grid": { "unit": "kn", "speeds": [1.0] }, "families": ["dynamic"] })),
        )
        .await;
    conflict_naming(&r, &["vessel 'Surveyor'", &vid]);
    // Restore the vessel and the campaign: both listed again.
    let r = app
        .call("POST", "/api/vessels/{id}/restore", &[&vid], None)
        .await;
    assert_eq!(r.status, 200, "{}", r.text);
    let r = app.call("GET", "/api/campaigns", &[], None).await;
    assert_eq!(
        ids(&r),
        vec![other_c.clone()],
        "the campaign is still deleted"
    );
    let r = app
        .call("POST", "/api/campaigns/{id}/restore", &[&cid], None)
        .await;
    assert_eq!(r.status, 200, "{}", r.text);
    // A live campaign of a deleted vessel leaves the lists with it.
    expect(&app, "DELETE", "/api/vessels/{id}", &other_v, 200).await;
    let r = app.call("GET", "/api/campaigns", &[], None).await;
    assert_eq!(ids(&r), vec![cid.clone()]);
    let r = app
        .call("GET", "/api/campaigns?vessel_id={id}", &[&other_v], None)
        .await;
    assert_eq!(ids(&r), Vec::<String>::new());
}

#[tokio::test]
async fn restoring_a_model_names_it_and_its_deleted_campaign() {
    let app = TestApp::new().await;
    let (vid, cid) = vessel_and_campaign(&app, "Surveyor").await;
    let mid = common::stored_model(&app, &cid, &vid, None, &[]).await;
    let m = app.call("GET", "/api/models/{id}", &[&mid], None).await;
    let name = m.json["model"]["name"].as_str().unwrap().to_string();
    let r = app
        .call("POST", "/api/models/{id}/restore", &[&mid], None)
        .await;
    conflict_naming(&r, &[&name, &mid, "not deleted"]);
    for path in ["/api/models/{id}", "/api/campaigns/{id}"] {
        let id = if path.contains("models") { &mid } else { &cid };
        expect(&app, "DELETE", path, id, 200).await;
    }
    let r = app
        .call("POST", "/api/models/{id}/restore", &[&mid], None)
        .await;
    conflict_naming(&r, &[&name, &mid, "campaign 'Surveyor trials'", &cid]);
}

/// The stored files (SHA-256) of run `rid`.
async fn files_of(app: &TestApp, rid: &str) -> Vec<String> {
    let r = app.call("GET", "/api/runs/{id}", &[rid], None).await;
    r.json["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["sha256"].as_str().unwrap().to_string())
        .collect()
}

#[tokio::test]
async fn a_deleted_run_is_purged_with_its_files_unless_a_model_uses_it() {
    let app = TestApp::new().await;
    let (vid, cid) = vessel_and_campaign(&app, "Surveyor").await;
    let used = run(&app, &cid, "dive 1").await;
    let free = run_from(&app, &cid, "dive 2", 8).await;
    let mid = common::stored_model(&app, &cid, &vid, None, &[&used]).await;
    let shas = files_of(&app, &free).await;
    assert!(!shas.is_empty());
    for sha in &shas {
        assert!(app.state.blobs.path(sha).exists());
    }
    // A live run is not purged; a deleted run a model uses is kept, naming it
    // (the model deleted too: its provenance still names the run).
    let r = app
        .call("DELETE", "/api/runs/{id}?purge=true", &[&free], None)
        .await;
    conflict_naming(&r, &["dive 2", &free, "not deleted"]);
    for path in ["/api/runs/{id}", "/api/models/{id}"] {
        let id = if path.contains("runs") { &used } else { &mid };
        expect(&app, "DELETE", path, id, 200).await;
    }
    let model = app.call("GET", "/api/models/{id}", &[&mid], None).await;
    let model_name = model.json["model"]["name"].as_str().unwrap().to_string();
    let r = app
        .call("DELETE", "/api/runs/{id}?purge=true", &[&used], None)
        .await;
    conflict_naming(&r, &["dive 1", &used, &model_name, &mid]);
    expect(&app, "GET", "/api/runs/{id}", &used, 200).await;
    // Purged: row and files gone, the audit row says so.
    expect(&app, "DELETE", "/api/runs/{id}", &free, 200).await;
    let r = app
        .call(
            "DELETE",
            "/api/runs/{id}?purge=true&reason=duplicate",
            &[&free],
            None,
        )
        .await;
    assert_eq!(r.status, 204, "{}", r.text);
    expect(&app, "GET", "/api/runs/{id}", &free, 404).await;
    for sha in &shas {
        assert!(!app.state.blobs.path(sha).exists(), "{sha} still on disk");
    }
    let r = app
        .call(
            "GET",
            "/api/campaigns/{id}/runs?deleted=true",
            &[&cid],
            None,
        )
        .await;
    assert_eq!(ids(&r), vec![used.clone()]);
    let r = app.call("GET", "/api/audit", &[], None).await;
    let entry = r
        .json
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["method"] == "DELETE" && e["status"] == 204)
        .unwrap_or_else(|| panic!("no audit row: {}", r.text))
        .clone();
    let note = entry["note"].as_str().unwrap();
    assert!(
        note.contains("purged") && note.contains(&free) && note.contains("duplicate"),
        "{note}"
    );
    // The used run's files are still there.
    for sha in files_of(&app, &used).await {
        assert!(app.state.blobs.path(&sha).exists());
    }
}

#[tokio::test]
async fn shared_files_stay_and_a_file_left_by_a_crash_after_the_commit_is_swept() {
    let app = TestApp::new().await;
    let (_, cid) = vessel_and_campaign(&app, "Surveyor").await;
    // Two runs of the same bytes share one blob: purging one keeps the file.
    let a = run(&app, &cid, "dive a").await;
    let b = run(&app, &cid, "dive b").await;
    let shas = files_of(&app, &a).await;
    assert_eq!(shas, files_of(&app, &b).await);
    for r in [&a, &b] {
        expect(&app, "DELETE", "/api/runs/{id}", r, 200).await;
    }
    let r = app
        .call("DELETE", "/api/runs/{id}?purge=true", &[&a], None)
        .await;
    assert_eq!(r.status, 204, "{}", r.text);
    for sha in &shas {
        assert!(app.state.blobs.path(sha).exists(), "shared file removed");
    }
    // A crash between the purge's commit and the file removal: the rows are
    // gone, the file stays. The next start removes it before serving.
    let sha = &shas[0];
    let bytes = std::fs::read(app.state.blobs.path(sha)).unwrap();
    let r = app
        .call("DELETE", "/api/runs/{id}?purge=true", &[&b], None)
        .await;
    assert_eq!(r.status, 204, "{}", r.text);
    std::fs::write(app.state.blobs.path(sha), &bytes).unwrap();
    let debris = seatrial::intake::recover(&app.state.db, &app.state.blobs)
        .await
        .unwrap();
    assert_eq!(debris.orphan_blobs, 1);
    assert!(!app.state.blobs.path(sha).exists());
    // Files some row names are never swept.
    let c = run(&app, &cid, "dive c").await;
    seatrial::intake::recover(&app.state.db, &app.state.blobs)
        .await
        .unwrap();
    for sha in files_of(&app, &c).await {
        assert!(app.state.blobs.path(&sha).exists());
    }
}

#[tokio::test]
async fn only_an_admin_purges() {
    let app = common::auth::required_app().await;
    let (admin_token, others) = common::auth::everyone(&app).await;
    let admin = common::auth::Caller::bearer(&app, &admin_token);
    let supervisor =
        common::auth::Caller::bearer(&app, common::auth::token_of(&others, "supervisor"));
    let mut profile = rov_profile();
    profile["name"] = json!("Surveyor");
    let v = admin.send("POST", "/api/vessels", &[], Some(profile)).await;
    let c = admin
        .send(
            "POST",
            "/api/campaigns",
            &[],
            Some(json!({ "vessel_id": id(&v), "name": "t", "seed": 3,
                         "grid": { "unit": "kn", "speeds": [1.0] }, "families": ["dynamic"] })),
        )
        .await;
    let cid = id(&c);
    let (ct, body) = sim::multipart(&[("file", Some("run.csv"), &common::rov_log())]);
    let auth = format!("Bearer {admin_token}");
    let headers = [common::auth::HOST, ("authorization", auth.as_str())];
    let r = app
        .raw_with(
            "POST",
            &format!("/api/campaigns/{cid}/runs"),
            &headers,
            Some((&ct, body)),
        )
        .await;
    assert_eq!(r.status, 201, "{}", r.text);
    let rid = id(&r);
    let r = supervisor
        .send("DELETE", "/api/runs/{id}", &[&rid], None)
        .await;
    assert_eq!(r.status, 200, "a supervisor deletes: {}", r.text);
    let r = supervisor
        .send("DELETE", "/api/runs/{id}?purge=true", &[&rid], None)
        .await;
    assert_eq!(
        (r.status.as_u16(), r.json["field"].as_str()),
        (403, Some("role")),
        "{}",
        r.text
    );
    let r = admin
        .send("DELETE", "/api/runs/{id}?purge=true", &[&rid], None)
        .await;
    assert_eq!(r.status, 204, "{}", r.text);
}
