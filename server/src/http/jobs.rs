//! Jobs: submit, list, follow (JSON or Server-Sent Events), cancel, retry.

use std::convert::Infallible;

use axum::Json;
use axum::extract::{Path, State};
use axum::http::StatusCode;
use axum::response::sse::{Event, KeepAlive, Sse};
use axum::response::{IntoResponse, Response};
use futures_util::StreamExt;
use serde::Deserialize;

use super::json::ApiJson;
use super::query::{ApiQuery, Paging, paged};
use super::{AppState, found};
use crate::error::{ApiError, ApiResult, ErrorBody};
use crate::jobs::{self, JobEvent};
use crate::storage::campaigns;
use crate::storage::jobs::{
    self as stored, CancelOutcome, Job, JobRequest, JobState, RetryOutcome,
};

/// Overlays the freshest progress of a job running in this process (the
/// database copy is written about once a second).
fn fresh(s: &AppState, mut job: Job) -> Job {
    if job.state == JobState::Running
        && let Some(e) = s.jobs.live().latest(&job.id)
        && e.state == JobState::Running
    {
        job.progress = e.progress;
        job.stage = e.stage;
    }
    job
}

async fn get_job_or_404(s: &AppState, id: &str) -> ApiResult<Job> {
    found(stored::get(&s.db, id).await?, "job", id)
}

/// Submit a job. The request is checked against the database first (the
/// kind, the campaign, each run, then what the kind itself requires);
/// nothing is queued on error. Follow it with `GET /api/jobs/{id}` or
/// `GET /api/jobs/{id}/events`.
#[utoipa::path(post, path = "/api/jobs", tag = "jobs",
    request_body = JobRequest,
    responses(
        (status = 202, description = "Queued", body = Job),
        (status = 400, description = "Malformed JSON; `field` names the JSON path", body = ErrorBody),
        (status = 404, description = "An id in the request is unknown; `field` names it (`campaign_id`, `run_ids[i]`, `model_id`)", body = ErrorBody),
        (status = 409, description = "The campaign or its vessel is deleted (named by name and id)", body = ErrorBody),
        (status = 413, description = "Body too large", body = ErrorBody),
        (status = 415, description = "Not JSON", body = ErrorBody),
        (status = 422, description = "Unusable request; `field` names it: an unknown `kind` (the message lists the registered ones), runs of another campaign, an unknown `method`, bad `settings`", body = ErrorBody)))]
pub async fn submit_job(
    State(s): State<AppState>,
    ApiJson(req): ApiJson<JobRequest>,
) -> ApiResult<(StatusCode, Json<Job>)> {
    let job = jobs::submit(&s.jobs, &s.job_context(), req).await?;
    Ok((StatusCode::ACCEPTED, Json(job)))
}

/// Filter of the job list.
#[derive(Debug, Deserialize, utoipa::IntoParams)]
#[into_params(parameter_in = Query)]
pub struct JobFilter {
    /// Only jobs of this campaign.
    pub campaign_id: Option<String>,
    /// Only jobs in this state: queued, running, succeeded, failed, cancelled or interrupted.
    #[param(value_type = Option<JobState>)]
    pub state: Option<String>,
}

/// Jobs, newest first; `limit`/`offset` page the list and the
/// `X-Total-Count` header gives how many match.
#[utoipa::path(get, path = "/api/jobs", tag = "jobs",
    params(JobFilter, Paging),
    responses(
        (status = 200, description = "Jobs, newest first", body = [Job],
            headers(("x-total-count" = i64, description = "Jobs that match the filters (all pages)"))),
        (status = 400, description = "Unknown `state`", body = ErrorBody),
        (status = 404, description = "No such campaign", body = ErrorBody),
        (status = 422, description = "`limit` outside 1–1000", body = ErrorBody)))]
pub async fn list_jobs(
    State(s): State<AppState>,
    ApiQuery(q): ApiQuery<JobFilter>,
    ApiQuery(p): ApiQuery<Paging>,
) -> ApiResult<Response> {
    let page = p.page()?;
    let state = match q.state.as_deref() {
        None => None,
        Some(v) => Some(JobState::parse(v).ok_or_else(|| {
            let all: Vec<&str> = JobState::ALL.iter().map(|s| s.as_str()).collect();
            ApiError::bad_field(
                "state",
                format!("unknown state '{v}'; one of {}", all.join(", ")),
            )
        })?),
    };
    if let Some(c) = &q.campaign_id
        && campaigns::get(&s.db, c).await?.is_none()
    {
        return Err(ApiError::missing(
            "campaign_id",
            format!("no campaign with id '{c}'"),
        ));
    }
    let list = stored::list(&s.db, q.campaign_id.as_deref(), state).await?;
    Ok(paged(
        list.into_iter().map(|j| fresh(&s, j)).collect(),
        page,
    ))
}

