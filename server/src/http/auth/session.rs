//! Browser sign-in: `POST /api/auth/login` sets the session cookie,
//! `POST /api/auth/logout` ends it, `GET /api/auth/me` says who is signed
//! in, `POST /api/auth/password` changes one's own password.

use std::time::Instant;

use axum::Json;
use axum::extract::{Extension, State};
use axum::http::StatusCode;
use axum::http::header::{self, HeaderMap, HeaderValue};
use axum::response::{IntoResponse, Response};
use serde::{Deserialize, Serialize};

use super::middleware::{AuditActor, cookie};
use super::{Principal, Role, SESSION_COOKIE, SESSION_SECS, Via, secrets};
use crate::error::{ApiError, ApiResult, ErrorBody};
use crate::http::json::ApiJson;
use crate::http::{AppState, blocking};
use crate::storage::accounts::{self, UpdateRefused, UserUpdate};

/// Credentials.
#[derive(Debug, Deserialize, utoipa::ToSchema)]
#[serde(deny_unknown_fields)]
pub struct Login {
    /// Login name.
    #[schema(min_length = 1)]
    pub name: String,
    /// Password.
    #[schema(min_length = 1)]
    pub password: String,
}

/// Who is asking.
#[derive(Debug, Serialize, utoipa::ToSchema)]
pub struct Me {
    /// Account id (`null`: the local admin of local mode).
    pub user_id: Option<String>,
    /// Account name (`local` for the local admin).
    pub name: String,
    /// The role this request has (a token's, when lower than its user's).
    pub role: Role,
    /// `session`, `token` or `local`.
    pub via: String,
    /// Whether the service requires credentials (false: local mode).
    pub auth_required: bool,
}

impl Me {
    fn of(p: &Principal, auth_required: bool) -> Me {
        Me {
            user_id: p.user_id().map(String::from),
            name: p.name().to_string(),
            role: p.role,
            via: p.via.as_str().to_string(),
            auth_required,
        }
    }
}

fn session_cookie(s: &AppState, value: &str, max_age: i64) -> Result<HeaderValue, ApiError> {
    let secure = if s.auth.secure_cookie { "; Secure" } else { "" };
    HeaderValue::from_str(&format!(
        "{SESSION_COOKIE}={value}; Path=/; HttpOnly; SameSite=Strict; Max-Age={max_age}{secure}"
    ))
    .map_err(|e| ApiError::Internal(anyhow::anyhow!("cookie header: {e}")))
}

/// Sign in: the answer sets the session cookie (HttpOnly, SameSite=Strict,
/// 12 h; `Secure` with `--cookie-secure`). A wrong name, a wrong password
/// and a disabled account are answered alike.
#[utoipa::path(post, path = "/api/auth/login", tag = "accounts",
    request_body = Login,
    responses(
        (status = 200, description = "Signed in; `Set-Cookie: seatrial_session=…`", body = Me,
            headers(("set-cookie" = String, description = "The session cookie"))),
        (status = 400, description = "Malformed JSON", body = ErrorBody),
        (status = 401, description = "Wrong name or password, or a disabled account", body = ErrorBody),
        (status = 403, description = "A write from another origin, or a signed-in cookie without `X-Seatrial-CSRF: 1`", body = ErrorBody),
        (status = 415, description = "Not JSON", body = ErrorBody),
        (status = 429, description = "Too many wrong passwords for this name: wait the `Retry-After` seconds (after 5 failures, 1 s doubling to 15 min)", body = ErrorBody,
            headers(("retry-after" = u64, description = "Seconds to wait")))))]
pub async fn login(
    State(s): State<AppState>,
    ApiJson(body): ApiJson<Login>,
) -> ApiResult<Response> {
    let throttle = &s.auth.throttle;
    let actor = AuditActor {
        user_id: None,
        user_name: body.name.chars().take(200).collect(),
    };
    if let Err(e) = throttle.check(&body.name, Instant::now()) {
        let mut r = e.into_response();
        r.extensions_mut().insert(actor);
        return Ok(r);
    }
    let found = accounts::user_for_login(&s.db, &body.name).await?;
    let (user, phc) = match found {
        Some((u, phc)) => (Some(u), phc),
        None => (None, secrets::decoy_hash().to_string()),
    };
    let password = body.password;
    let ok = {
        let _permit = throttle.hashing_permit().await?;
        blocking(move || secrets::verify_password(&password, &phc)).await?
    };
    let actor = AuditActor {
        user_id: user.as_ref().map(|u| u.id.clone()),
        ..actor
    };
    let user = match user {
        Some(u) if ok && !u.disabled => u,
        _ => {
            if !ok {
                throttle.failed(&body.name, Instant::now());
            }
            let mut r =
                ApiError::Unauthorized("wrong name or password".to_string()).into_response();
            r.extensions_mut().insert(actor);
            return Ok(r);
        }
    };
    throttle.succeeded(&body.name);
    let value = secrets::random_hex()?;
    accounts::insert_session(&s.db, &user.id, &secrets::token_hash(&value), SESSION_SECS).await?;
    let me = Me::of(
        &Principal {
            role: user.role,
            user: Some(user),
            via: Via::Session,
        },
        s.auth.required,
    );
    let mut r = Json(me).into_response();
    r.headers_mut().insert(
        header::SET_COOKIE,
        session_cookie(&s, &value, SESSION_SECS)?,
    );
    r.extensions_mut().insert(actor);
    Ok(r)
}

