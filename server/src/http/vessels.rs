//! Vessel profiles.

use axum::Json;
use axum::extract::{Path, State};
use axum::http::StatusCode;
use seatrial_core::planning::VesselProfile;

use super::json::ApiJson;
use super::{AppState, found};
use crate::error::{ApiResult, ErrorBody};
use crate::storage::vessels::{self, Vessel};

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

/// List vessels.
#[utoipa::path(get, path = "/api/vessels", tag = "planning",
    responses((status = 200, description = "All vessels", body = [Vessel])))]
pub async fn list_vessels(State(s): State<AppState>) -> ApiResult<Json<Vec<Vessel>>> {
    Ok(Json(vessels::list(&s.db).await?))
}

/// One vessel.
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
