//! The newest result of a campaign's planning job (precision, design,
//! next dive), read back by the campaign's GET routes.

use serde::de::DeserializeOwned;

use super::{AppState, found};
use crate::error::ApiError;
use crate::storage::jobs::{self as stored, Job, JobState};
use crate::storage::{campaigns, plans};

/// The newest succeeded `kind` job of campaign `id`, its result as `T`,
/// and whether `plan_id(&result)` is still the campaign's newest plan. A
/// 404 names how to compute one (`what`: e.g. "predicted precision").
pub(crate) async fn newest_result<T: DeserializeOwned>(
    s: &AppState,
    id: &str,
    kind: &str,
    what: &str,
    plan_id: impl Fn(&T) -> &str,
) -> Result<(Job, T, bool), ApiError> {
    found(campaigns::get(&s.db, id).await?, "campaign", id)?;
    let jobs = stored::list(&s.db, Some(id), Some(JobState::Succeeded)).await?;
    let Some(job) = jobs.into_iter().find(|j| j.kind == kind) else {
        return Err(ApiError::NotFound(format!(
            "campaign '{id}' has no {what} yet; submit POST /api/jobs {{\"kind\": \"{kind}\", \"campaign_id\": \"{id}\"}}"
        )));
    };
    let result: T = serde_json::from_value(job.result.clone().unwrap_or_default())
        .map_err(|e| ApiError::Internal(anyhow::anyhow!("stored {what} unreadable: {e}")))?;
    let newest = plans::latest(&s.db, id).await?.map(|p| p.id);
    let current = newest.as_deref() == Some(plan_id(&result));
    Ok((job, result, current))
}
