//! Accounts and roles (issue 17): with credentials required, every route's
//! role — read from the generated OpenAPI document, so none is missed — is
//! enforced before anything else is looked at (403 before 404 or 422), no
//! credentials get 401, and every write is in the audit trail. Local mode
//! (requests without credentials act as the local admin) is what every
//! other API test runs in. Secrets and cookies: `api_auth_secrets.rs`.

mod common;

use common::auth::{ADMIN_PASSWORD, Caller, everyone, login, required_app, token_of};
use common::{TestApp, rov_log, rov_profile};
use serde_json::json;

/// An id no row has: routes with `{id}` must still answer 401/403 first.
const DUMMY: &str = "00000000-0000-7000-8000-000000000000";

/// Every operation of the spec: (method, template, required role).
fn operations(app: &TestApp) -> Vec<(String, String, String)> {
    let mut ops = Vec::new();
    for (path, item) in app.spec["paths"].as_object().unwrap() {
        for (method, op) in item.as_object().unwrap() {
            let role = op["x-required-role"]
                .as_str()
                .unwrap_or_else(|| panic!("{method} {path} has no x-required-role"));
            ops.push((method.to_uppercase(), path.clone(), role.to_string()));
        }
    }
    ops
}

fn rank(role: &str) -> usize {
    ["public", "viewer", "supervisor", "engineer", "admin"]
        .iter()
        .position(|r| *r == role)
        .unwrap_or_else(|| panic!("unknown role {role}"))
}

/// The template with every parameter set to [`DUMMY`].
fn dummy_path(template: &str) -> String {
    let segs: Vec<&str> = template
        .split('/')
        .map(|seg| if seg.starts_with('{') { DUMMY } else { seg })
        .collect();
    segs.join("/")
}

/// A body the route would refuse (400/415/422) if it got that far.
fn body_for(method: &str) -> Option<serde_json::Value> {
    matches!(method, "POST" | "PUT" | "PATCH").then(|| json!({}))
}

#[tokio::test]
async fn each_role_gets_403_on_every_route_above_it_before_404_or_422() {
    let app = required_app().await;
    let (admin, others) = everyone(&app).await;
    let ops = operations(&app);
    let writes: Vec<_> = ops.iter().filter(|(m, _, _)| m != "GET").collect();
    assert!(writes.len() >= 20, "{writes:?}");
    // The only writes a viewer may make: signing in and out, its own
    // password and tokens.
    let mut open: Vec<String> = writes
        .iter()
        .filter(|(_, _, r)| rank(r) <= rank("viewer"))
        .map(|(m, p, _)| format!("{m} {p}"))
        .collect();
    open.sort();
    let expected = [
        "DELETE /api/auth/tokens/{id}",
        "POST /api/auth/login",
        "POST /api/auth/logout",
        "POST /api/auth/password",
        "POST /api/auth/tokens",
    ];
    assert_eq!(open, expected);
    let mut refused = 0;
    for (role, token) in others.iter().chain([&("admin", admin.clone())]) {
        let caller = Caller::bearer(&app, token);
        for (method, template, needed) in &ops {
            let r = caller
                .exchange(method, &dummy_path(template), body_for(method))
                .await;
            let what = format!("{role}: {method} {template}: {} {}", r.status, r.text);
            if rank(role) < rank(needed) {
                app.check_contract(method, template, &r);
                assert_eq!(r.status, 403, "{what}");
                assert_eq!(r.json["field"], "role", "{what}");
                assert!(
                    r.json["message"]
                        .as_str()
                        .unwrap()
                        .contains(needed.as_str())
                );
                refused += 1;
            } else {
                assert!(r.status != 401 && r.status != 403, "{what}");
            }
        }
    }
    // The viewer alone is refused every write above it.
    assert!(refused >= 16 + 6 + 3, "{refused}");
}

