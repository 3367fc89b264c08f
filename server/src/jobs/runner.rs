//! The runner: at start-up it recovers jobs orphaned by a dead server, then
//! one worker loop per slot claims queued jobs and runs them — inputs loaded
//! async, the computation on a blocking thread (the HTTP side never waits
//! for a core), a heartbeat alongside, and the end recorded in one
//! transaction with what the handler stores.

use std::sync::Arc;
use std::time::Duration;

use tokio::sync::{Notify, Semaphore, watch};
use tokio::task::JoinHandle;

use super::handler::{JobContext, JobFailure, Persist};
use super::heartbeat::{self, Beat};
use super::progress::{JobEvent, JobProgress, StopFlags};
use super::service::Jobs;
use crate::storage::jobs::{self, Finish, Job, JobError, JobState};

/// The running runner: stop it with [`shutdown`](Self::shutdown) (graceful)
/// or [`abort`](Self::abort) (as if the process died).
pub struct RunnerHandle {
    jobs: Jobs,
    cx: JobContext,
    workers: Vec<String>,
    tasks: Vec<JoinHandle<()>>,
}

struct Worker {
    id: String,
    jobs: Jobs,
    cx: JobContext,
    slots: Arc<Semaphore>,
}

/// Recovers orphaned jobs, then starts `config.workers` worker loops and a
/// periodic recovery (a job orphaned while this server runs — by another
/// process that died — is queued again once its lease expires).
pub async fn start(jobs: Jobs, cx: JobContext) -> anyhow::Result<RunnerHandle> {
    let r = jobs::recover(&cx.db).await?;
    if r != jobs::Recovered::default() {
        tracing::info!(
            requeued = r.requeued,
            interrupted = r.interrupted,
            cancelled = r.cancelled,
            "recovered jobs left running by a stopped server"
        );
    }
    let n = jobs.config().workers;
    let slots = Arc::new(Semaphore::new(n));
    // Unique per start, so two runners over one database never share a name.
    let tag = crate::storage::new_id();
    let tag = &tag[tag.len() - 8..];
    let mut workers = Vec::new();
    let mut tasks = Vec::new();
    for slot in 0..n {
        let w = Worker {
            id: format!("pid{}-{tag}/{slot}", std::process::id()),
            jobs: jobs.clone(),
            cx: cx.clone(),
            slots: slots.clone(),
        };
        workers.push(w.id.clone());
        tasks.push(tokio::spawn(worker_loop(w)));
    }
    tasks.push(tokio::spawn(recovery_loop(jobs.clone(), cx.clone())));
    tracing::info!(workers = n, "job runner started");
    Ok(RunnerHandle {
        jobs,
        cx,
        workers,
        tasks,
    })
}

impl RunnerHandle {
    /// Graceful stop (SIGTERM, Ctrl-C): stop claiming and renewing leases;
    /// running computations unwind at their next progress report and
    /// record nothing — the job is not cancelled (nobody asked) nor failed.
    /// Waits up to `grace` for them, then queues their jobs again with the
    /// attempt given back and the lease released, so the next start (or
    /// another server) claims them at once. A computation that finished
    /// within `grace` keeps its result.
    pub async fn shutdown(mut self, grace: Duration) {
        self.jobs.shutdown_token().cancel();
        let wait = async {
            for t in &mut self.tasks {
                let _ = t.await;
            }
        };
        if tokio::time::timeout(grace, wait).await.is_err() {
            tracing::warn!(
                "a computation did not stop within {grace:?}; its job is queued again anyway"
            );
        }
        for w in &self.workers {
            match jobs::requeue_at_shutdown(&self.cx.db, w).await {
                Ok(r) if r == jobs::Shutdown::default() => {}
                Ok(r) => tracing::info!(
                    worker = %w,
                    requeued = r.requeued,
                    cancelled = r.cancelled,
                    "queued running jobs again for the next start"
                ),
                Err(e) => {
                    tracing::warn!(worker = %w, error = %e, "could not queue running jobs again")
                }
            }
        }
    }

    /// Stops at once without writing anything, as a killed process would:
    /// running jobs stay `running` until their leases expire.
    pub fn abort(self) {
        // Unwinds the computations' threads too (they check the token).
        self.jobs.shutdown_token().cancel();
        for t in self.tasks {
            t.abort();
        }
    }

    /// Names of this runner's workers (as stored in `job.worker`).
    pub fn workers(&self) -> &[String] {
        &self.workers
    }
}

async fn worker_loop(w: Worker) {
    let token = w.jobs.shutdown_token().clone();
    let cfg = w.jobs.config().clone();
    loop {
        let permit = tokio::select! {
            p = w.slots.clone().acquire_owned() => match p {
                Ok(p) => p,
                Err(_) => return,
            },
            () = token.cancelled() => return,
        };
        if token.is_cancelled() {
            return;
        }
        match jobs::claim(&w.cx.db, &w.id, cfg.lease).await {
            Ok(Some(job)) => run_one(&w, job).await,
            Ok(None) => {
                drop(permit);
                // A wake sent while we were claiming is kept (Notify's permit).
                tokio::select! {
                    () = w.jobs.woken() => {}
                    () = tokio::time::sleep(cfg.poll) => {}
                    () = token.cancelled() => return,
                }
            }
            Err(e) => {
                drop(permit);
                tracing::warn!(worker = %w.id, error = %e, "claiming a job failed");
                tokio::select! {
                    () = tokio::time::sleep(cfg.poll) => {}
                    () = token.cancelled() => return,
                }
            }
        }
    }
}

