//! Soft deletes of vessels and campaigns with undo, as runs and models have
//! them (`lifecycle`): the row stays, readable by id, with who deleted it,
//! when and why; a deleted vessel's campaigns leave the lists with it, a
//! deleted campaign's runs and models stay readable by id (every model's
//! provenance stays whole). Restoring under a deleted parent is a 409
//! naming the parent; so is new work (a campaign, a plan, an upload, a job)
//! under a deleted vessel or campaign.

use axum::extract::{Path, State};
use axum::response::Response;
use axum::{Extension, Json};
use serde::Deserialize;

use super::auth::Principal;
use super::lifecycle::{actor, noted, reason};
use super::query::ApiQuery;
use super::{AppState, found};
use crate::error::{ApiError, ApiResult, ErrorBody};
use crate::storage::campaigns::{self, Campaign};
use crate::storage::vessels::{self, Vessel};
use crate::storage::{Db, Restored, trash};

/// Why a vessel or campaign is deleted.
#[derive(Debug, Deserialize, utoipa::IntoParams)]
#[into_params(parameter_in = Query)]
pub struct DeleteQuery {
    /// Why (at most 2000 characters); kept with the item and in the audit trail.
    pub reason: Option<String>,
}

/// 409 when row `id` of `table` (a vessel or campaign) or one of its
/// parents is deleted: nothing new goes under a deleted item.
pub async fn refuse_deleted(db: &Db, table: &'static str, id: &str) -> ApiResult<()> {
    match trash::deleted_self_or_parent(db, table, id).await? {
        Some(g) => Err(gone(&g)),
        None => Ok(()),
    }
}

/// The 409 of new work under deleted item `g` (`kind 'name' (id)`).
pub fn gone(g: &str) -> ApiError {
    ApiError::Conflict(format!("{g} is deleted: restore it first (POST …/restore)"))
}

/// The answer to a restore of `what` (a vessel, campaign, run or model):
/// 404, or 409 naming it by name and id (not deleted, or under a deleted
/// parent, named too).
pub fn restored(r: Restored, what: &str, id: &str, name: &str) -> ApiResult<()> {
    restored_version(r, what, id, name, None)
}

/// [`restored`] for a model version (`'name' v3 (id)`).
pub fn restored_version(
    r: Restored,
    what: &str,
    id: &str,
    name: &str,
    version: Option<i64>,
) -> ApiResult<()> {
    let v = version.map(|v| format!(" v{v}")).unwrap_or_default();
    match r {
        Restored::NotFound => Err(ApiError::NotFound(format!("no {what} with id '{id}'"))),
        Restored::NotDeleted => Err(ApiError::Conflict(format!(
            "{what} '{name}'{v} ({id}) is not deleted"
        ))),
        Restored::ParentDeleted(p) => Err(ApiError::Conflict(format!(
            "{what} '{name}'{v} ({id}) cannot be restored: {p} is deleted; restore it first"
        ))),
        Restored::Done => Ok(()),
    }
}

/// Soft-deletes row `id` of `table` (a vessel or campaign) as the caller,
/// with the reason; 404 when there is none or it is deleted already. The
/// reason, for the audit row.
async fn soft_delete(
    s: &AppState,
    table: &'static str,
    id: &str,
    who: Option<&Extension<Principal>>,
    q: &DeleteQuery,
) -> ApiResult<Option<String>> {
    let why = reason(q.reason.as_deref())?;
    if !trash::delete(&s.db, table, id, &actor(who), why.as_deref()).await? {
        return Err(ApiError::NotFound(format!(
            "no {table} with id '{id}' (or it is deleted already)"
        )));
    }
    Ok(why)
}

/// Delete a vessel profile (soft): it and its campaigns leave the lists,
/// but everything stays readable by id; `POST /api/vessels/{id}/restore`
/// undoes it.
#[utoipa::path(delete, path = "/api/vessels/{id}", tag = "planning",
    params(("id" = String, Path, description = "Vessel id"), DeleteQuery),
    responses((status = 200, description = "Deleted: the vessel as it now is", body = Vessel),
              (status = 404, description = "No such vessel, or deleted already", body = ErrorBody),
              (status = 422, description = "`reason` over 2000 characters", body = ErrorBody)))]
pub async fn delete_vessel(
    State(s): State<AppState>,
    Path(id): Path<String>,
    who: Option<Extension<Principal>>,
    ApiQuery(q): ApiQuery<DeleteQuery>,
) -> ApiResult<Response> {
    let why = soft_delete(&s, "vessel", &id, who.as_ref(), &q).await?;
    let v = found(vessels::get(&s.db, &id).await?, "vessel", &id)?;
    Ok(noted(Json(v), why))
}

/// Undo the delete of a vessel (its campaigns come back into the lists
/// unless deleted themselves).
#[utoipa::path(post, path = "/api/vessels/{id}/restore", tag = "planning",
    params(("id" = String, Path, description = "Vessel id")),
    responses((status = 200, description = "Restored: the vessel", body = Vessel),
              (status = 404, description = "No such vessel", body = ErrorBody),
              (status = 409, description = "The vessel is not deleted", body = ErrorBody)))]
pub async fn restore_vessel(
    State(s): State<AppState>,
    Path(id): Path<String>,
) -> ApiResult<Json<Vessel>> {
    let r = trash::restore(&s.db, "vessel", &id).await?;
    let v = vessels::get(&s.db, &id).await?;
    restored(r, "vessel", &id, v.as_ref().map_or("", |v| &v.profile.name))?;
    Ok(Json(found(v, "vessel", &id)?))
}

/// Delete a campaign (soft): it leaves the lists with its runs and models,
/// which stay readable by id (every model's provenance stays whole); `POST
/// /api/campaigns/{id}/restore` undoes it.
#[utoipa::path(delete, path = "/api/campaigns/{id}", tag = "planning",
    params(("id" = String, Path, description = "Campaign id"), DeleteQuery),
    responses((status = 200, description = "Deleted: the campaign as it now is", body = Campaign),
              (status = 404, description = "No such campaign, or deleted already", body = ErrorBody),
              (status = 422, description = "`reason` over 2000 characters", body = ErrorBody)))]
pub async fn delete_campaign(
    State(s): State<AppState>,
    Path(id): Path<String>,
    who: Option<Extension<Principal>>,
    ApiQuery(q): ApiQuery<DeleteQuery>,
) -> ApiResult<Response> {
    let why = soft_delete(&s, "campaign", &id, who.as_ref(), &q).await?;
    let c = found(campaigns::get(&s.db, &id).await?, "campaign", &id)?;
    Ok(noted(Json(c), why))
}

/// Undo the delete of a campaign; refused while its vessel is deleted.
#[utoipa::path(post, path = "/api/campaigns/{id}/restore", tag = "planning",
    params(("id" = String, Path, description = "Campaign id")),
    responses((status = 200, description = "Restored: the campaign", body = Campaign),
              (status = 404, description = "No such campaign", body = ErrorBody),
              (status = 409, description = "The campaign is not deleted, or its vessel is (the message names it by name and id)", body = ErrorBody)))]
pub async fn restore_campaign(
    State(s): State<AppState>,
    Path(id): Path<String>,
) -> ApiResult<Json<Campaign>> {
    let r = trash::restore(&s.db, "campaign", &id).await?;
    let c = campaigns::get(&s.db, &id).await?;
    restored(r, "campaign", &id, c.as_ref().map_or("", |c| &c.spec.name))?;
    Ok(Json(found(c, "campaign", &id)?))
}