/// One job: state, progress 0–1, stage, result or error, attempts, times.
#[utoipa::path(get, path = "/api/jobs/{id}", tag = "jobs",
    params(("id" = String, Path, description = "Job id")),
    responses((status = 200, description = "The job", body = Job),
              (status = 404, description = "No such job", body = ErrorBody)))]
pub async fn get_job(State(s): State<AppState>, Path(id): Path<String>) -> ApiResult<Json<Job>> {
    let job = get_job_or_404(&s, &id).await?;
    Ok(Json(fresh(&s, job)))
}

/// Cancel a job. A queued job is cancelled at once (200); a running one is
/// asked to stop (202, `cancel_requested`) and becomes `cancelled` when its
/// computation next reports progress — also when another server process
/// runs it. A job that already ended answers 409.
#[utoipa::path(post, path = "/api/jobs/{id}/cancel", tag = "jobs",
    params(("id" = String, Path, description = "Job id")),
    responses(
        (status = 200, description = "It was queued and is now cancelled", body = Job),
        (status = 202, description = "It is running; cancellation requested", body = Job),
        (status = 404, description = "No such job", body = ErrorBody),
        (status = 409, description = "It already ended", body = ErrorBody)))]
pub async fn cancel_job(
    State(s): State<AppState>,
    Path(id): Path<String>,
) -> ApiResult<(StatusCode, Json<Job>)> {
    match stored::request_cancel(&s.db, &id).await? {
        CancelOutcome::Cancelled(job) => Ok((StatusCode::OK, Json(*job))),
        CancelOutcome::Requested(job) => {
            // In-process at once; another process reads the flag with its heartbeat.
            s.jobs.live().cancel(&id);
            Ok((StatusCode::ACCEPTED, Json(fresh(&s, *job))))
        }
        CancelOutcome::Finished(state) => Err(ApiError::Conflict(format!(
            "job '{id}' already ended ({}); there is nothing to cancel",
            state.as_str()
        ))),
        CancelOutcome::NotFound => Err(ApiError::NotFound(format!("no job with id '{id}'"))),
    }
}

/// Queue a failed, cancelled or interrupted job again. It starts from the
/// beginning with the same request and `max_attempts` more attempts.
#[utoipa::path(post, path = "/api/jobs/{id}/retry", tag = "jobs",
    params(("id" = String, Path, description = "Job id")),
    responses(
        (status = 202, description = "Queued again", body = Job),
        (status = 404, description = "No such job", body = ErrorBody),
        (status = 409, description = "Queued, running or succeeded: not retryable", body = ErrorBody)))]
pub async fn retry_job(
    State(s): State<AppState>,
    Path(id): Path<String>,
) -> ApiResult<(StatusCode, Json<Job>)> {
    match stored::retry(&s.db, &id, s.jobs.config().max_attempts).await? {
        RetryOutcome::Queued(job) => {
            s.jobs.wake();
            Ok((StatusCode::ACCEPTED, Json(*job)))
        }
        RetryOutcome::NotRetryable(state) => Err(ApiError::Conflict(format!(
            "job '{id}' is {}; only failed, cancelled or interrupted jobs can be retried{}",
            state.as_str(),
            if state == JobState::Succeeded {
                " (submit a new job to compute again)"
            } else {
                ""
            }
        ))),
        RetryOutcome::NotFound => Err(ApiError::NotFound(format!("no job with id '{id}'"))),
    }
}

/// Follow a job as Server-Sent Events: each event's `data` is a `JobEvent`
/// (`{state, progress, stage}`), the first one the current state; the
/// stream ends after the event with a terminal state (succeeded, failed,
/// cancelled, interrupted). At most ten events a second; progress in
/// between is coalesced.
#[utoipa::path(get, path = "/api/jobs/{id}/events", tag = "jobs",
    params(("id" = String, Path, description = "Job id")),
    responses(
        (status = 200, description = "`text/event-stream`: each event's `data` is one JSON `JobEvent` (the schema given here), until a terminal state", content_type = "text/event-stream", body = JobEvent),
        (status = 404, description = "No such job", body = ErrorBody)))]
pub async fn job_events(State(s): State<AppState>, Path(id): Path<String>) -> ApiResult<Response> {
    get_job_or_404(&s, &id).await?;
    let stream = jobs::events::follow(s.jobs.clone(), s.db.clone(), id).map(|e| {
        let event = Event::default()
            .json_data(&e)
            .unwrap_or_else(|_| Event::default().data("{}"));
        Ok::<_, Infallible>(event)
    });
    Ok(Sse::new(stream)
        .keep_alive(KeepAlive::default())
        .into_response())
}
