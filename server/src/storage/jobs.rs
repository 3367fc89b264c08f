//! Jobs: the persisted queue of background computations. Every transition is
//! one conditional `UPDATE` (the state in the `WHERE`), so two workers, a
//! cancel request and a start-up recovery can never both win.

use sqlx::SqliteConnection;
use time::OffsetDateTime;

use super::{Db, new_id};

mod job;
pub use job::{IdentifyMethod, Job, JobError, JobKind, JobRequest, JobState, SubmittedRequest};

#[derive(sqlx::FromRow)]
struct Row {
    id: String,
    kind: String,
    campaign_id: Option<String>,
    request: String,
    state: String,
    progress: f64,
    stage: String,
    result: Option<String>,
    error: Option<String>,
    attempts: i64,
    max_attempts: i64,
    cancel_requested: bool,
    worker: Option<String>,
    lease_until: Option<String>,
    created_at: String,
    started_at: Option<String>,
    finished_at: Option<String>,
    updated_at: String,
}

impl TryFrom<Row> for Job {
    type Error = anyhow::Error;
    fn try_from(r: Row) -> anyhow::Result<Self> {
        Ok(Job {
            state: JobState::parse(&r.state)
                .ok_or_else(|| anyhow::anyhow!("job {} has unknown state '{}'", r.id, r.state))?,
            request: serde_json::from_str(&r.request)?,
            result: r.result.map(|v| serde_json::from_str(&v)).transpose()?,
            error: r.error.map(|v| serde_json::from_str(&v)).transpose()?,
            id: r.id,
            kind: r.kind,
            campaign_id: r.campaign_id,
            progress: r.progress,
            stage: r.stage,
            attempts: r.attempts,
            max_attempts: r.max_attempts,
            cancel_requested: r.cancel_requested,
            worker: r.worker,
            lease_until: r.lease_until,
            created_at: r.created_at,
            started_at: r.started_at,
            finished_at: r.finished_at,
            updated_at: r.updated_at,
        })
    }
}

const COLUMNS: &str = "id, kind, campaign_id, request, state, progress, stage, result, error, \
    attempts, max_attempts, cancel_requested, worker, lease_until, created_at, started_at, \
    finished_at, updated_at";

/// RFC 3339 UTC with exactly three fractional digits: fixed width, so text
/// order is time order (`time`'s RFC 3339 drops trailing zeros, which breaks it).
pub fn timestamp(t: OffsetDateTime) -> String {
    let t = t.to_offset(time::UtcOffset::UTC);
    format!(
        "{:04}-{:02}-{:02}T{:02}:{:02}:{:02}.{:03}Z",
        t.year(),
        u8::from(t.month()),
        t.day(),
        t.hour(),
        t.minute(),
        t.second(),
        t.millisecond()
    )
}

/// Now, as [`timestamp`].
pub fn stamp_now() -> String {
    timestamp(OffsetDateTime::now_utc())
}

fn lease_end(lease: std::time::Duration) -> String {
    timestamp(OffsetDateTime::now_utc() + lease)
}

/// Queues a new job.
pub async fn insert(db: &Db, request: &JobRequest, max_attempts: i64) -> anyhow::Result<Job> {
    let id = new_id();
    let now = stamp_now();
    sqlx::query(
        "INSERT INTO job (id, kind, campaign_id, request, state, progress, stage, attempts, \
         max_attempts, cancel_requested, created_at, updated_at) \
         VALUES ($1, $2, $3, $4, 'queued', 0, 'queued', 0, $5, FALSE, $6, $6)",
    )
    .bind(&id)
    .bind(&request.kind)
    .bind(&request.campaign_id)
    .bind(serde_json::to_string(request)?)
    .bind(max_attempts)
    .bind(&now)
    .execute(db)
    .await?;
    get(db, &id)
        .await?
        .ok_or_else(|| anyhow::anyhow!("job {id} vanished after insert"))
}

/// One job.
pub async fn get(db: &Db, id: &str) -> anyhow::Result<Option<Job>> {
    let row = sqlx::query_as::<_, Row>(sqlx::AssertSqlSafe(format!(
        "SELECT {COLUMNS} FROM job WHERE id = $1"
    )))
    .bind(id)
    .fetch_optional(db)
    .await?;
    row.map(Job::try_from).transpose()
}