/// Sign out: ends the session of the cookie sent (if any) and clears it.
#[utoipa::path(post, path = "/api/auth/logout", tag = "accounts",
    responses(
        (status = 204, description = "Signed out; the cookie is cleared"),
        (status = 403, description = "A write from another origin, or a signed-in cookie without `X-Seatrial-CSRF: 1`", body = ErrorBody)))]
pub async fn logout(State(s): State<AppState>, headers: HeaderMap) -> ApiResult<Response> {
    if let Some(value) = cookie(&headers, SESSION_COOKIE) {
        accounts::delete_session(&s.db, &secrets::token_hash(value)).await?;
    }
    let mut r = StatusCode::NO_CONTENT.into_response();
    r.headers_mut()
        .insert(header::SET_COOKIE, session_cookie(&s, "", 0)?);
    Ok(r)
}

/// Who is signed in (401 when nobody is and the service requires it; in
/// local mode the local admin).
#[utoipa::path(get, path = "/api/auth/me", tag = "accounts",
    responses((status = 200, description = "The requester", body = Me)))]
pub async fn me(State(s): State<AppState>, Extension(p): Extension<Principal>) -> Json<Me> {
    Json(Me::of(&p, s.auth.required))
}

/// A change of one's own password.
#[derive(Debug, Deserialize, utoipa::ToSchema)]
#[serde(deny_unknown_fields)]
pub struct PasswordChange {
    /// The password now.
    pub current_password: String,
    /// The new one: 8 characters to 1024 bytes.
    #[schema(min_length = 8)]
    pub new_password: String,
}

/// Change one's own password; every session of the account ends (sign in
/// again). Tokens stay valid.
#[utoipa::path(post, path = "/api/auth/password", tag = "accounts",
    request_body = PasswordChange,
    responses(
        (status = 204, description = "Changed; sign in again"),
        (status = 400, description = "Malformed JSON", body = ErrorBody),
        (status = 409, description = "The local admin of local mode has no password", body = ErrorBody),
        (status = 415, description = "Not JSON", body = ErrorBody),
        (status = 422, description = "`current_password` wrong, or `new_password` too short or long", body = ErrorBody),
        (status = 429, description = "Too many wrong passwords for this account: wait the `Retry-After` seconds", body = ErrorBody,
            headers(("retry-after" = u64, description = "Seconds to wait")))))]
pub async fn change_password(
    State(s): State<AppState>,
    Extension(p): Extension<Principal>,
    ApiJson(body): ApiJson<PasswordChange>,
) -> ApiResult<StatusCode> {
    let Some(user) = p.user else {
        return Err(ApiError::Conflict(
            "the local admin of local mode has no account or password".to_string(),
        ));
    };
    secrets::check_password("new_password", &body.new_password)?;
    let (_, phc) = accounts::user_for_login(&s.db, &user.name)
        .await?
        .ok_or_else(|| ApiError::NotFound(format!("no user with id '{}'", user.id)))?;
    let throttle = &s.auth.throttle;
    throttle.check(&user.name, Instant::now())?;
    let (current, new) = (body.current_password, body.new_password);
    let hashed = {
        let _permit = throttle.hashing_permit().await?;
        blocking(move || {
            secrets::verify_password(&current, &phc).then(|| secrets::hash_password(&new))
        })
        .await?
    };
    let Some(hash) = hashed else {
        throttle.failed(&user.name, Instant::now());
        return Err(ApiError::invalid(
            "current_password",
            "the current password is wrong",
        ));
    };
    let change = UserUpdate {
        password_hash: Some(hash?),
        ..UserUpdate::default()
    };
    match accounts::update_user(&s.db, &user.id, change).await? {
        Ok(_) => Ok(StatusCode::NO_CONTENT),
        Err(UpdateRefused::Missing | UpdateRefused::LastAdmin) => {
            Err(ApiError::NotFound(format!("no user with id '{}'", user.id)))
        }
    }
}
