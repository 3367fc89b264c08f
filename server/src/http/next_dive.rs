//! The campaign's next dive: the newest succeeded `next_dive` job's
//! proposal, and its printable run sheet.

use axum::Json;
use axum::extract::{Path, State};
use axum::response::Html;
use serde::Serialize;

use super::planning_jobs::newest_result;
use super::{AppState, export, found};
use crate::error::{ApiError, ApiResult, ErrorBody};
use crate::jobs::next_dive::NextDiveResult;
use crate::storage::{campaigns, plans, vessels};

/// A stored next-dive proposal.
#[derive(Debug, Serialize, utoipa::ToSchema)]
pub struct CampaignNextDive {
    /// The `next_dive` job that computed it.
    pub job_id: String,
    /// When it finished (RFC 3339).
    pub finished_at: Option<String>,
    /// True when the plan it was drawn from is still the campaign's newest.
    pub current: bool,
    /// The proposal, the plan version and the runs that counted as flown.
    #[serde(flatten)]
    pub result: NextDiveResult,
}

async fn newest(s: &AppState, id: &str) -> ApiResult<CampaignNextDive> {
    let (job, result, current) = newest_result(
        s,
        id,
        "next_dive",
        "next-dive proposal",
        |r: &NextDiveResult| &r.plan_id,
    )
    .await?;
    Ok(CampaignNextDive {
        job_id: job.id,
        finished_at: job.finished_at,
        current,
        result,
    })
}

/// The newest next-dive proposal (submit a `next_dive` job after the
/// dive's runs are uploaded): the precision with what was flown, the runs
/// to fly next in order, and their hours.
#[utoipa::path(get, path = "/api/campaigns/{id}/next-dive", tag = "planning",
    params(("id" = String, Path, description = "Campaign id")),
    responses((status = 200, description = "The newest proposal", body = CampaignNextDive),
              (status = 404, description = "No such campaign, or no proposal yet", body = ErrorBody)))]
pub async fn get_next_dive(
    State(s): State<AppState>,
    Path(id): Path<String>,
) -> ApiResult<Json<CampaignNextDive>> {
    Ok(Json(newest(&s, &id).await?))
}

/// The next dive as a printable run sheet (HTML): the proposed runs in the
/// order to fly them, with the plan's instructions and references.
#[utoipa::path(get, path = "/api/campaigns/{id}/next-dive/runsheet", tag = "planning",
    params(("id" = String, Path, description = "Campaign id")),
    responses(
        (status = 200, description = "Printable HTML run sheet of the next dive", content_type = "text/html", body = String),
        (status = 404, description = "No such campaign, no proposal, or its plan version is gone", body = ErrorBody)))]
pub async fn next_dive_run_sheet(
    State(s): State<AppState>,
    Path(id): Path<String>,
) -> ApiResult<Html<String>> {
    let dive = newest(&s, &id).await?;
    let campaign = found(campaigns::get(&s.db, &id).await?, "campaign", &id)?;
    let vessel = found(
        vessels::get(&s.db, &campaign.vessel_id).await?,
        "vessel",
        &campaign.vessel_id,
    )?;
    let mut plan = plans::latest(&s.db, &id)
        .await?
        .filter(|p| p.id == dive.result.plan_id)
        .ok_or_else(|| {
            ApiError::NotFound(format!(
                "the proposal was drawn from plan v{}, which is no longer the campaign's plan; propose the next dive again",
                dive.result.plan_version
            ))
        })?;
    let order = &dive.result.proposal.proposed;
    plan.experiments
        .retain(|e| order.iter().any(|p| p.code == e.experiment.code));
    plan.experiments.sort_by_key(|e| {
        order
            .iter()
            .position(|p| p.code == e.experiment.code)
            .unwrap_or(usize::MAX)
    });
    let setup_each = plan.totals.setup_time_s / plan.totals.experiments.max(1) as f64;
    let run: f64 = plan
        .experiments
        .iter()
        .map(|e| e.experiment.duration_s)
        .sum();
    plan.totals.experiments = plan.experiments.len();
    plan.totals.per_family.clear();
    for e in &plan.experiments {
        *plan
            .totals
            .per_family
            .entry(e.experiment.family.name().to_string())
            .or_default() += 1;
    }
    plan.totals.run_time_s = run;
    plan.totals.setup_time_s = setup_each * plan.experiments.len() as f64;
    plan.totals.total_time_s = run + plan.totals.setup_time_s;
    Ok(Html(export::run_sheet_titled(
        &vessel,
        &campaign,
        &plan,
        "Next dive",
    )))
}