/// Jobs, newest first, optionally of one campaign and/or in one state.
pub async fn list(
    db: &Db,
    campaign_id: Option<&str>,
    state: Option<JobState>,
) -> anyhow::Result<Vec<Job>> {
    // Only fixed fragments are spliced; the values are bound.
    let mut conditions = Vec::new();
    let mut n = 0;
    if campaign_id.is_some() {
        n += 1;
        conditions.push(format!("campaign_id = ${n}"));
    }
    if state.is_some() {
        n += 1;
        conditions.push(format!("state = ${n}"));
    }
    let filter = if conditions.is_empty() {
        String::new()
    } else {
        format!(" WHERE {}", conditions.join(" AND "))
    };
    let sql = format!("SELECT {COLUMNS} FROM job{filter} ORDER BY created_at DESC, id DESC");
    let mut q = sqlx::query_as::<_, Row>(sqlx::AssertSqlSafe(sql));
    if let Some(c) = campaign_id {
        q = q.bind(c.to_string());
    }
    if let Some(s) = state {
        q = q.bind(s.as_str());
    }
    q.fetch_all(db)
        .await?
        .into_iter()
        .map(Job::try_from)
        .collect()
}

/// Claims the oldest queued job for `worker`, race-free: the selection and
/// the transition are one statement (on PostgreSQL, add `FOR UPDATE SKIP
/// LOCKED` to the subquery). The attempt counter counts this claim.
pub async fn claim(
    db: &Db,
    worker: &str,
    lease: std::time::Duration,
) -> anyhow::Result<Option<Job>> {
    let now = stamp_now();
    let row = sqlx::query_as::<_, Row>(sqlx::AssertSqlSafe(format!(
        "UPDATE job SET state = 'running', worker = $1, lease_until = $2, attempts = attempts + 1, \
         progress = 0, started_at = $3, updated_at = $3 \
         WHERE id = (SELECT id FROM job WHERE state = 'queued' ORDER BY created_at, id LIMIT 1) \
         AND state = 'queued' RETURNING {COLUMNS}"
    )))
    .bind(worker)
    .bind(lease_end(lease))
    .bind(&now)
    .fetch_optional(db)
    .await?;
    row.map(Job::try_from).transpose()
}

/// What a heartbeat learned.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Heartbeat {
    /// Lease renewed; carry on.
    Continue,
    /// Lease renewed, but someone asked to cancel (possibly another process).
    CancelRequested,
    /// The job is no longer this worker's (its lease expired and it was
    /// recovered elsewhere): stop and write nothing.
    Lost,
}

/// Records progress, renews the lease and reads `cancel_requested`.
pub async fn heartbeat(
    db: &Db,
    id: &str,
    worker: &str,
    progress: f64,
    stage: &str,
    lease: std::time::Duration,
) -> anyhow::Result<Heartbeat> {
    let cancel: Option<bool> = sqlx::query_scalar(
        "UPDATE job SET progress = $1, stage = $2, lease_until = $3, updated_at = $4 \
         WHERE id = $5 AND worker = $6 AND state = 'running' RETURNING cancel_requested",
    )
    .bind(progress)
    .bind(stage)
    .bind(lease_end(lease))
    .bind(stamp_now())
    .bind(id)
    .bind(worker)
    .fetch_optional(db)
    .await?;
    Ok(match cancel {
        None => Heartbeat::Lost,
        Some(true) => Heartbeat::CancelRequested,
        Some(false) => Heartbeat::Continue,
    })
}

/// The end of a running job.
#[derive(Debug, Clone)]
pub enum Finish {
    /// Succeeded with the handler's result.
    Succeeded(serde_json::Value),
    /// Failed.
    Failed(JobError),
    /// Stopped on request.
    Cancelled,
}

