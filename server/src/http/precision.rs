//! The campaign's predicted precision: the newest succeeded `precision`
//! job's table, and whether the plan has changed since.

use axum::Json;
use axum::extract::{Path, State};
use serde::Serialize;

use super::AppState;
use super::planning_jobs::newest_result;
use crate::error::{ApiResult, ErrorBody};
use crate::jobs::precision::PrecisionResult;

/// A stored prediction.
#[derive(Debug, Serialize, utoipa::ToSchema)]
pub struct CampaignPrecision {
    /// The `precision` job that computed it.
    pub job_id: String,
    /// When it finished (RFC 3339).
    pub finished_at: Option<String>,
    /// True when the plan it is for is still the campaign's newest.
    pub current: bool,
    /// The prediction and its plan version.
    #[serde(flatten)]
    pub result: PrecisionResult,
}

/// The newest predicted precision of the campaign's plan (submit a
/// `precision` job to compute one). `current` says whether the plan
/// changed since.
#[utoipa::path(get, path = "/api/campaigns/{id}/precision", tag = "planning",
    params(("id" = String, Path, description = "Campaign id")),
    responses((status = 200, description = "The newest prediction", body = CampaignPrecision),
              (status = 404, description = "No such campaign, or no prediction yet", body = ErrorBody)))]
pub async fn get_precision(
    State(s): State<AppState>,
    Path(id): Path<String>,
) -> ApiResult<Json<CampaignPrecision>> {
    let (job, result, current) = newest_result(
        &s,
        &id,
        "precision",
        "predicted precision",
        |r: &PrecisionResult| &r.plan_id,
    )
    .await?;
    Ok(Json(CampaignPrecision {
        job_id: job.id,
        finished_at: job.finished_at,
        current,
        result,
    }))
}
