//! Accounts in tests: an app that requires credentials with its first
//! admin, and callers that send a session cookie or a bearer token.

use std::sync::Arc;

use serde_json::{Value, json};

use super::{Resp, TestApp};

pub const ADMIN_PASSWORD: &str = "admin-password-1";
/// The Host every request names (an allowed one).
pub const HOST: (&str, &str) = ("host", "127.0.0.1:8080");

/// An app that requires credentials, with its first admin (`admin`).
pub async fn required_app() -> TestApp {
    let mut app = TestApp::new().await;
    app.state.auth = Arc::new(seatrial::http::auth::AuthConfig {
        required: true,
        secure_cookie: false,
        ..Default::default()
    });
    let web = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("web");
    app.router = seatrial::http::app(app.state.clone(), web);
    let made =
        seatrial::http::auth::users::bootstrap_admin(&app.state.db, Some(ADMIN_PASSWORD.into()))
            .await
            .unwrap();
    assert_eq!(made.as_deref(), Some(ADMIN_PASSWORD));
    app
}

/// Fills a route template's parameters in order.
pub fn fill(template: &str, args: &[&str]) -> String {
    let mut path = template.to_string();
    for a in args {
        let start = path.find('{').expect("more args than parameters");
        let end = path[start..].find('}').unwrap() + start;
        path.replace_range(start..=end, a);
    }
    path
}

/// Someone sending requests with these extra headers (credentials).
pub struct Caller<'a> {
    pub app: &'a TestApp,
    pub headers: Vec<(String, String)>,
}

impl<'a> Caller<'a> {
    /// No credentials.
    pub fn anonymous(app: &'a TestApp) -> Self {
        Caller {
            app,
            headers: Vec::new(),
        }
    }

    /// `Authorization: Bearer <token>`.
    pub fn bearer(app: &'a TestApp, token: &str) -> Self {
        Self::anonymous(app).with("authorization", &format!("Bearer {token}"))
    }

    /// The session cookie, and the CSRF header the web UI sends.
    pub fn session(app: &'a TestApp, cookie: &str) -> Self {
        Self::anonymous(app)
            .with("cookie", &format!("seatrial_session={cookie}"))
            .with("x-seatrial-csrf", "1")
    }

    /// One more header.
    pub fn with(mut self, name: &str, value: &str) -> Self {
        self.headers.push((name.to_string(), value.to_string()));
        self
    }

    /// A request to `path` (a JSON body when given), unchecked.
    pub async fn exchange(&self, method: &str, path: &str, body: Option<Value>) -> Resp {
        let mut headers = vec![HOST];
        headers.extend(self.headers.iter().map(|(k, v)| (k.as_str(), v.as_str())));
        let body = body.map(|b| ("application/json", b.to_string()));
        self.app.raw_with(method, path, &headers, body).await
    }

    /// A request to `template` filled with `args` (a query string may
    /// follow the template), checked against the spec.
    pub async fn send(
        &self,
        method: &str,
        template: &str,
        args: &[&str],
        body: Option<Value>,
    ) -> Resp {
        let r = self.exchange(method, &fill(template, args), body).await;
        let operation = template.split('?').next().unwrap();
        self.app.check_contract(method, operation, &r);
        r
    }
}

/// Signs in; the `Set-Cookie` header and the session cookie's value.
pub async fn login(app: &TestApp, name: &str, password: &str) -> (String, String) {
    let body = json!({ "name": name, "password": password });
    let r = Caller::anonymous(app)
        .send("POST", "/api/auth/login", &[], Some(body))
        .await;
    assert_eq!(r.status, 200, "{}", r.text);
    let set = r.headers["set-cookie"].to_str().unwrap().to_string();
    let first = set.split(';').next().unwrap();
    let value = first.strip_prefix("seatrial_session=").unwrap().to_string();
    (set, value)
}

/// The admin (signed in, then with a token of its own), and a user with a
/// token for each other role: (role, token).
pub async fn everyone(app: &TestApp) -> (String, Vec<(&'static str, String)>) {
    let (_, cookie) = login(app, "admin", ADMIN_PASSWORD).await;
    let session = Caller::session(app, &cookie);
    let me = session.send("GET", "/api/auth/me", &[], None).await;
    let body = json!({ "name": "admin ci" });
    let r = session
        .send("POST", "/api/auth/tokens", &[], Some(body))
        .await;
    assert_eq!(r.status, 201, "{}", r.text);
    assert_eq!(r.json["user_id"], me.json["user_id"]);
    let admin_token = r.json["token"].as_str().unwrap().to_string();
    let admin = Caller::bearer(app, &admin_token);
    let mut others = Vec::new();
    for role in ["viewer", "supervisor", "engineer"] {
        let body = json!({ "name": role, "role": role, "password": format!("{role}-password") });
        let r = admin.send("POST", "/api/users", &[], Some(body)).await;
        assert_eq!(r.status, 201, "{}", r.text);
        assert_eq!(r.json["role"], role);
        let body = json!({ "name": "ci", "user_id": r.json["id"] });
        let r = admin
            .send("POST", "/api/auth/tokens", &[], Some(body))
            .await;
        assert_eq!(r.status, 201, "{}", r.text);
        let token = r.json["token"].as_str().unwrap();
        assert!(token.starts_with("st_") && token.len() == 67, "{token}");
        others.push((role, token.to_string()));
    }
    (admin_token, others)
}

/// The token of `role` among [`everyone`]'s.
pub fn token_of<'a>(others: &'a [(&str, String)], role: &str) -> &'a str {
    &others.iter().find(|(r, _)| *r == role).unwrap().1
}