#[tokio::test]
async fn without_credentials_everything_but_health_and_sign_in_is_401() {
    let app = required_app().await;
    let nobody = Caller::anonymous(&app);
    for (method, template, needed) in operations(&app) {
        let r = nobody
            .exchange(&method, &dummy_path(&template), body_for(&method))
            .await;
        if needed == "public" {
            assert_ne!(r.status, 401, "{method} {template}");
        } else {
            app.check_contract(&method, &template, &r);
            assert_eq!(r.status, 401, "{method} {template}: {}", r.text);
            assert_eq!(r.headers["www-authenticate"], "Bearer realm=\"seatrial\"");
        }
    }
    let r = nobody.send("GET", "/api/health", &[], None).await;
    assert_eq!(r.status, 200);
    // A wrong password, an unknown name and a bad token are 401 too.
    for (name, pw) in [("admin", "wrong-password"), ("nobody", ADMIN_PASSWORD)] {
        let body = json!({ "name": name, "password": pw });
        let r = nobody
            .send("POST", "/api/auth/login", &[], Some(body))
            .await;
        assert_eq!(r.status, 401, "{}", r.text);
        assert!(r.headers.get("set-cookie").is_none());
    }
    let r = Caller::bearer(&app, "st_0000")
        .send("GET", "/api/vessels", &[], None)
        .await;
    assert_eq!(r.status, 401);
}

#[tokio::test]
async fn a_supervisor_plans_and_uploads_an_engineer_deletes_models_all_audited() {
    let app = required_app().await;
    let (_, others) = everyone(&app).await;
    let sup = Caller::bearer(&app, token_of(&others, "supervisor"));
    let eng = Caller::bearer(&app, token_of(&others, "engineer"));
    // Vessel profiles are an engineer's settings.
    let r = sup
        .send("POST", "/api/vessels", &[], Some(rov_profile()))
        .await;
    assert_eq!(r.status, 403, "{}", r.text);
    let r = eng
        .send("POST", "/api/vessels", &[], Some(rov_profile()))
        .await;
    assert_eq!(r.status, 201, "{}", r.text);
    let vid = r.json["id"].as_str().unwrap().to_string();
    let body = json!({ "vessel_id": vid, "name": "auth", "grid": { "unit": "kn", "speeds": [1.0] },
                       "families": ["dynamic"], "seed": 5 });
    let r = sup.send("POST", "/api/campaigns", &[], Some(body)).await;
    assert_eq!(r.status, 201, "{}", r.text);
    let cid = r.json["id"].as_str().unwrap().to_string();
    let r = sup
        .send("POST", "/api/campaigns/{id}/plan", &[&cid], None)
        .await;
    assert_eq!(r.status, 201, "{}", r.text);
    let (ct, multipart) = common::sim::multipart(&[("file", Some("run.csv"), &rov_log())]);
    let mut headers = vec![common::auth::HOST];
    headers.extend(sup.headers.iter().map(|(k, v)| (k.as_str(), v.as_str())));
    let path = format!("/api/campaigns/{cid}/runs");
    let r = app
        .raw_with("POST", &path, &headers, Some((&ct, multipart)))
        .await;
    assert_eq!(r.status, 201, "{}", r.text);
    let rid = r.json["id"].as_str().unwrap().to_string();
    let mid = common::stored_model(&app, &cid, &vid, None, &[&rid]).await;
    let r = sup.send("DELETE", "/api/models/{id}", &[&mid], None).await;
    assert_eq!(r.status, 403, "{}", r.text);
    let r = eng.send("DELETE", "/api/models/{id}", &[&mid], None).await;
    assert_eq!(r.status, 200, "{}", r.text);
    // Soft deletes name who deleted; restoring needs the same role.
    let r = eng.send("GET", "/api/models/{id}", &[&mid], None).await;
    assert_eq!(r.json["model"]["deleted_by"], "engineer", "{}", r.text);
    let r = sup
        .send("POST", "/api/models/{id}/restore", &[&mid], None)
        .await;
    assert_eq!(r.status, 403, "{}", r.text);
    let r = sup
        .send(
            "DELETE",
            "/api/runs/{id}?reason=wrong%20vessel",
            &[&rid],
            None,
        )
        .await;
    assert_eq!(
        (r.status.as_u16(), r.json["run"]["deleted_by"].as_str()),
        (200, Some("supervisor")),
        "{}",
        r.text
    );

    // The audit trail names who did each write, and what it touched.
    let (_, cookie) = login(&app, "admin", ADMIN_PASSWORD).await;
    let admin = Caller::session(&app, &cookie);
    let r = admin.send("GET", "/api/audit?limit=50", &[], None).await;
    assert_eq!(r.status, 200, "{}", r.text);
    let entries = r.json.as_array().unwrap();
    let find = |method: &str, route: &str, status: i64| {
        let e = entries
            .iter()
            .find(|e| e["method"] == method && e["route"] == route && e["status"] == status);
        e.unwrap_or_else(|| panic!("no audit entry {method} {route} {status}: {entries:#?}"))
    };
    let who = |e: &serde_json::Value| {
        let s = |k: &str| e[k].as_str().map(String::from);
        (s("user_name"), s("via"), s("target_id"))
    };
    let named = |n: &str, via: &str, target: &str| {
        (
            Some(n.to_string()),
            Some(via.to_string()),
            Some(target.to_string()),
        )
    };
    let e = find("POST", "/api/campaigns", 201);
    assert_eq!(who(e), named("supervisor", "token", &cid));
    assert!(e["user_id"].is_string() && e["at"].is_string());
    let e = find("POST", "/api/campaigns/{id}/runs", 201);
    assert_eq!(who(e), named("supervisor", "token", &cid));
    let e = find("DELETE", "/api/models/{id}", 403);
    assert_eq!(who(e), named("supervisor", "token", &mid));
    let e = find("DELETE", "/api/models/{id}", 200);
    assert_eq!(who(e), named("engineer", "token", &mid));
    let e = find("POST", "/api/vessels", 201);
    assert_eq!(who(e), named("engineer", "token", &vid));
    let e = find("POST", "/api/auth/login", 200);
    assert_eq!(
        (e["user_name"].as_str(), e["via"].as_str()),
        (Some("admin"), Some("login"))
    );
    // Paged like the other lists.
    let total: usize = r.headers["x-total-count"]
        .to_str()
        .unwrap()
        .parse()
        .unwrap();
    assert!(total >= entries.len() && entries.len() >= 10, "{total}");
    let r = admin
        .send("GET", "/api/audit?limit=1&offset=1", &[], None)
        .await;
    assert_eq!(r.json.as_array().unwrap().len(), 1);
    assert_eq!(r.json[0]["id"], entries[1]["id"]);
    // Reads are not audited.
    assert!(entries.iter().all(|e| e["method"] != "GET"));
}

