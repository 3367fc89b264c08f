//! The campaign's predicted precision: the newest succeeded `precision`
//! job's table, and whether the plan has changed since.

use axum::Json;
use axum::extract::{Path, State};
use serde::Serialize;

use super::{AppState, found};
use crate::error::{ApiError, ApiResult, ErrorBody};
use crate::jobs::precision::PrecisionResult;
use crate::storage::jobs::{self as stored, JobState};
use crate::storage::{campaigns, plans};

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
    found(campaigns::get(&s.db, &id).await?, "campaign", &id)?;
    let jobs = stored::list(&s.db, Some(&id), Some(JobState::Succeeded)).await?;
    let Some(job) = jobs.into_iter().find(|j| j.kind == "precision") else {
        return Err(ApiError::NotFound(format!(
            "campaign '{id}' has no predicted precision yet; submit POST /api/jobs {{\"kind\": \"precision\", \"campaign_id\": \"{id}\"}}"
        )));
    };
    let result: PrecisionResult = serde_json::from_value(job.result.clone().unwrap_or_default())
        .map_err(|e| ApiError::Internal(anyhow::anyhow!("stored prediction unreadable: {e}")))?;
    let newest = plans::latest(&s.db, &id).await?.map(|p| p.id);
    Ok(Json(CampaignPrecision {
        job_id: job.id,
        finished_at: job.finished_at,
        current: newest.as_deref() == Some(result.plan_id.as_str()),
        result,
    }))
}
