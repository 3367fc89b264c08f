//! Accounts and roles (issue 17). Who a request is: a browser session
//! (cookie), a personal API token (`Authorization: Bearer`), or — in local
//! mode only — the built-in local admin. What a route needs: [`access`],
//! one table for the guard ([`middleware`]) and the OpenAPI document
//! ([`document`]), so the two cannot disagree.
//!
//! Local mode: the service listens on a loopback address and `--auth
//! required` is not set; a request without credentials acts as the local
//! admin (the two-command demo). Anywhere else every route but health and
//! sign-in needs credentials.
//!
//! CSRF: a cookie-authenticated write must carry `X-Seatrial-CSRF: 1` (the
//! web UI always sends it). A cross-site form cannot set a header, and a
//! cross-site `fetch` with one needs a CORS preflight this service never
//! grants; the cookie is also `SameSite=Strict` and the Origin rule of
//! [`super::exposure`] applies first. Tokens are not ambient, so bearer
//! requests need no such header.

pub mod middleware;
pub mod secrets;
pub mod session;
pub mod throttle;
pub mod tokens;
pub mod users;

use axum::http::Method;
use utoipa::openapi::security::{ApiKey, ApiKeyValue, Http, HttpAuthScheme, SecurityScheme};
use utoipa::openapi::{Ref, ResponseBuilder, SecurityRequirement, extensions::Extensions};

pub use crate::storage::accounts::Role;
use crate::storage::accounts::User;

/// Name of the session cookie.
pub const SESSION_COOKIE: &str = "seatrial_session";
/// The header a cookie-authenticated write must carry (value `1`).
pub const CSRF_HEADER: &str = "x-seatrial-csrf";
/// Lifetime of a session (s): 12 hours, one working day at sea.
pub const SESSION_SECS: i64 = 12 * 3600;

/// How the service authenticates.
#[derive(Debug, Clone, Default)]
pub struct AuthConfig {
    /// Requests without credentials get 401 (false: local mode, they act
    /// as the local admin).
    pub required: bool,
    /// Mark the session cookie `Secure` (behind an https proxy).
    pub secure_cookie: bool,
    /// Back-off of failed sign-ins and the bound on password checks.
    pub throttle: std::sync::Arc<throttle::LoginThrottle>,
}

impl AuthConfig {
    /// Auth required: `--auth required`, or any listen address that is not loopback.
    pub fn for_listen(required: bool, listen: std::net::SocketAddr) -> Self {
        AuthConfig {
            required: required || !listen.ip().is_loopback(),
            secure_cookie: false,
            throttle: Default::default(),
        }
    }
}

/// How a request was authenticated.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Via {
    /// A browser session cookie.
    Session,
    /// A personal API token (its id).
    Token(String),
    /// No credentials, in local mode.
    Local,
}

impl Via {
    /// `session`, `token` or `local`.
    pub fn as_str(&self) -> &'static str {
        match self {
            Via::Session => "session",
            Via::Token(_) => "token",
            Via::Local => "local",
        }
    }
}

/// Who is asking, as the guard put it in the request's extensions.
#[derive(Debug, Clone)]
pub struct Principal {
    /// The account (`None`: the local admin of local mode).
    pub user: Option<User>,
    /// What this request may do: the user's role, or the lower of the
    /// user's and the token's.
    pub role: Role,
    /// How it was authenticated.
    pub via: Via,
}

impl Principal {
    /// The local admin of local mode.
    pub fn local() -> Self {
        Principal {
            user: None,
            role: Role::Admin,
            via: Via::Local,
        }
    }

    /// The account's name (`local` for the local admin).
    pub fn name(&self) -> &str {
        self.user.as_ref().map_or("local", |u| u.name.as_str())
    }

    /// The account's id.
    pub fn user_id(&self) -> Option<&str> {
        self.user.as_ref().map(|u| u.id.as_str())
    }
}

/// What a route needs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Access {
    /// Anyone (health, sign-in, sign-out).
    Public,
    /// This role or a higher one.
    Role(Role),
}

impl Access {
    fn label(self) -> &'static str {
        match self {
            Access::Public => "public",
            Access::Role(r) => r.as_str(),
        }
    }
}