#[tokio::test]
async fn local_mode_acts_as_the_local_admin_and_auth_is_required_off_loopback() {
    let app = TestApp::new().await;
    let local = Caller::anonymous(&app);
    let r = local.send("GET", "/api/auth/me", &[], None).await;
    let me = json!({ "user_id": null, "name": "local", "role": "admin", "via": "local",
                     "auth_required": false });
    assert_eq!(r.json, me);
    let r = local
        .send("POST", "/api/vessels", &[], Some(rov_profile()))
        .await;
    assert_eq!(r.status, 201);
    let r = local.send("GET", "/api/audit", &[], None).await;
    let e = &r.json[0];
    assert_eq!(
        (e["user_name"].as_str(), e["via"].as_str()),
        (Some("local"), Some("local"))
    );
    use seatrial::http::auth::AuthConfig;
    let required =
        |listen: &str, flag: bool| AuthConfig::for_listen(flag, listen.parse().unwrap()).required;
    assert!(!required("127.0.0.1:8080", false));
    assert!(!required("[::1]:8080", false));
    assert!(required("0.0.0.0:8080", false));
    assert!(required("10.0.0.5:8080", false));
    assert!(required("127.0.0.1:8080", true));
    // The first admin is made once, with a random password when none is given.
    let boot = || seatrial::http::auth::users::bootstrap_admin(&app.state.db, None);
    assert_eq!(boot().await.unwrap().unwrap().len(), 20);
    assert!(boot().await.unwrap().is_none());
}