/// Moves a running job of `worker` to its terminal state, on the caller's
/// connection, so that it commits together with what the handler persisted
/// in the same transaction. `false` when the job is no longer this worker's
/// (the caller must then roll back).
pub async fn finish(
    conn: &mut SqliteConnection,
    id: &str,
    worker: &str,
    outcome: &Finish,
    progress: f64,
    stage: &str,
) -> anyhow::Result<bool> {
    let (state, result, error, progress, stage) = match outcome {
        Finish::Succeeded(v) => ("succeeded", Some(v.to_string()), None, 1.0, "done"),
        Finish::Failed(e) => (
            "failed",
            None,
            Some(serde_json::to_string(e)?),
            progress,
            stage,
        ),
        Finish::Cancelled => ("cancelled", None, None, progress, "cancelled"),
    };
    let now = stamp_now();
    let done = sqlx::query(
        "UPDATE job SET state = $1, result = $2, error = $3, progress = $4, stage = $5, \
         lease_until = NULL, finished_at = $6, updated_at = $6 \
         WHERE id = $7 AND worker = $8 AND state = 'running'",
    )
    .bind(state)
    .bind(result)
    .bind(error)
    .bind(progress)
    .bind(stage)
    .bind(&now)
    .bind(id)
    .bind(worker)
    .execute(conn)
    .await?;
    Ok(done.rows_affected() == 1)
}

/// Result of a cancel request.
#[derive(Debug)]
pub enum CancelOutcome {
    /// It was queued and is now cancelled.
    Cancelled(Box<Job>),
    /// It is running; it stops at its next progress report.
    Requested(Box<Job>),
    /// It already ended in this state.
    Finished(JobState),
    /// No such job.
    NotFound,
}

/// Cancels a queued job at once, or flags a running one.
pub async fn request_cancel(db: &Db, id: &str) -> anyhow::Result<CancelOutcome> {
    // A job can move on between the statements (claimed, or re-queued by a
    // recovery); go round again then. Two rounds always suffice in practice.
    for _ in 0..4 {
        let now = stamp_now();
        let queued = sqlx::query(
            "UPDATE job SET state = 'cancelled', stage = 'cancelled before it started', \
             finished_at = $1, updated_at = $1 WHERE id = $2 AND state = 'queued'",
        )
        .bind(&now)
        .bind(id)
        .execute(db)
        .await?;
        if queued.rows_affected() == 1 {
            return Ok(get(db, id).await?.map_or(CancelOutcome::NotFound, |j| {
                CancelOutcome::Cancelled(Box::new(j))
            }));
        }
        let running = sqlx::query(
            "UPDATE job SET cancel_requested = TRUE, updated_at = $1 \
             WHERE id = $2 AND state = 'running'",
        )
        .bind(&now)
        .bind(id)
        .execute(db)
        .await?;
        if running.rows_affected() == 1 {
            return Ok(get(db, id).await?.map_or(CancelOutcome::NotFound, |j| {
                CancelOutcome::Requested(Box::new(j))
            }));
        }
        match get(db, id).await? {
            Some(j) if j.state.is_terminal() => return Ok(CancelOutcome::Finished(j.state)),
            Some(_) => continue,
            None => return Ok(CancelOutcome::NotFound),
        }
    }
    anyhow::bail!("job {id} kept changing state while being cancelled")
}

/// Result of a retry request.
#[derive(Debug)]
pub enum RetryOutcome {
    /// Queued again.
    Queued(Box<Job>),
    /// Not retryable in this state (queued, running or succeeded).
    NotRetryable(JobState),
    /// No such job.
    NotFound,
}

/// Queues a failed, cancelled or interrupted job again, from the beginning,
/// with `extra_attempts` more attempts than it has used.
pub async fn retry(db: &Db, id: &str, extra_attempts: i64) -> anyhow::Result<RetryOutcome> {
    let now = stamp_now();
    let done = sqlx::query(
        "UPDATE job SET state = 'queued', progress = 0, stage = 'queued again on request', \
         result = NULL, error = NULL, cancel_requested = FALSE, worker = NULL, lease_until = NULL, \
         started_at = NULL, finished_at = NULL, max_attempts = attempts + $1, updated_at = $2 \
         WHERE id = $3 AND state IN ('failed', 'cancelled', 'interrupted')",
    )
    .bind(extra_attempts)
    .bind(&now)
    .bind(id)
    .execute(db)
    .await?;
    Ok(match get(db, id).await? {
        Some(j) if done.rows_affected() == 1 => RetryOutcome::Queued(Box::new(j)),
        Some(j) => RetryOutcome::NotRetryable(j.state),
        None => RetryOutcome::NotFound,
    })
}

