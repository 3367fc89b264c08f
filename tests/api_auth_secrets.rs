//! Accounts (issue 17): passwords stored as argon2id PHC strings, tokens and
//! sessions as SHA-256, tokens revocable and never above their owner's role,
//! the session cookie HttpOnly and SameSite=Strict, cookie writes guarded
//! against cross-site requests.

mod common;

use common::auth::{ADMIN_PASSWORD, Caller, everyone, login, required_app, token_of};
use common::rov_profile;
use serde_json::json;

#[tokio::test]
async fn secrets_are_stored_hashed() {
    let app = required_app().await;
    let (_, others) = everyone(&app).await;
    let db = &app.state.db;
    let users: Vec<(String, String)> = sqlx::query_as("SELECT name, password_hash FROM app_user")
        .fetch_all(db)
        .await
        .unwrap();
    assert_eq!(users.len(), 4);
    for (name, hash) in &users {
        assert!(hash.starts_with("$argon2id$v=19$m="), "{name}: {hash}");
        assert!(!hash.contains("password"), "{name}: {hash}");
    }
    let tokens: Vec<(String, String)> = sqlx::query_as("SELECT token_hash, prefix FROM api_token")
        .fetch_all(db)
        .await
        .unwrap();
    assert_eq!(tokens.len(), 4);
    let secret = token_of(&others, "viewer");
    assert!(
        tokens
            .iter()
            .all(|(h, _)| h.len() == 64 && !h.contains(secret))
    );
    let hashed = seatrial::http::auth::secrets::token_hash(secret);
    assert!(
        tokens
            .iter()
            .any(|(h, p)| *h == hashed && secret.starts_with(p.as_str()))
    );
    let sessions: Vec<(String,)> = sqlx::query_as("SELECT token_hash FROM session")
        .fetch_all(db)
        .await
        .unwrap();
    assert!(!sessions.is_empty() && sessions.iter().all(|(h,)| h.len() == 64));
}

#[tokio::test]
async fn tokens_are_revocable_and_follow_their_users_role() {
    let app = required_app().await;
    let (admin, others) = everyone(&app).await;
    let admin = Caller::bearer(&app, &admin);
    let secret = token_of(&others, "viewer");
    let viewer = Caller::bearer(&app, secret);
    // The viewer reads with its token, lists it (never the secret), revokes it: then 401.
    let r = viewer.send("GET", "/api/vessels", &[], None).await;
    assert_eq!(r.status, 200);
    let r = viewer.send("GET", "/api/auth/tokens", &[], None).await;
    assert_eq!(r.json.as_array().unwrap().len(), 1, "{}", r.text);
    assert!(!r.text.contains(secret));
    let tid = r.json[0]["id"].as_str().unwrap().to_string();
    // A token above its owner's role is refused; so is another user's token.
    let body = json!({ "name": "x", "role": "admin" });
    let r = viewer
        .send("POST", "/api/auth/tokens", &[], Some(body))
        .await;
    assert_eq!(
        (r.status.as_u16(), r.json["field"].as_str()),
        (422, Some("role"))
    );
    let r = admin
        .send("GET", "/api/auth/tokens?all=true", &[], None)
        .await;
    assert_eq!(r.json.as_array().unwrap().len(), 4, "{}", r.text);
    let other = r.json[0]["id"].as_str().unwrap().to_string();
    let r = viewer
        .send("DELETE", "/api/auth/tokens/{id}", &[&other], None)
        .await;
    assert_eq!(r.status, 404, "{}", r.text);
    let r = viewer
        .send("DELETE", "/api/auth/tokens/{id}", &[&tid], None)
        .await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert!(r.json["revoked_at"].is_string());
    let r = viewer.send("GET", "/api/vessels", &[], None).await;
    assert_eq!(r.status, 401, "{}", r.text);

    // Demoting a user demotes its tokens; disabling it refuses them and its sign-in.
    let eng = Caller::bearer(&app, token_of(&others, "engineer"));
    let users = admin.send("GET", "/api/users", &[], None).await;
    assert_eq!(users.headers["x-total-count"], "4");
    let list = users.json.as_array().unwrap();
    let eid = list.iter().find(|u| u["name"] == "engineer").unwrap()["id"]
        .as_str()
        .unwrap();
    let body = json!({ "role": "viewer" });
    let r = admin
        .send("PATCH", "/api/users/{id}", &[eid], Some(body))
        .await;
    assert_eq!(r.json["role"], "viewer", "{}", r.text);
    let r = eng
        .send("PATCH", "/api/models/{id}", &[eid], Some(json!({})))
        .await;
    assert_eq!(r.status, 403, "{}", r.text);
    let body = json!({ "disabled": true });
    let r = admin
        .send("PATCH", "/api/users/{id}", &[eid], Some(body))
        .await;
    assert_eq!(r.json["disabled"], true, "{}", r.text);
    let r = eng.send("GET", "/api/vessels", &[], None).await;
    assert_eq!(r.status, 401);
    let body = json!({ "name": "engineer", "password": "engineer-password" });
    let r = Caller::anonymous(&app)
        .send("POST", "/api/auth/login", &[], Some(body))
        .await;
    assert_eq!(r.status, 401);
    // The last enabled admin stays one; a taken name is a conflict.
    let me = admin.send("GET", "/api/auth/me", &[], None).await;
    let aid = me.json["user_id"].as_str().unwrap();
    let body = json!({ "role": "engineer" });
    let r = admin
        .send("PATCH", "/api/users/{id}", &[aid], Some(body))
        .await;
    assert_eq!(r.status, 409, "{}", r.text);
    let body = json!({ "name": "viewer", "role": "viewer", "password": "12345678" });
    let r = admin.send("POST", "/api/users", &[], Some(body)).await;
    assert_eq!(r.status, 409, "{}", r.text);
}

