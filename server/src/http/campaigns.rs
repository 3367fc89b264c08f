//! Campaigns: the LPV grid, families and excitation settings for a vessel.

use axum::Json;
use axum::extract::{Path, State};
use axum::http::StatusCode;
use seatrial_core::planning::campaign::{Durations, Excitation};
use seatrial_core::planning::{CampaignSpec, ExperimentFamily, SpeedGrid, generate_plan};
use serde::Deserialize;

use super::json::ApiJson;
use super::query::{ApiQuery, Paging, paged};
use super::{AppState, blocking, found};
use crate::error::{ApiError, ApiResult, ErrorBody};
use crate::storage::campaigns::{self, Campaign};
use crate::storage::vessels;
use axum::response::Response;

/// A new campaign: the vessel it is for, and the campaign itself.
#[derive(Debug, Deserialize, utoipa::ToSchema)]
#[serde(deny_unknown_fields)]
pub struct NewCampaign {
    /// Vessel id.
    pub vessel_id: String,
    /// Name (1–200 characters, not blank).
    #[schema(min_length = 1, max_length = 200, pattern = r"\S")]
    pub name: String,
    /// Forward-speed grid, in kn or m/s.
    pub grid: SpeedGrid,
    /// Families to fly (at least one, each once).
    #[schema(min_items = 1)]
    pub families: Vec<ExperimentFamily>,
    /// Repetitions (default 1 for a ROV, 2 for a DP vessel; DP needs ≥ 2).
    #[serde(default)]
    pub repetitions: Option<u32>,
    /// Excitation settings.
    #[serde(default)]
    pub excitation: Excitation,
    /// Durations.
    #[serde(default)]
    pub durations: Durations,
    /// Seed of every pseudo-random sequence (0 … 2⁵³−1). When absent a random
    /// seed is drawn and stored, so the plan stays reproducible.
    #[serde(default)]
    pub seed: Option<u64>,
}

/// Filter of the campaign list.
#[derive(Debug, Deserialize, utoipa::IntoParams)]
#[into_params(parameter_in = Query)]
pub struct CampaignFilter {
    /// Only campaigns of this vessel.
    pub vessel_id: Option<String>,
    /// `true`: the deleted campaigns instead of the live ones (default false;
    /// the campaigns of a deleted vessel are in neither list).
    pub deleted: Option<bool>,
}

/// Create a campaign. It is planned once as a dry run, so a campaign that
/// exists can always be planned: every limit violation is a 422 here.
#[utoipa::path(post, path = "/api/campaigns", tag = "planning",
    request_body = NewCampaign,
    responses(
        (status = 201, description = "Created", body = Campaign),
        (status = 400, description = "Malformed JSON; `field` names the JSON path", body = ErrorBody),
        (status = 404, description = "No such vessel", body = ErrorBody),
        (status = 409, description = "The vessel is deleted (named by name and id)", body = ErrorBody),
        (status = 413, description = "Body too large", body = ErrorBody),
        (status = 415, description = "Not JSON", body = ErrorBody),
        (status = 422, description = "Impossible request: `field` and `limit` name what and why", body = ErrorBody)))]
pub async fn create_campaign(
    State(s): State<AppState>,
    ApiJson(req): ApiJson<NewCampaign>,
) -> ApiResult<(StatusCode, Json<Campaign>)> {
    let vessel = vessels::get(&s.db, &req.vessel_id).await?.ok_or_else(|| {
        ApiError::NotFound(format!(
            "no vessel with id '{}' (field vessel_id)",
            req.vessel_id
        ))
    })?;
    super::lifecycle_parents::refuse_deleted(&s.db, "vessel", &vessel.id).await?;
    let spec = CampaignSpec {
        name: req.name,
        grid: req.grid,
        families: req.families,
        repetitions: req.repetitions,
        excitation: req.excitation,
        durations: req.durations,
        seed: req.seed.unwrap_or_else(|| {
            (uuid::Uuid::now_v7().as_u128() as u64) & seatrial_core::planning::design::MAX_SEED
        }),
        deciding: Vec::new(),
    };
    let profile = vessel.profile.clone();
    let checked = spec.clone();
    blocking(move || generate_plan(&profile, &checked).map(|_| ())).await??;
    Ok((
        StatusCode::CREATED,
        Json(campaigns::insert(&s.db, &vessel.id, spec).await?),
    ))
}

/// List campaigns, oldest first, without the deleted ones and those of a
/// deleted vessel (`?deleted=true` lists the deleted ones); `limit`/`offset`
/// page the list and the `X-Total-Count` header gives how many match.
#[utoipa::path(get, path = "/api/campaigns", tag = "planning",
    params(CampaignFilter, Paging),
    responses((status = 200, description = "Campaigns, oldest first", body = [Campaign],
                headers(("x-total-count" = i64, description = "Campaigns that match the filter (all pages)"))),
              (status = 400, description = "Malformed query parameter", body = ErrorBody),
              (status = 422, description = "`limit` outside 1–1000", body = ErrorBody)))]
pub async fn list_campaigns(
    State(s): State<AppState>,
    ApiQuery(f): ApiQuery<CampaignFilter>,
    ApiQuery(p): ApiQuery<Paging>,
) -> ApiResult<Response> {
    let page = p.page()?;
    Ok(paged(
        campaigns::list(&s.db, f.vessel_id.as_deref(), f.deleted.unwrap_or(false)).await?,
        page,
    ))
}

/// One campaign (a deleted one too, with `deleted_at`).
#[utoipa::path(get, path = "/api/campaigns/{id}", tag = "planning",
    params(("id" = String, Path, description = "Campaign id")),
    responses((status = 200, description = "The campaign", body = Campaign),
              (status = 404, description = "No such campaign", body = ErrorBody)))]
pub async fn get_campaign(
    State(s): State<AppState>,
    Path(id): Path<String>,
) -> ApiResult<Json<Campaign>> {
    Ok(Json(found(
        campaigns::get(&s.db, &id).await?,
        "campaign",
        &id,
    )?))
}
