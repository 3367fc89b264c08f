//! The guard on every `/api` route (a route layer, so the matched route
//! template is known): who is asking (token, session cookie, or the local
//! admin), whether their role suffices for the route ([`super::access`]) —
//! before any path, query or body is read, so a too-low role gets 403
//! rather than 404 or 422 — and the audit row of every write.

use axum::body::Body;
use axum::extract::{MatchedPath, Request, State};
use axum::http::header::{self, HeaderMap, HeaderValue};
use axum::http::{Method, StatusCode};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};

use super::{Access, CSRF_HEADER, Principal, SESSION_COOKIE, Via, access, secrets};
use crate::error::ApiError;
use crate::http::AppState;
use crate::storage::accounts;
use crate::storage::audit::{self, NewAudit};

/// Who to record for a write that the guard could not name: a sign-in
/// (set by the handler on its response).
#[derive(Debug, Clone)]
pub struct AuditActor {
    /// The account, when the name is one.
    pub user_id: Option<String>,
    /// The name signed in with (or tried).
    pub user_name: String,
}

/// The reason a handler was given for a write (a delete's `reason`), for
/// the audit row (set on its response).
#[derive(Debug, Clone)]
pub struct AuditNote(pub String);

/// Largest response body read back for the id of what a write created.
const MAX_AUDIT_BODY: usize = 4 << 20;

fn is_write(m: &Method) -> bool {
    !matches!(
        *m,
        Method::GET | Method::HEAD | Method::OPTIONS | Method::TRACE
    )
}

/// The value of cookie `name` in the request's `Cookie` headers.
pub fn cookie<'a>(headers: &'a HeaderMap, name: &str) -> Option<&'a str> {
    headers
        .get_all(header::COOKIE)
        .iter()
        .filter_map(|v| v.to_str().ok())
        .flat_map(|v| v.split(';'))
        .filter_map(|kv| kv.trim().split_once('='))
        .find(|(k, _)| *k == name)
        .map(|(_, v)| v.trim_matches('"'))
}

fn unauthorized(message: impl Into<String>) -> Response {
    let mut r = ApiError::Unauthorized(message.into()).into_response();
    r.headers_mut().insert(
        header::WWW_AUTHENTICATE,
        HeaderValue::from_static("Bearer realm=\"seatrial\""),
    );
    r
}

/// Who sent the request: `Ok(None)` when nobody is signed in and the
/// service requires credentials; `Err` for a bad token or a cookie write
/// without the CSRF header.
async fn authenticate(
    s: &AppState,
    headers: &HeaderMap,
    write: bool,
) -> Result<Option<Principal>, Response> {
    if let Some(auth) = headers.get(header::AUTHORIZATION) {
        let token = auth
            .to_str()
            .ok()
            .and_then(|v| v.split_once(' '))
            .filter(|(scheme, _)| scheme.eq_ignore_ascii_case("bearer"))
            .map(|(_, t)| t.trim())
            .ok_or_else(|| unauthorized("Authorization must be `Bearer <token>`"))?;
        let found = accounts::token_user(&s.db, &secrets::token_hash(token))
            .await
            .map_err(|e| ApiError::Internal(e).into_response())?;
        let Some((t, user)) = found else {
            return Err(unauthorized(
                "the API token is unknown, revoked or expired, or its user is disabled",
            ));
        };
        return Ok(Some(Principal {
            role: t.role.min(user.role),
            user: Some(user),
            via: Via::Token(t.id),
        }));
    }
    if let Some(value) = cookie(headers, SESSION_COOKIE) {
        let user = accounts::session_user(&s.db, &secrets::token_hash(value))
            .await
            .map_err(|e| ApiError::Internal(e).into_response())?;
        if let Some(user) = user {
            if write
                && headers
                    .get(CSRF_HEADER)
                    .is_none_or(|v| v.as_bytes() != b"1")
            {
                return Err(ApiError::forbidden(
                    "X-Seatrial-CSRF",
                    "a write with a session cookie must carry the header X-Seatrial-CSRF: 1 \
                     (the web UI sends it; a cross-site page cannot)",
                )
                .into_response());
            }
            return Ok(Some(Principal {
                role: user.role,
                user: Some(user),
                via: Via::Session,
            }));
        }
        // An expired or ended session is no session.
    }
    Ok((!s.auth.required).then(Principal::local))
}