#[tokio::test]
async fn the_session_cookie_is_strict_and_cookie_writes_need_the_csrf_header() {
    let app = required_app().await;
    let (set, value) = login(&app, "admin", ADMIN_PASSWORD).await;
    for flag in ["HttpOnly", "SameSite=Strict", "Path=/", "Max-Age=43200"] {
        assert!(set.contains(flag), "{set}");
    }
    assert!(!set.contains("Secure"), "{set}");
    let session = Caller::session(&app, &value);
    let me = session.send("GET", "/api/auth/me", &[], None).await;
    let got = |k: &str| me.json[k].as_str().map(String::from);
    assert_eq!(
        (got("name"), got("role"), got("via")),
        (
            Some("admin".into()),
            Some("admin".into()),
            Some("session".into())
        )
    );
    assert_eq!(me.json["auth_required"], true);
    // A cookie write without the header, or from another origin: 403, nothing created.
    let bare = Caller::anonymous(&app).with("cookie", &format!("seatrial_session={value}"));
    let r = bare
        .send("POST", "/api/vessels", &[], Some(rov_profile()))
        .await;
    assert_eq!(
        (r.status.as_u16(), r.json["field"].as_str()),
        (403, Some("X-Seatrial-CSRF"))
    );
    let evil = Caller::session(&app, &value).with("origin", "http://evil.example");
    let r = evil
        .send("POST", "/api/vessels", &[], Some(rov_profile()))
        .await;
    assert_eq!(
        (r.status.as_u16(), r.json["field"].as_str()),
        (403, Some("Origin"))
    );
    let cross = Caller::session(&app, &value).with("sec-fetch-site", "cross-site");
    let r = cross
        .send("POST", "/api/vessels", &[], Some(rov_profile()))
        .await;
    assert_eq!(r.status, 403);
    let r = bare.send("GET", "/api/vessels", &[], None).await;
    assert_eq!(r.json, json!([]));
    // The same write from this origin with the header goes through.
    let own = Caller::session(&app, &value).with("origin", "http://127.0.0.1:8080");
    let r = own
        .send("POST", "/api/vessels", &[], Some(rov_profile()))
        .await;
    assert_eq!(r.status, 201, "{}", r.text);
    // Sign out: the cookie is cleared and the session is gone.
    let r = session.send("POST", "/api/auth/logout", &[], None).await;
    assert_eq!(r.status, 204);
    assert!(
        r.headers["set-cookie"]
            .to_str()
            .unwrap()
            .contains("Max-Age=0")
    );
    let r = session.send("GET", "/api/auth/me", &[], None).await;
    assert_eq!(r.status, 401);
}

#[tokio::test]
async fn a_password_change_ends_the_sessions() {
    let app = required_app().await;
    let (_, value) = login(&app, "admin", ADMIN_PASSWORD).await;
    let session = Caller::session(&app, &value);
    let body = json!({ "current_password": "nope-nope", "new_password": "another-password" });
    let r = session
        .send("POST", "/api/auth/password", &[], Some(body))
        .await;
    assert_eq!(
        (r.status.as_u16(), r.json["field"].as_str()),
        (422, Some("current_password"))
    );
    let body = json!({ "current_password": ADMIN_PASSWORD, "new_password": "short" });
    let r = session
        .send("POST", "/api/auth/password", &[], Some(body))
        .await;
    assert_eq!(
        (r.status.as_u16(), r.json["field"].as_str()),
        (422, Some("new_password"))
    );
    let body = json!({ "current_password": ADMIN_PASSWORD, "new_password": "another-password" });
    let r = session
        .send("POST", "/api/auth/password", &[], Some(body))
        .await;
    assert_eq!(r.status, 204, "{}", r.text);
    let r = session.send("GET", "/api/auth/me", &[], None).await;
    assert_eq!(r.status, 401);
    login(&app, "admin", "another-password").await;
}

#[tokio::test]
async fn wrong_passwords_back_off_per_name_with_retry_after() {
    let app = required_app().await;
    let anyone = Caller::anonymous(&app);
    let attempt = |name: &'static str, password: &'static str| {
        let body = json!({ "name": name, "password": password });
        anyone.send("POST", "/api/auth/login", &[], Some(body))
    };
    for i in 0..5 {
        let r = attempt("admin", "guess-guess").await;
        assert_eq!(r.status, 401, "attempt {i}: {}", r.text);
    }
    // The sixth attempt waits, even with the right password, and is not
    // checked; the answer says how long.
    let r = attempt("admin", ADMIN_PASSWORD).await;
    assert_eq!(r.status, 429, "{}", r.text);
    assert_eq!(r.headers["retry-after"], "1");
    let message = r.json["message"].as_str().unwrap();
    assert!(
        message.contains("5 failed sign-ins for 'admin'"),
        "{message}"
    );
    // Names that do not exist back off alike (answers do not reveal which
    // exist); other names are not affected.
    for _ in 0..5 {
        assert_eq!(attempt("nobody", "x").await.status, 401);
    }
    assert_eq!(attempt("nobody", "x").await.status, 429);
    tokio::time::sleep(std::time::Duration::from_millis(1100)).await;
    let r = attempt("admin", ADMIN_PASSWORD).await;
    assert_eq!(r.status, 200, "after the wait: {}", r.text);
    // The success cleared the name: wrong passwords are free again.
    assert_eq!(attempt("admin", "guess-guess").await.status, 401);
    assert_eq!(attempt("admin", "guess-guess").await.status, 401);
}
