//! Vessel profiles.

use axum::Json;
use axum::extract::{Path, State};
use axum::http::StatusCode;
use seatrial_core::planning::VesselProfile;

use super::json::ApiJson;
use super::query::{ApiQuery, Paging, paged};
use super::{AppState, found};
use crate::error::{ApiResult, ErrorBody};
use crate::storage::vessels::{self, Vessel};
use axum::response::Response;

/// Create a vessel profile.
#[utoipa::path(post, path = "/api/vessels", tag = "planning",
    request_body = VesselProfile,
    responses(
        (status = 201, description = "Created", body = Vessel),
        (status = 400, description = "Malformed JSON; `field` names the JSON path", body = ErrorBody),
        (status = 413, description = "Body too large", body = ErrorBody),
        (status = 415, description = "Not JSON", body = ErrorBody),
        (status = 422, description = "Incomplete or impossible profile; `field` and `limit` say why", body = ErrorBody)))]
pub async fn create_vessel(
    State(s): State<AppState>,
    ApiJson(profile): ApiJson<VesselProfile>,
) -> ApiResult<(StatusCode, Json<Vessel>)> {
    profile.validate()?;
    Ok((
        StatusCode::CREATED,
        Json(vessels::insert(&s.db, profile).await?),
    ))
}

/// Filter of the vessel list.
#[derive(Debug, serde::Deserialize, utoipa::IntoParams)]
#[into_params(parameter_in = Query)]
pub struct VesselFilter {
    /// `true`: the deleted vessels instead of the live ones (default false).
    pub deleted: Option<bool>,
}

/// List vessels, oldest first, without the deleted ones (`?deleted=true`
/// lists those); `limit`/`offset` page the list and the `X-Total-Count`
/// header gives how many there are.
#[utoipa::path(get, path = "/api/vessels", tag = "planning", params(VesselFilter, Paging),
    responses((status = 200, description = "Vessels, oldest first", body = [Vessel],
                headers(("x-total-count" = i64, description = "Vessels (all pages)"))),
              (status = 400, description = "Malformed query parameter", body = ErrorBody),
              (status = 422, description = "`limit` outside 1–1000", body = ErrorBody)))]
pub async fn list_vessels(
    State(s): State<AppState>,
    ApiQuery(f): ApiQuery<VesselFilter>,
    ApiQuery(p): ApiQuery<Paging>,
) -> ApiResult<Response> {
    let page = p.page()?;
    Ok(paged(
        vessels::list(&s.db, f.deleted.unwrap_or(false)).await?,
        page,
    ))
}

/// One vessel (a deleted one too, with `deleted_at`).
#[utoipa::path(get, path = "/api/vessels/{id}", tag = "planning",
    params(("id" = String, Path, description = "Vessel id")),
    responses((status = 200, description = "The vessel", body = Vessel),
              (status = 404, description = "No such vessel", body = ErrorBody)))]
pub async fn get_vessel(
    State(s): State<AppState>,
    Path(id): Path<String>,
) -> ApiResult<Json<Vessel>> {
    Ok(Json(found(vessels::get(&s.db, &id).await?, "vessel", &id)?))
}

/// A change to a vessel. Its physics (DOFs, limits, thrusters) stay as the
/// plans were made with them: a changed vessel is a new profile.
#[derive(Debug, serde::Deserialize, utoipa::ToSchema)]
#[serde(deny_unknown_fields)]
pub struct VesselChange {
    /// New name, 1–200 characters (trimmed).
    #[schema(min_length = 1, max_length = 200, pattern = r"\S")]
    pub name: String,
}

/// Rename a vessel (its campaigns, runs and models are unchanged).
#[utoipa::path(patch, path = "/api/vessels/{id}", tag = "planning",
    params(("id" = String, Path, description = "Vessel id")),
    request_body = VesselChange,
    responses(
        (status = 200, description = "The renamed vessel", body = Vessel),
        (status = 400, description = "Malformed JSON; `field` names the JSON path", body = ErrorBody),
        (status = 404, description = "No such vessel", body = ErrorBody),
        (status = 415, description = "Not JSON", body = ErrorBody),
        (status = 422, description = "An empty or too long `name`", body = ErrorBody)))]
pub async fn patch_vessel(
    State(s): State<AppState>,
    Path(id): Path<String>,
    ApiJson(change): ApiJson<VesselChange>,
) -> ApiResult<Json<Vessel>> {
    let name = super::run_description::check_name("name", &change.name)?;
    let v = vessels::rename(&s.db, &id, &name).await?;
    Ok(Json(found(v, "vessel", &id)?))
}
