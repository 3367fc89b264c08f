//! Accounts, managed by admins: create with a role, change the role, reset
//! the password, disable; and the audit trail. Also the first admin, made
//! at start when the service requires credentials and has no account.

use axum::Json;
use axum::extract::{Extension, Path, State};
use axum::http::StatusCode;
use axum::response::Response;
use serde::Deserialize;

use super::{Principal, Role, secrets};
use crate::error::{ApiError, ApiResult, ErrorBody};
use crate::http::json::ApiJson;
use crate::http::query::{ApiQuery, Paging, with_total};
use crate::http::{AppState, blocking};
use crate::storage::Db;
use crate::storage::accounts::{self, UpdateRefused, User, UserUpdate};
use crate::storage::audit::{self, AuditEntry};

/// Longest login name.
const MAX_USER_NAME: usize = 64;

/// A login name: 1–64 of letters, digits, `.`, `_`, `-`, `@`.
fn check_user_name(name: &str) -> Result<(), ApiError> {
    let ok = !name.is_empty()
        && name.len() <= MAX_USER_NAME
        && name
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || matches!(b, b'.' | b'_' | b'-' | b'@'));
    if ok {
        Ok(())
    } else {
        Err(ApiError::invalid(
            "name",
            format!("a login name has 1–{MAX_USER_NAME} letters, digits, '.', '_', '-' or '@'"),
        ))
    }
}

/// An account to create.
#[derive(Debug, Deserialize, utoipa::ToSchema)]
#[serde(deny_unknown_fields)]
pub struct NewUser {
    /// Login name: 1–64 letters, digits, `.`, `_`, `-`, `@`.
    #[schema(min_length = 1, max_length = 64, pattern = r"^[A-Za-z0-9._@-]+$")]
    pub name: String,
    /// Role.
    pub role: Role,
    /// Password: 8 characters to 1024 bytes.
    #[schema(min_length = 8)]
    pub password: String,
}

/// Create an account.
#[utoipa::path(post, path = "/api/users", tag = "accounts",
    request_body = NewUser,
    responses(
        (status = 201, description = "The account", body = User),
        (status = 400, description = "Malformed JSON", body = ErrorBody),
        (status = 409, description = "The name is taken", body = ErrorBody),
        (status = 415, description = "Not JSON", body = ErrorBody),
        (status = 422, description = "A bad `name` or `password`", body = ErrorBody)))]
pub async fn create_user(
    State(s): State<AppState>,
    Extension(p): Extension<Principal>,
    ApiJson(body): ApiJson<NewUser>,
) -> ApiResult<(StatusCode, Json<User>)> {
    check_user_name(&body.name)?;
    secrets::check_password("password", &body.password)?;
    let password = body.password;
    let hash = blocking(move || secrets::hash_password(&password)).await??;
    let user = accounts::insert_user(&s.db, &body.name, body.role, &hash, p.user_id()).await?;
    let user = user.ok_or_else(|| {
        ApiError::Conflict(format!("a user named '{}' exists already", body.name))
    })?;
    Ok((StatusCode::CREATED, Json(user)))
}

/// Accounts by creation; `limit`/`offset` page the list and `X-Total-Count`
/// gives how many there are.
#[utoipa::path(get, path = "/api/users", tag = "accounts", params(Paging),
    responses(
        (status = 200, description = "Accounts", body = [User],
            headers(("x-total-count" = i64, description = "Accounts (all pages)"))),
        (status = 400, description = "Malformed query parameter", body = ErrorBody),
        (status = 422, description = "`limit` outside 1–1000", body = ErrorBody)))]
pub async fn list_users(
    State(s): State<AppState>,
    ApiQuery(p): ApiQuery<Paging>,
) -> ApiResult<Response> {
    let (items, total) = accounts::page_users(&s.db, p.page()?).await?;
    Ok(with_total(items, total))
}

