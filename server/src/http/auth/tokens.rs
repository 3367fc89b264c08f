//! Personal API tokens: created (shown once), listed, revoked. A token's
//! role is at most its owner's; a request made with it gets the lower of
//! the two, so demoting a user demotes their tokens.

use axum::Json;
use axum::extract::{Extension, Path, State};
use axum::http::StatusCode;
use serde::{Deserialize, Serialize};

use super::{Principal, Role, secrets};
use crate::error::{ApiError, ApiResult, ErrorBody};
use crate::http::json::ApiJson;
use crate::http::query::ApiQuery;
use crate::http::run_description::check_name;
use crate::http::{AppState, found};
use crate::storage::accounts::{self, ApiToken};

/// A token to create.
#[derive(Debug, Deserialize, utoipa::ToSchema)]
#[serde(deny_unknown_fields)]
pub struct NewToken {
    /// What it is for, 1–200 characters.
    #[schema(min_length = 1, max_length = 200)]
    pub name: String,
    /// Its role (default: the requester's; at most the owner's).
    #[serde(default)]
    pub role: Option<Role>,
    /// Days until it expires, 1–3650 (default: until revoked).
    #[serde(default)]
    #[schema(minimum = 1, maximum = 3650)]
    pub expires_in_days: Option<u32>,
    /// Owner (admins only; default: the requester).
    #[serde(default)]
    pub user_id: Option<String>,
}

/// A new token: the secret is in this answer only.
#[derive(Debug, Serialize, utoipa::ToSchema)]
pub struct CreatedToken {
    /// Id (UUIDv7).
    pub id: String,
    /// The token, for `Authorization: Bearer …`; not stored, not shown again.
    pub token: String,
    /// Its description.
    #[serde(flatten)]
    pub info: ApiToken,
}

fn account(p: &Principal) -> Result<&crate::storage::accounts::User, ApiError> {
    p.user.as_ref().ok_or_else(|| {
        ApiError::Conflict(
            "the local admin of local mode has no account: create a user \
             (POST /api/users) and sign in as it"
                .to_string(),
        )
    })
}

/// Create a personal API token (an admin may create one for another user
/// with `user_id`).
#[utoipa::path(post, path = "/api/auth/tokens", tag = "accounts",
    request_body = NewToken,
    responses(
        (status = 201, description = "The token, shown once", body = CreatedToken),
        (status = 400, description = "Malformed JSON", body = ErrorBody),
        (status = 404, description = "No such `user_id`", body = ErrorBody),
        (status = 409, description = "The local admin of local mode has no account", body = ErrorBody),
        (status = 415, description = "Not JSON", body = ErrorBody),
        (status = 422, description = "`role` above the owner's or the requester's, `user_id` of another user without being admin, a bad `name` or `expires_in_days`", body = ErrorBody)))]
pub async fn create_token(
    State(s): State<AppState>,
    Extension(p): Extension<Principal>,
    ApiJson(body): ApiJson<NewToken>,
) -> ApiResult<(StatusCode, Json<CreatedToken>)> {
    let name = check_name("name", &body.name)?;
    let owner = match &body.user_id {
        Some(id) if p.user_id() != Some(id.as_str()) => {
            if p.role < Role::Admin {
                return Err(ApiError::invalid(
                    "user_id",
                    "only an admin creates tokens for another user",
                ));
            }
            accounts::get_user(&s.db, id)
                .await?
                .ok_or_else(|| ApiError::missing("user_id", format!("no user with id '{id}'")))?
        }
        _ => account(&p)?.clone(),
    };
    let ceiling = owner.role.min(p.role);
    let role = body.role.unwrap_or(ceiling);
    if role > ceiling {
        return Err(ApiError::invalid(
            "role",
            format!(
                "a token's role is at most its owner's and the requester's ({})",
                ceiling.as_str()
            ),
        ));
    }
    let expires_at = match body.expires_in_days {
        Some(d) if !(1..=3650).contains(&d) => {
            return Err(ApiError::invalid(
                "expires_in_days",
                "expires_in_days must be 1–3650",
            ));
        }
        Some(d) => Some(accounts::from_now(i64::from(d) * 86_400)),
        None => None,
    };
    let token = secrets::new_token()?;
    let prefix: String = token.chars().take(10).collect();
    let info = accounts::insert_token(
        &s.db,
        &owner.id,
        &name,
        role,
        &secrets::token_hash(&token),
        &prefix,
        expires_at,
    )
    .await?;
    Ok((
        StatusCode::CREATED,
        Json(CreatedToken {
            id: info.id.clone(),
            token,
            info,
        }),
    ))
}

/// Which tokens to list.
#[derive(Debug, Deserialize, utoipa::IntoParams)]
#[into_params(parameter_in = Query)]
pub struct TokenFilter {
    /// Everyone's tokens (admins only).
    pub all: Option<bool>,
}

/// One's own tokens, newest first (`?all=true`: everyone's, for an admin).
#[utoipa::path(get, path = "/api/auth/tokens", tag = "accounts", params(TokenFilter),
    responses(
        (status = 200, description = "Tokens (never their secret)", body = [ApiToken]),
        (status = 400, description = "Malformed query parameter", body = ErrorBody),
        (status = 409, description = "The local admin of local mode has no account (use `?all=true`)", body = ErrorBody)))]
pub async fn list_tokens(
    State(s): State<AppState>,
    Extension(p): Extension<Principal>,
    ApiQuery(f): ApiQuery<TokenFilter>,
) -> ApiResult<Json<Vec<ApiToken>>> {
    let all = f.all.unwrap_or(false);
    if all && p.role < Role::Admin {
        return Err(ApiError::forbidden(
            "role",
            "only an admin lists everyone's tokens",
        ));
    }
    let owner = if all {
        None
    } else {
        Some(account(&p)?.id.as_str())
    };
    Ok(Json(accounts::list_tokens(&s.db, owner).await?))
}

/// Revoke a token: one's own, or anyone's for an admin. Requests with it
/// get 401 from then on.
#[utoipa::path(delete, path = "/api/auth/tokens/{id}", tag = "accounts",
    params(("id" = String, Path, description = "Token id")),
    responses(
        (status = 200, description = "The revoked token", body = ApiToken),
        (status = 404, description = "No such token of the requester's", body = ErrorBody)))]
pub async fn revoke_token(
    State(s): State<AppState>,
    Extension(p): Extension<Principal>,
    Path(id): Path<String>,
) -> ApiResult<Json<ApiToken>> {
    let owner = if p.role >= Role::Admin {
        None
    } else {
        p.user_id()
    };
    let t = accounts::revoke_token(&s.db, &id, owner).await?;
    Ok(Json(found(t, "token", &id)?))
}
