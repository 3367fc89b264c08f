//! The `design` job: a campaign, a prior model and a ship-time budget →
//! the campaign designed for the most precision in those hours, with the
//! trade-off of precision against hours beside today's rule-based plan.
//! The numerics are the core's [`seatrial_core::design::design_campaign`];
//! the result is read back by `GET /api/campaigns/{id}/design`, and the
//! supervisor adopts it by re-planning with its `spec`.

use seatrial_core::design::{ExperimentDesign, Prior, design_campaign};
use seatrial_core::estimation::Progress;
use seatrial_core::planning::vessel::VesselKind;
use serde::{Deserialize, Serialize};

use super::handler::{BoxFuture, Compute, JobContext, JobFailure, JobHandler, compute};
use super::identify::parse_settings;
use super::precision::{
    PriorChoice, build_prior, campaign_and_prior, failure, no_plan, prior_or_default,
};
use crate::error::ApiError;
use crate::storage::jobs::{Job, JobRequest};
use crate::storage::plans;

/// Largest budget accepted (h): a month of ship time.
pub const MAX_BUDGET_HOURS: f64 = 720.0;

/// Settings of a `design` job.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, utoipa::ToSchema)]
#[serde(deny_unknown_fields)]
pub struct DesignSettings {
    /// The prior; default: `model` when `model_id` is given, else `profile`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub prior: Option<PriorChoice>,
    /// Ship hours available (runs and set-up), 0 < h ≤ 720; default: the
    /// current plan's hours (the same time, spent better).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(exclusive_minimum = 0, maximum = 720)]
    pub budget_hours: Option<f64>,
}

/// The job's result: the design and the plan version it was made against.
#[derive(Debug, Clone, Serialize, Deserialize, utoipa::ToSchema)]
pub struct DesignResult {
    /// The plan the design is compared with.
    pub plan_id: String,
    /// Its version.
    pub plan_version: i64,
    /// Where the prior came from.
    pub prior: seatrial_core::design::PriorSource,
    /// The design.
    pub design: ExperimentDesign,
}

/// The `design` handler.
pub struct Design;

async fn checked(
    cx: &JobContext,
    req: &JobRequest,
) -> Result<
    (
        DesignSettings,
        super::precision::CampaignPrior,
        (String, i64),
    ),
    ApiError,
> {
    let settings: DesignSettings =
        parse_settings(&req.settings).map_err(|(f, m)| ApiError::invalid(f, m))?;
    if let Some(b) = settings.budget_hours
        && !(b.is_finite() && b > 0.0 && b <= MAX_BUDGET_HOURS)
    {
        return Err(ApiError::invalid(
            "settings.budget_hours",
            format!("must be a number of hours in (0, {MAX_BUDGET_HOURS}] (got {b})"),
        ));
    }
    let found =
        campaign_and_prior(cx, req, "design", prior_or_default(settings.prior, req)).await?;
    if found.profile.kind != VesselKind::Rov6 {
        return Err(ApiError::invalid(
            "campaign_id",
            "design for precision per ship-hour ranks plans by the λ-filter regression's information, which a DP ship's parallel EKF does not share; predict a DP plan's precision with a `precision` job instead",
        ));
    }
    let Some(plan) = plans::latest(&cx.db, &found.campaign.id).await? else {
        return Err(no_plan(&found.campaign));
    };
    Ok((settings, found, (plan.id, plan.version)))
}

impl JobHandler for Design {
    fn check<'a>(
        &'a self,
        cx: &'a JobContext,
        req: &'a JobRequest,
    ) -> BoxFuture<'a, Result<(), ApiError>> {
        Box::pin(async move { checked(cx, req).await.map(|_| ()) })
    }

    fn load<'a>(
        &'a self,
        cx: &'a JobContext,
        job: &'a Job,
    ) -> BoxFuture<'a, Result<Compute, JobFailure>> {
        Box::pin(async move {
            let req = &job.request;
            let (settings, found, head) = checked(cx, req)
                .await
                .map_err(|e| JobFailure::new(e.to_string()))?;
            let choice = prior_or_default(settings.prior, req);
            Ok(compute(move |progress: &mut dyn Progress| {
                let (prior, source) = build_prior(choice, found.model, &found.profile)?;
                let Prior::Rov(truth) = prior else {
                    return Err(JobFailure::field(
                        "campaign_id",
                        "design needs an ROV prior",
                    ));
                };
                let design = design_campaign(
                    &found.profile,
                    &found.campaign.spec,
                    &truth,
                    settings.budget_hours,
                    progress,
                )
                .map_err(failure)?;
                serde_json::to_value(DesignResult {
                    plan_id: head.0,
                    plan_version: head.1,
                    prior: source,
                    design,
                })
                .map_err(|e| JobFailure::new(e.to_string()))
            }))
        })
    }
}