async fn recovery_loop(jobs: Jobs, cx: JobContext) {
    let every = (jobs.config().lease / 2).max(Duration::from_millis(100));
    let token = jobs.shutdown_token().clone();
    loop {
        tokio::select! {
            () = tokio::time::sleep(every) => {}
            () = token.cancelled() => return,
        }
        match jobs::recover(&cx.db).await {
            Ok(r) => {
                if r.requeued > 0 || r.interrupted > 0 || r.cancelled > 0 {
                    tracing::info!(
                        requeued = r.requeued,
                        interrupted = r.interrupted,
                        cancelled = r.cancelled,
                        "recovered jobs whose worker stopped"
                    );
                }
                for _ in 0..r.requeued {
                    jobs.wake();
                }
            }
            Err(e) => tracing::warn!(error = %e, "job recovery failed"),
        }
    }
}

async fn run_one(w: &Worker, job: Job) {
    let id = job.id.clone();
    let cfg = w.jobs.config();
    // A restart after a crash begins again: say so until the handler reports.
    let stage = if job.attempts > 1 {
        format!(
            "loading inputs (attempt {}: restarted from the beginning)",
            job.attempts
        )
    } else {
        "loading inputs".to_string()
    };
    let (events, rx) = watch::channel(JobEvent {
        state: JobState::Running,
        progress: 0.0,
        stage,
    });
    let flags = Arc::new(StopFlags::new(job.cancel_requested));
    let stage_changed = Arc::new(Notify::new());
    w.jobs.live().insert(&id, rx.clone(), flags.clone());
    tracing::info!(job = %id, kind = %job.kind, attempt = job.attempts, worker = %w.id, "job started");

    let sink = JobProgress::new(
        events.clone(),
        flags.clone(),
        w.jobs.shutdown_token().clone(),
        stage_changed.clone(),
    );
    let work = async {
        let handler = w.jobs.registry().get(&job.kind).ok_or_else(|| {
            JobFailure::new(format!(
                "this server has no handler for the job kind '{}'",
                job.kind
            ))
        })?;
        let compute = handler.load(&w.cx, &job).await?;
        let mut sink = sink;
        match tokio::task::spawn_blocking(move || compute(&mut sink)).await {
            Ok(r) => r,
            Err(e) => Err(JobFailure::new(panic_message(e))),
        }
    };
    let beat = heartbeat::run(
        Beat {
            db: w.cx.db.clone(),
            id: id.clone(),
            worker: w.id.clone(),
            every: cfg.heartbeat,
            lease: cfg.lease,
            stop: w.jobs.shutdown_token().clone(),
        },
        rx,
        flags.clone(),
        stage_changed,
    );
    let outcome = tokio::select! {
        r = work => r,
        never = beat => match never {},
    };
    let last = events.borrow().clone();
    match conclude(w, &job, outcome, &flags, &last).await {
        Ok(true) => {
            // Subscribers see the terminal state as stored.
            if let Ok(Some(done)) = jobs::get(&w.cx.db, &id).await {
                tracing::info!(job = %id, state = done.state.as_str(), "job ended");
                events.send_replace(JobEvent::from(&done));
            }
        }
        Ok(false) => {
            tracing::info!(job = %id, "job not recorded (shutdown: queued again; or lease lost)")
        }
        // The row stays `running`; its lease expires and recovery re-queues it.
        Err(e) => tracing::error!(job = %id, error = %e, "recording the end of a job failed"),
    }
    w.jobs.live().remove(&id);
}

/// Records the end of a job; `false` when nothing was recorded on purpose
/// (abandoned at shutdown, or no longer this worker's).
async fn conclude(
    w: &Worker,
    job: &Job,
    outcome: Result<Box<dyn Persist>, JobFailure>,
    flags: &StopFlags,
    last: &JobEvent,
) -> anyhow::Result<bool> {
    if flags.is_lost() {
        return Ok(false);
    }
    let finish = match outcome {
        // Even during a shutdown: the work is done, keep it.
        Ok(output) => return persist(w, job, output, last).await,
        Err(JobFailure::Cancelled)
            if !flags.cancelled() && w.jobs.shutdown_token().is_cancelled() =>
        {
            return Ok(false);
        }
        Err(JobFailure::Cancelled) => Finish::Cancelled,
        Err(JobFailure::Failed(e)) => Finish::Failed(e),
    };
    let mut conn = w.cx.db.acquire().await?;
    jobs::finish(
        &mut conn,
        &job.id,
        &w.id,
        &finish,
        last.progress,
        &last.stage,
    )
    .await
}

/// The handler's output and the `succeeded` state, in one transaction.
async fn persist(
    w: &Worker,
    job: &Job,
    output: Box<dyn Persist>,
    last: &JobEvent,
) -> anyhow::Result<bool> {
    let mut tx = w.cx.db.begin().await?;
    match output.persist(&mut tx, job).await {
        Ok(result) => {
            let ok = jobs::finish(
                &mut tx,
                &job.id,
                &w.id,
                &Finish::Succeeded(result),
                1.0,
                "done",
            )
            .await?;
            if ok {
                tx.commit().await?;
            } else {
                // Not ours any more: what the handler wrote goes too.
                tx.rollback().await?;
            }
            Ok(ok)
        }
        Err(e) => {
            tx.rollback().await?;
            tracing::warn!(job = %job.id, error = %e, "storing a job's result failed");
            let failed = Finish::Failed(JobError::new(format!("storing the result failed: {e:#}")));
            let mut conn = w.cx.db.acquire().await?;
            jobs::finish(
                &mut conn,
                &job.id,
                &w.id,
                &failed,
                last.progress,
                &last.stage,
            )
            .await
        }
    }
}

fn panic_message(e: tokio::task::JoinError) -> String {
    match e.try_into_panic() {
        Ok(p) => {
            let what = p
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| p.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            format!("the computation failed unexpectedly (panic: {what})")
        }
        Err(e) => format!("the computation was stopped: {e}"),
    }
}
