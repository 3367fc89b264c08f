//! The campaign's experiment design: the newest succeeded `design` job's
//! result, and whether the plan has changed since.

use axum::Json;
use axum::extract::{Path, State};
use serde::Serialize;

use super::AppState;
use super::planning_jobs::newest_result;
use crate::error::{ApiResult, ErrorBody};
use crate::jobs::design::DesignResult;

/// A stored design.
#[derive(Debug, Serialize, utoipa::ToSchema)]
pub struct CampaignDesign {
    /// The `design` job that computed it.
    pub job_id: String,
    /// When it finished (RFC 3339).
    pub finished_at: Option<String>,
    /// True when the plan it was compared with is still the campaign's
    /// newest (after adopting the design by re-planning, it is not).
    pub current: bool,
    /// The design and its plan version.
    #[serde(flatten)]
    pub result: DesignResult,
}

/// The newest experiment design of the campaign (submit a `design` job to
/// compute one): the designed campaign within the budget, the trade-off of
/// precision against ship hours, and the ship-hour ratio to today's rules.
/// Adopt it by re-planning with `design.spec`'s families, repetitions,
/// excitation and durations.
#[utoipa::path(get, path = "/api/campaigns/{id}/design", tag = "planning",
    params(("id" = String, Path, description = "Campaign id")),
    responses((status = 200, description = "The newest design", body = CampaignDesign),
              (status = 404, description = "No such campaign, or no design yet", body = ErrorBody)))]
pub async fn get_design(
    State(s): State<AppState>,
    Path(id): Path<String>,
) -> ApiResult<Json<CampaignDesign>> {
    let (job, result, current) = newest_result(
        &s,
        &id,
        "design",
        "experiment design",
        |r: &DesignResult| &r.plan_id,
    )
    .await?;
    Ok(Json(CampaignDesign {
        job_id: job.id,
        finished_at: job.finished_at,
        current,
        result,
    }))
}
