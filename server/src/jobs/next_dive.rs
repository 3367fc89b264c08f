//! The `next_dive` job: after a dive's runs are uploaded and scored, the
//! campaign's precision with what was actually flown (good and weak runs;
//! rejected, insufficient and excluded ones left out), and the planned
//! experiments to fly next within the dive's hours. The numerics are the
//! core's [`seatrial_core::design::propose_next_dive`]; the result is read
//! back by `GET /api/campaigns/{id}/next-dive`, and its run sheet by
//! `GET /api/campaigns/{id}/next-dive/runsheet`.

use std::collections::HashSet;

use seatrial_core::design::{NextDive, Prior, PriorSource, propose_next_dive};
use seatrial_core::estimation::Progress;
use seatrial_core::planning::vessel::VesselKind;
use serde::{Deserialize, Serialize};

use super::handler::{BoxFuture, Compute, JobContext, JobFailure, JobHandler, compute};
use super::identify::parse_settings;
use super::precision::{
    PriorChoice, build_prior, campaign_and_prior, core_plan, failure, no_plan, prior_or_default,
};
use super::run_inputs;
use crate::coverage::{CoverageStatus, coverage};
use crate::error::ApiError;
use crate::storage::jobs::{Job, JobRequest};
use crate::storage::{plans, runs};

/// Longest dive accepted (h).
pub const MAX_DIVE_HOURS: f64 = 48.0;
/// A dive's hours when none are given.
pub const DEFAULT_DIVE_HOURS: f64 = 4.0;

/// Settings of a `next_dive` job.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, utoipa::ToSchema)]
#[serde(deny_unknown_fields)]
pub struct NextDiveSettings {
    /// The prior the candidates are flown with; default: `model` when
    /// `model_id` is given, else `profile`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub prior: Option<PriorChoice>,
    /// Hours of the next dive (runs and set-up), 0 < h ≤ 48; default 4.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(exclusive_minimum = 0, maximum = 48)]
    pub dive_hours: Option<f64>,
}

/// The job's result.
#[derive(Debug, Clone, Serialize, Deserialize, utoipa::ToSchema)]
pub struct NextDiveResult {
    /// The plan the proposal is drawn from.
    pub plan_id: String,
    /// Its version.
    pub plan_version: i64,
    /// Where the prior came from.
    pub prior: PriorSource,
    /// Runs whose data counted (id, name).
    pub flown_run_ids: Vec<String>,
    /// The proposal.
    pub proposal: NextDive,
}

/// The `next_dive` handler.
pub struct NextDiveJob;

async fn checked(
    cx: &JobContext,
    req: &JobRequest,
) -> Result<(NextDiveSettings, super::precision::CampaignPrior), ApiError> {
    let settings: NextDiveSettings =
        parse_settings(&req.settings).map_err(|(f, m)| ApiError::invalid(f, m))?;
    if let Some(h) = settings.dive_hours
        && !(h.is_finite() && h > 0.0 && h <= MAX_DIVE_HOURS)
    {
        return Err(ApiError::invalid(
            "settings.dive_hours",
            format!("must be a number of hours in (0, {MAX_DIVE_HOURS}] (got {h})"),
        ));
    }
    let found =
        campaign_and_prior(cx, req, "next_dive", prior_or_default(settings.prior, req)).await?;
    if found.profile.kind != VesselKind::Rov6 {
        return Err(ApiError::invalid(
            "campaign_id",
            "the next-dive proposal ranks runs by the λ-filter regression's information, which a DP ship's parallel EKF does not share; see the campaign's coverage for the runs still to fly",
        ));
    }
    if plans::latest(&cx.db, &found.campaign.id).await?.is_none() {
        return Err(no_plan(&found.campaign));
    }
    Ok((settings, found))
}

impl JobHandler for NextDiveJob {
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
            let (settings, found) = checked(cx, req)
                .await
                .map_err(|e| JobFailure::new(e.to_string()))?;
            let cid = found.campaign.id.clone();
            let (stored_plan, plan) = core_plan(cx, &cid).await?;
            let all = runs::list(&cx.db, &cid).await?;
            let cov = coverage(&stored_plan, &all);
            // Good and weak runs of planned experiments, and accepted runs
            // flown without the plan, count; the rest is left out.
            let mut flown_ids: HashSet<String> = cov
                .experiments
                .iter()
                .flat_map(|e| &e.runs)
                .filter(|r| r.verdict == "good" || r.verdict == "weak")
                .map(|r| r.run_id.clone())
                .collect();
            flown_ids.extend(cov.unassigned_runs.iter().cloned());
            let chosen: Vec<_> = all
                .into_iter()
                .filter(|r| r.status == "accepted" && !r.excluded && flown_ids.contains(&r.id))
                .collect();
            let done: Vec<String> = cov
                .experiments
                .iter()
                .filter(|e| e.status == CoverageStatus::Covered)
                .map(|e| e.code.clone())
                .collect();
            let stored = run_inputs::describe(cx, &cid, chosen).await?;
            let choice = prior_or_default(settings.prior, req);
            let dive_hours = settings.dive_hours.unwrap_or(DEFAULT_DIVE_HOURS);
            let (plan_id, plan_version) = (stored_plan.id.clone(), stored_plan.version);
            Ok(compute(move |progress: &mut dyn Progress| {
                progress.update(0.0, "reading the flown runs")?;
                // One unreadable run is left out, not the job.
                let mut inputs = Vec::new();
                let mut unreadable = Vec::new();
                for s in &stored {
                    match run_inputs::read(&found.profile, std::slice::from_ref(s)) {
                        Ok((mut i, _)) => inputs.append(&mut i),
                        Err(_) => unreadable.push(format!(
                            "run '{}' could not be read and was left out",
                            s.name
                        )),
                    }
                }
                let (prior, source) = build_prior(choice, found.model, &found.profile)?;
                let Prior::Rov(truth) = prior else {
                    return Err(JobFailure::field(
                        "campaign_id",
                        "next dive needs an ROV prior",
                    ));
                };
                let mut proposal = propose_next_dive(
                    &found.profile,
                    &plan,
                    &inputs,
                    &done,
                    &truth,
                    dive_hours,
                    progress,
                )
                .map_err(failure)?;
                proposal.notes.extend(unreadable);
                serde_json::to_value(NextDiveResult {
                    plan_id,
                    plan_version,
                    prior: source,
                    flown_run_ids: inputs.iter().map(|i| i.run_id.clone()).collect(),
                    proposal,
                })
                .map_err(|e| JobFailure::new(e.to_string()))
            }))
        })
    }
}