/// A change to an account; absent fields are kept.
#[derive(Debug, Deserialize, utoipa::ToSchema)]
#[serde(deny_unknown_fields)]
pub struct UserChange {
    /// New role (its tokens get at most this role from now on).
    #[serde(default)]
    pub role: Option<Role>,
    /// Disable (`true`: no sign-in, sessions ended, tokens refused) or enable.
    #[serde(default)]
    pub disabled: Option<bool>,
    /// New password (ends the account's sessions).
    #[serde(default)]
    #[schema(min_length = 8)]
    pub password: Option<String>,
}

/// Change an account's role, password or whether it is disabled.
#[utoipa::path(patch, path = "/api/users/{id}", tag = "accounts",
    params(("id" = String, Path, description = "User id")),
    request_body = UserChange,
    responses(
        (status = 200, description = "The account", body = User),
        (status = 400, description = "Malformed JSON", body = ErrorBody),
        (status = 404, description = "No such user", body = ErrorBody),
        (status = 409, description = "It would leave no enabled admin", body = ErrorBody),
        (status = 415, description = "Not JSON", body = ErrorBody),
        (status = 422, description = "A bad `password`", body = ErrorBody)))]
pub async fn patch_user(
    State(s): State<AppState>,
    Path(id): Path<String>,
    ApiJson(change): ApiJson<UserChange>,
) -> ApiResult<Json<User>> {
    let password_hash = match change.password {
        Some(pw) => {
            secrets::check_password("password", &pw)?;
            Some(blocking(move || secrets::hash_password(&pw)).await??)
        }
        None => None,
    };
    let update = UserUpdate {
        role: change.role,
        disabled: change.disabled,
        password_hash,
    };
    match accounts::update_user(&s.db, &id, update).await? {
        Ok(u) => Ok(Json(u)),
        Err(UpdateRefused::Missing) => Err(ApiError::NotFound(format!("no user with id '{id}'"))),
        Err(UpdateRefused::LastAdmin) => Err(ApiError::Conflict(
            "this would leave no enabled admin: make another user admin first".to_string(),
        )),
    }
}

/// Filter of the audit trail.
#[derive(Debug, Deserialize, utoipa::IntoParams)]
#[into_params(parameter_in = Query)]
pub struct AuditFilter {
    /// Only this user's entries.
    pub user_id: Option<String>,
}

/// The audit trail, newest first: every write (who, when, method, route,
/// target, status) and every sign-in attempt. `limit`/`offset` page it and
/// `X-Total-Count` gives how many entries match.
#[utoipa::path(get, path = "/api/audit", tag = "accounts", params(AuditFilter, Paging),
    responses(
        (status = 200, description = "Entries, newest first", body = [AuditEntry],
            headers(("x-total-count" = i64, description = "Entries that match (all pages)"))),
        (status = 400, description = "Malformed query parameter", body = ErrorBody),
        (status = 422, description = "`limit` outside 1–1000", body = ErrorBody)))]
pub async fn list_audit(
    State(s): State<AppState>,
    ApiQuery(f): ApiQuery<AuditFilter>,
    ApiQuery(p): ApiQuery<Paging>,
) -> ApiResult<Response> {
    let (items, total) = audit::page(&s.db, f.user_id.as_deref(), p.page()?).await?;
    Ok(with_total(items, total))
}

/// The first admin of a service that requires credentials and has no
/// account: `admin` with the given password, else a random one returned
/// (to be printed once). `None` when accounts exist.
pub async fn bootstrap_admin(db: &Db, password: Option<String>) -> anyhow::Result<Option<String>> {
    if accounts::count_users(db).await? > 0 {
        return Ok(None);
    }
    let password = match password {
        Some(p) => p,
        None => secrets::one_time_password().map_err(|e| anyhow::anyhow!("{e}"))?,
    };
    secrets::check_password("admin password", &password).map_err(|e| anyhow::anyhow!("{e}"))?;
    let pw = password.clone();
    let hash = tokio::task::spawn_blocking(move || secrets::hash_password(&pw)).await??;
    accounts::insert_user(db, "admin", Role::Admin, &hash, None).await?;
    Ok(Some(password))
}
