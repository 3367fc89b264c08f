//! Managing what is stored: rename a campaign, rename or annotate a model
//! (vessels: `vessels`; runs: `PATCH /api/runs/{id}` in `run_description`;
//! deletes and their undo: `lifecycle`). Every write is one transaction.

use axum::Json;
use axum::extract::{Path, State};
use serde::Deserialize;

use super::json::ApiJson;
use super::run_description::{MAX_NOTES_CHARS, check_name};
use super::{AppState, found};
use crate::error::{ApiError, ApiResult, ErrorBody};
use crate::storage::campaigns::{self, Campaign};
use crate::storage::models::{self, ModelSummary};
use seatrial_core::planning::PlanError;

/// A change to a campaign.
#[derive(Debug, Deserialize, utoipa::ToSchema)]
#[serde(deny_unknown_fields)]
pub struct CampaignChange {
    /// New name, 1–200 characters (trimmed).
    #[schema(min_length = 1, max_length = 200, pattern = r"\S")]
    pub name: String,
}

/// Rename a campaign (its plan, runs and models are unchanged).
#[utoipa::path(patch, path = "/api/campaigns/{id}", tag = "planning",
    params(("id" = String, Path, description = "Campaign id")),
    request_body = CampaignChange,
    responses(
        (status = 200, description = "The renamed campaign", body = Campaign),
        (status = 400, description = "Malformed JSON; `field` names the JSON path", body = ErrorBody),
        (status = 404, description = "No such campaign", body = ErrorBody),
        (status = 415, description = "Not JSON", body = ErrorBody),
        (status = 422, description = "An empty or too long `name`", body = ErrorBody)))]
pub async fn patch_campaign(
    State(s): State<AppState>,
    Path(id): Path<String>,
    ApiJson(change): ApiJson<CampaignChange>,
) -> ApiResult<Json<Campaign>> {
    let name = check_name("name", &change.name)?;
    let c = campaigns::rename(&s.db, &id, &name).await?;
    Ok(Json(found(c, "campaign", &id)?))
}

/// A change to a model's name or notes. Absent: kept; `notes: null` clears them.
#[derive(Debug, Deserialize, utoipa::ToSchema)]
#[serde(deny_unknown_fields)]
pub struct ModelChange {
    /// New name, 1–200 characters (trimmed).
    #[schema(min_length = 1, max_length = 200, pattern = r"\S")]
    #[serde(default)]
    pub name: Option<String>,
    /// Free notes, at most 2000 characters (`null` clears them).
    #[serde(default, deserialize_with = "present")]
    #[schema(value_type = Option<String>, nullable, max_length = 2000)]
    pub notes: Option<Option<String>>,
}

/// Present (even as `null`) → `Some(value)`; absent → `None` (with `default`).
fn present<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<Option<String>>, D::Error> {
    Option::<String>::deserialize(d).map(Some)
}

/// Rename a model version or set its notes.
#[utoipa::path(patch, path = "/api/models/{id}", tag = "models",
    params(("id" = String, Path, description = "Model id")),
    request_body = ModelChange,
    responses(
        (status = 200, description = "The model's metadata", body = ModelSummary),
        (status = 400, description = "Malformed JSON; `field` names the JSON path", body = ErrorBody),
        (status = 404, description = "No such model", body = ErrorBody),
        (status = 415, description = "Not JSON", body = ErrorBody),
        (status = 422, description = "An empty or too long `name`, `notes` over 2000 characters", body = ErrorBody)))]
pub async fn patch_model(
    State(s): State<AppState>,
    Path(id): Path<String>,
    ApiJson(change): ApiJson<ModelChange>,
) -> ApiResult<Json<ModelSummary>> {
    let name = change
        .name
        .as_deref()
        .map(|n| check_name("name", n))
        .transpose()?;
    let notes = change
        .notes
        .map(|n| n.map(|n| n.trim().to_string()).filter(|n| !n.is_empty()));
    if let Some(Some(n)) = &notes
        && n.chars().count() > MAX_NOTES_CHARS
    {
        return Err(ApiError::Unprocessable(PlanError::over_limit(
            "notes",
            format!("notes are limited to {MAX_NOTES_CHARS} characters"),
            MAX_NOTES_CHARS as f64,
        )));
    }
    if !models::update(
        &s.db,
        &id,
        name.as_deref(),
        notes.as_ref().map(|n| n.as_deref()),
    )
    .await?
    {
        return Err(ApiError::NotFound(format!("no model with id '{id}'")));
    }
    let m = found(models::get(&s.db, &id).await?, "model", &id)?;
    Ok(Json(m.summary))
}
