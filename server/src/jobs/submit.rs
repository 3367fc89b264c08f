//! Submission: the checks every kind shares, then the kind's own `check`,
//! then the job is queued. Nothing is queued when a check fails.

use std::collections::HashSet;

use super::handler::JobContext;
use super::service::Jobs;
use crate::error::ApiError;
use crate::storage::jobs::{self, Job, JobRequest};
use crate::storage::{campaigns, runs, trash};

/// Validates `request` and queues it.
pub async fn submit(jobs: &Jobs, cx: &JobContext, request: JobRequest) -> Result<Job, ApiError> {
    let handler = jobs.registry().get(&request.kind).ok_or_else(|| {
        let kinds = jobs.registry().kinds();
        let known = if kinds.is_empty() {
            "this server has no job kinds registered yet".to_string()
        } else {
            format!("the registered kinds are: {}", kinds.join(", "))
        };
        ApiError::invalid(
            "kind",
            format!("unknown job kind '{}'; {known}", request.kind),
        )
    })?;
    if !request.settings.is_object() {
        return Err(ApiError::invalid(
            "settings",
            "settings must be a JSON object (use {} for the defaults)",
        ));
    }
    check_campaign_and_runs(cx, &request).await?;
    handler.check(cx, &request).await?;
    let job = jobs::insert(&cx.db, &request, jobs.config().max_attempts).await?;
    jobs.wake();
    Ok(job)
}

async fn check_campaign_and_runs(cx: &JobContext, request: &JobRequest) -> Result<(), ApiError> {
    let campaign = match &request.campaign_id {
        Some(id) => Some(campaigns::get(&cx.db, id).await?.ok_or_else(|| {
            ApiError::missing("campaign_id", format!("no campaign with id '{id}'"))
        })?),
        None => None,
    };
    if let Some(c) = &campaign
        && let Some(g) = trash::deleted_self_or_parent(&cx.db, "campaign", &c.id).await?
    {
        return Err(ApiError::Conflict(format!(
            "{g} is deleted: restore it first (POST …/restore)"
        )));
    }
    if request.run_ids.is_empty() {
        return Ok(());
    }
    let Some(campaign) = campaign else {
        return Err(ApiError::invalid(
            "campaign_id",
            "runs belong to a campaign: give the campaign_id of the run_ids",
        ));
    };
    let mut seen = HashSet::new();
    for (i, rid) in request.run_ids.iter().enumerate() {
        let field = format!("run_ids[{i}]");
        if !seen.insert(rid.as_str()) {
            return Err(ApiError::invalid(
                field,
                format!("run '{rid}' is listed twice"),
            ));
        }
        let run = runs::get(&cx.db, rid)
            .await?
            .ok_or_else(|| ApiError::missing(field.clone(), format!("no run with id '{rid}'")))?;
        let named = format!("run '{}' ({rid})", run.name);
        if run.campaign_id != campaign.id {
            return Err(ApiError::invalid(
                field,
                format!(
                    "{named} belongs to campaign '{}', not to '{}'",
                    run.campaign_id, campaign.id
                ),
            ));
        }
        if let Some(at) = &run.deleted_at {
            return Err(ApiError::invalid(
                field,
                format!(
                    "{named} was deleted at {at}; restore it (POST /api/runs/{rid}/restore) or leave it out"
                ),
            ));
        }
        if run.status != "accepted" {
            return Err(ApiError::invalid(
                field,
                format!(
                    "{named} is {} (not accepted at upload): it has no usable data",
                    run.status
                ),
            ));
        }
    }
    Ok(())
}