/// The least role each route needs (by method and route template). Reads
/// need a viewer; a write not listed needs an admin (closed by default;
/// `tests/api_auth.rs` lists every write of the spec).
pub fn access(method: &Method, route: &str) -> Access {
    use Role::*;
    let m = method.as_str();
    let role = match (m, route) {
        ("GET", "/api/health") | ("POST", "/api/auth/login" | "/api/auth/logout") => {
            return Access::Public;
        }
        // Accounts and the audit trail.
        ("GET", "/api/users" | "/api/audit") => Admin,
        (_, "/api/users" | "/api/users/{id}") => Admin,
        // One's own password and tokens (an admin also sees and revokes everyone's).
        ("POST", "/api/auth/password" | "/api/auth/tokens") => Viewer,
        ("DELETE", "/api/auth/tokens/{id}") => Viewer,
        ("GET" | "HEAD", _) => Viewer,
        // Plans, uploads, runs, jobs.
        ("POST", "/api/campaigns" | "/api/campaigns/{id}/plan" | "/api/campaigns/{id}/runs") => {
            Supervisor
        }
        ("PATCH" | "DELETE", "/api/campaigns/{id}") | ("POST", "/api/campaigns/{id}/restore") => {
            Supervisor
        }
        ("PATCH" | "DELETE", "/api/runs/{id}") | ("POST", "/api/runs/{id}/restore") => Supervisor,
        ("PUT", "/api/runs/{id}/clock-offset") => Supervisor,
        ("POST", "/api/jobs" | "/api/jobs/{id}/cancel" | "/api/jobs/{id}/retry") => Supervisor,
        // Settings: vessel profiles (limits, priors, thrusters), a campaign's
        // clock offset (it re-aligns every run); models.
        ("POST", "/api/vessels" | "/api/vessels/{id}/restore")
        | ("PATCH" | "DELETE", "/api/vessels/{id}") => Engineer,
        ("PUT", "/api/campaigns/{id}/clock-offset") => Engineer,
        ("PATCH" | "DELETE", "/api/models/{id}") | ("POST", "/api/models/{id}/restore") => Engineer,
        _ => Admin,
    };
    Access::Role(role)
}

/// Adds the security schemes to the document and, on every operation, the
/// role it needs (`x-required-role`), its security requirement and its
/// 401/403 answers.
pub fn document(doc: &mut utoipa::openapi::OpenApi) {
    let components = doc.components.get_or_insert_with(Default::default);
    components.add_security_scheme(
        "session",
        SecurityScheme::ApiKey(ApiKey::Cookie(ApiKeyValue::with_description(
            SESSION_COOKIE,
            "Browser session from `POST /api/auth/login` (HttpOnly, SameSite=Strict); \
             writes also need the header `X-Seatrial-CSRF: 1`",
        ))),
    );
    let mut bearer = Http::new(HttpAuthScheme::Bearer);
    bearer.description = Some(
        "Personal API token from `POST /api/auth/tokens` (`Authorization: Bearer st_…`)"
            .to_string(),
    );
    components.add_security_scheme("token", SecurityScheme::Http(bearer));
    let error = || utoipa::openapi::Content::new(Some(Ref::from_schema_name("ErrorBody")));
    for (path, item) in doc.paths.paths.iter_mut() {
        let ops = [
            (Method::GET, &mut item.get),
            (Method::POST, &mut item.post),
            (Method::PUT, &mut item.put),
            (Method::PATCH, &mut item.patch),
            (Method::DELETE, &mut item.delete),
        ];
        for (method, op) in ops {
            let Some(op) = op.as_mut() else { continue };
            let needed = access(&method, path);
            let ext = op.extensions.get_or_insert_with(Extensions::default);
            ext.insert("x-required-role".to_string(), needed.label().into());
            if needed == Access::Public {
                continue;
            }
            op.security = Some(vec![
                SecurityRequirement::new("session", Vec::<String>::new()),
                SecurityRequirement::new("token", Vec::<String>::new()),
            ]);
            let answers = &mut op.responses.responses;
            answers.entry("401".to_string()).or_insert_with(|| {
                ResponseBuilder::new()
                    .description(
                        "No valid credentials (sign in, or send a valid token) when the \
                         service requires them",
                    )
                    .content("application/json", error())
                    .build()
                    .into()
            });
            let forbidden = format!(
                "The role is below {} (`field`: `role`), a cross-origin write (`field`: \
                 `Origin`), or a cookie write without `X-Seatrial-CSRF: 1`",
                needed.label()
            );
            answers.entry("403".to_string()).or_insert_with(|| {
                ResponseBuilder::new()
                    .description(forbidden)
                    .content("application/json", error())
                    .build()
                    .into()
            });
        }
    }
}