/// The guard (see the module documentation).
pub async fn guard(State(s): State<AppState>, mut req: Request, next: Next) -> Response {
    let route = req
        .extensions()
        .get::<MatchedPath>()
        .map_or_else(|| req.uri().path().to_string(), |m| m.as_str().to_string());
    let method = req.method().clone();
    let write = is_write(&method);
    let path = req.uri().path().to_string();
    let who = match authenticate(&s, req.headers(), write).await {
        Ok(who) => who,
        Err(resp) => return resp,
    };
    let resp = match (access(&method, &route), &who) {
        (Access::Role(_), None) => {
            return unauthorized(
                "sign in (POST /api/auth/login) or send a personal API token \
                 (Authorization: Bearer …)",
            );
        }
        (Access::Role(needed), Some(p)) if p.role < needed => ApiError::forbidden(
            "role",
            format!(
                "{method} {route} needs the role {} or higher; {} has {}",
                needed.as_str(),
                p.name(),
                p.role.as_str()
            ),
        )
        .into_response(),
        _ => {
            if let Some(p) = &who {
                req.extensions_mut().insert(p.clone());
            }
            next.run(req).await
        }
    };
    if !write {
        return resp;
    }
    let (user_id, user_name, via) = match (resp.extensions().get::<AuditActor>(), &who) {
        (Some(a), _) => (a.user_id.clone(), a.user_name.clone(), "login"),
        (None, Some(p)) => (
            p.user_id().map(String::from),
            p.name().to_string(),
            p.via.as_str(),
        ),
        // A sign-out without a session: nobody to record.
        (None, None) => return resp,
    };
    let status = resp.status();
    let note = resp.extensions().get::<AuditNote>().map(|n| n.0.clone());
    let (target_id, resp) = match path_id(&route, &path) {
        Some(id) => (Some(id), resp),
        None => created_id(resp).await,
    };
    let entry = NewAudit {
        user_id,
        user_name,
        via,
        method: method.to_string(),
        route,
        path,
        target_id,
        status: status.as_u16(),
        note,
    };
    if let Err(e) = audit::insert(&s.db, entry).await {
        tracing::error!(error = %e, "could not write the audit row of a write");
    }
    resp
}

/// The `{id}` of a route template, read from the path.
fn path_id(route: &str, path: &str) -> Option<String> {
    let at = route.split('/').position(|seg| seg == "{id}")?;
    path.split('/').nth(at).map(String::from)
}

/// The `id` of what a successful write answered with (JSON, not too large);
/// the response is rebuilt from the bytes read.
async fn created_id(resp: Response) -> (Option<String>, Response) {
    let json = resp
        .headers()
        .get(header::CONTENT_TYPE)
        .is_some_and(|v| v.as_bytes().starts_with(b"application/json"));
    let small = axum::body::HttpBody::size_hint(resp.body())
        .upper()
        .is_some_and(|n| n <= MAX_AUDIT_BODY as u64);
    if !resp.status().is_success() || resp.status() == StatusCode::NO_CONTENT || !json || !small {
        return (None, resp);
    }
    let (parts, body) = resp.into_parts();
    match axum::body::to_bytes(body, MAX_AUDIT_BODY).await {
        Ok(bytes) => {
            let id = serde_json::from_slice::<serde_json::Value>(&bytes)
                .ok()
                .and_then(|v| v.get("id").and_then(|i| i.as_str()).map(String::from));
            (id, Response::from_parts(parts, Body::from(bytes)))
        }
        Err(e) => (
            None,
            ApiError::Internal(anyhow::anyhow!("reading a response: {e}")).into_response(),
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_id_comes_from_the_routes_placeholder() {
        assert_eq!(
            path_id("/api/runs/{id}/clock-offset", "/api/runs/r1/clock-offset"),
            Some("r1".to_string())
        );
        assert_eq!(path_id("/api/vessels", "/api/vessels"), None);
    }

    #[test]
    fn cookies_are_found_among_others() {
        let mut h = HeaderMap::new();
        h.insert(
            header::COOKIE,
            HeaderValue::from_static("a=1; seatrial_session=xyz; b=2"),
        );
        assert_eq!(cookie(&h, "seatrial_session"), Some("xyz"));
        assert_eq!(cookie(&h, "c"), None);
    }
}