/// What a recovery pass did.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct Recovered {
    /// Orphans queued again (they restart from the beginning).
    pub requeued: u64,
    /// Orphans out of attempts, now `interrupted`.
    pub interrupted: u64,
    /// Orphans whose cancel had been requested, now `cancelled`.
    pub cancelled: u64,
}

/// Recovers jobs left `running` by a worker that died (its lease expired):
/// re-queued while attempts remain, else `interrupted`; a requested cancel
/// wins. Safe to run at any time and from several processes: a live worker
/// renews its lease long before it expires.
pub async fn recover(db: &Db) -> anyhow::Result<Recovered> {
    let now = stamp_now();
    let mut tx = db.begin().await?;
    let cancelled = sqlx::query(
        "UPDATE job SET state = 'cancelled', stage = 'cancelled (the server stopped while it ran)', \
         worker = NULL, lease_until = NULL, finished_at = $1, updated_at = $1 \
         WHERE state = 'running' AND lease_until < $1 AND cancel_requested",
    )
    .bind(&now)
    .execute(&mut *tx)
    .await?
    .rows_affected();
    let interrupted_error = serde_json::to_string(&JobError::new(
        "the server stopped while the job ran, and it has used all its attempts; retry it to start again",
    ))?;
    let interrupted = sqlx::query(
        "UPDATE job SET state = 'interrupted', error = $2, \
         stage = 'interrupted: the server stopped while it ran', \
         worker = NULL, lease_until = NULL, finished_at = $1, updated_at = $1 \
         WHERE state = 'running' AND lease_until < $1 AND attempts >= max_attempts",
    )
    .bind(&now)
    .bind(interrupted_error)
    .execute(&mut *tx)
    .await?
    .rows_affected();
    let requeued = sqlx::query(
        "UPDATE job SET state = 'queued', progress = 0, \
         stage = 'queued again: the server stopped while it ran; it restarts from the beginning', \
         worker = NULL, lease_until = NULL, updated_at = $1 \
         WHERE state = 'running' AND lease_until < $1",
    )
    .bind(&now)
    .execute(&mut *tx)
    .await?
    .rows_affected();
    tx.commit().await?;
    Ok(Recovered {
        requeued,
        interrupted,
        cancelled,
    })
}

/// A graceful stop of `worker`: its running jobs are queued again at once
/// with the attempt they were on given back (a restart is not a failure),
/// their leases released (the next start, or another server, claims them
/// now); a job whose cancel was asked for is cancelled.
pub async fn requeue_at_shutdown(db: &Db, worker: &str) -> anyhow::Result<Shutdown> {
    let now = stamp_now();
    let mut tx = db.begin().await?;
    let cancelled = sqlx::query(
        "UPDATE job SET state = 'cancelled', stage = 'cancelled (the server stopped while it ran)', \
         worker = NULL, lease_until = NULL, finished_at = $1, updated_at = $1 \
         WHERE worker = $2 AND state = 'running' AND cancel_requested",
    )
    .bind(&now)
    .bind(worker)
    .execute(&mut *tx)
    .await?
    .rows_affected();
    let requeued = sqlx::query(
        "UPDATE job SET state = 'queued', progress = 0, attempts = CASE WHEN attempts > 0 THEN attempts - 1 ELSE 0 END, \
         stage = 'queued again: the server was stopped while it ran; it restarts from the beginning', \
         worker = NULL, lease_until = NULL, updated_at = $1 \
         WHERE worker = $2 AND state = 'running'",
    )
    .bind(&now)
    .bind(worker)
    .execute(&mut *tx)
    .await?
    .rows_affected();
    tx.commit().await?;
    Ok(Shutdown {
        requeued,
        cancelled,
    })
}

/// What [`requeue_at_shutdown`] did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Shutdown {
    /// Jobs queued again, their attempt given back.
    pub requeued: u64,
    /// Jobs whose cancel had been asked for: cancelled.
    pub cancelled: u64,
}

#[cfg(test)]
mod tests;
