//! The runner end to end on a real database: the handler's writes commit
//! with the job's end or not at all; panics fail the job; a graceful
//! shutdown records nothing and queues the job again, no attempt spent.

use std::time::Duration;

use serde_json::json;
use sqlx::SqliteConnection;

use super::*;
use crate::error::ApiError;
use crate::storage::jobs::{self as stored, Job, JobRequest, JobState};

/// Writes a `blob` row named by `settings.sha`, then fails if `settings.fail_persist`.
struct Writer;

struct Row {
    sha: String,
    fail: bool,
}

impl Persist for Row {
    fn persist<'a>(
        self: Box<Self>,
        conn: &'a mut SqliteConnection,
        _job: &'a Job,
    ) -> BoxFuture<'a, anyhow::Result<serde_json::Value>> {
        Box::pin(async move {
            sqlx::query("INSERT INTO blob (sha256, size_bytes, created_at) VALUES ($1, 0, 'now')")
                .bind(&self.sha)
                .execute(&mut *conn)
                .await?;
            anyhow::ensure!(!self.fail, "disk full (simulated)");
            Ok(json!({ "sha": self.sha }))
        })
    }
}

impl JobHandler for Writer {
    fn check<'a>(
        &'a self,
        _cx: &'a JobContext,
        _req: &'a JobRequest,
    ) -> BoxFuture<'a, Result<(), ApiError>> {
        Box::pin(async { Ok(()) })
    }

    fn load<'a>(
        &'a self,
        _cx: &'a JobContext,
        job: &'a Job,
    ) -> BoxFuture<'a, Result<Compute, JobFailure>> {
        let s = &job.request.settings;
        let sha = s["sha"].as_str().unwrap_or("x").to_string();
        let fail = s["fail_persist"].as_bool().unwrap_or(false);
        let panic = s["panic"].as_bool().unwrap_or(false);
        let wait_ms = s["wait_ms"].as_u64().unwrap_or(0);
        Box::pin(async move {
            Ok(compute(move |p| {
                for i in 0..=10u64 {
                    p.update(i as f64 / 10.0, "writing")?;
                    std::thread::sleep(Duration::from_millis(wait_ms / 10));
                }
                if panic {
                    panic!("boom");
                }
                Ok(Row { sha, fail })
            }))
        })
    }
}

async fn setup() -> (tempfile::TempDir, Jobs, JobContext, RunnerHandle) {
    let dir = tempfile::tempdir().unwrap();
    let db = crate::storage::open(&dir.path().join("t.db"))
        .await
        .unwrap();
    let cx = JobContext {
        db,
        blobs: crate::storage::blobs::BlobStore::open(&dir.path().join("blobs")).unwrap(),
    };
    let jobs = writer_jobs();
    let runner = start(jobs.clone(), cx.clone()).await.unwrap();
    (dir, jobs, cx, runner)
}

/// The `write` kind on one worker, 5 s leases, 50 ms heartbeats, 3 attempts.
fn writer_jobs() -> Jobs {
    Jobs::new(
        JobRegistry::new().with("write", Writer),
        JobsConfig {
            workers: 1,
            lease: Duration::from_secs(5),
            heartbeat: Duration::from_millis(50),
            max_attempts: 3,
            poll: Duration::from_millis(50),
        },
    )
}

async fn submit_settings(jobs: &Jobs, cx: &JobContext, settings: serde_json::Value) -> Job {
    let req = JobRequest {
        kind: "write".into(),
        settings,
        ..Default::default()
    };
    submit(jobs, cx, req).await.unwrap()
}

async fn wait_until(cx: &JobContext, id: &str, done: impl Fn(&Job) -> bool) -> Job {
    for _ in 0..400 {
        let j = stored::get(&cx.db, id).await.unwrap().unwrap();
        if done(&j) {
            return j;
        }
        tokio::time::sleep(Duration::from_millis(25)).await;
    }
    panic!("job {id} did not get there in time");
}

async fn blob_exists(cx: &JobContext, sha: &str) -> bool {
    sqlx::query_scalar::<_, i64>("SELECT COUNT(*) FROM blob WHERE sha256 = $1")
        .bind(sha)
        .fetch_one(&cx.db)
        .await
        .unwrap()
        == 1
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_handlers_writes_commit_with_success_and_roll_back_with_failure() {
    let (_d, jobs, cx, runner) = setup().await;
    let ok = submit_settings(&jobs, &cx, json!({ "sha": "a" })).await;
    let bad = submit_settings(&jobs, &cx, json!({ "sha": "b", "fail_persist": true })).await;
    let ok = wait_until(&cx, &ok.id, |j| j.state.is_terminal()).await;
    assert_eq!(ok.state, JobState::Succeeded);
    assert_eq!(ok.result, Some(json!({ "sha": "a" })));
    assert!(blob_exists(&cx, "a").await);
    let bad = wait_until(&cx, &bad.id, |j| j.state.is_terminal()).await;
    assert_eq!(bad.state, JobState::Failed);
    let msg = &bad.error.unwrap().message;
    assert!(
        msg.contains("storing the result failed") && msg.contains("disk full"),
        "{msg}"
    );
    assert!(
        !blob_exists(&cx, "b").await,
        "a failed job's writes must roll back"
    );
    runner.shutdown(Duration::from_secs(5)).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_panicking_computation_fails_its_job_and_the_worker_goes_on() {
    let (_d, jobs, cx, runner) = setup().await;
    let p = submit_settings(&jobs, &cx, json!({ "sha": "p", "panic": true })).await;
    let next = submit_settings(&jobs, &cx, json!({ "sha": "n" })).await;
    let p = wait_until(&cx, &p.id, |j| j.state.is_terminal()).await;
    assert_eq!(p.state, JobState::Failed);
    assert!(p.error.unwrap().message.contains("boom"));
    let next = wait_until(&cx, &next.id, |j| j.state.is_terminal()).await;
    assert_eq!(next.state, JobState::Succeeded);
    runner.shutdown(Duration::from_secs(5)).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn graceful_shutdown_requeues_at_once_and_spends_no_attempt() {
    let (_d, jobs, cx, runner) = setup().await;
    let j = submit_settings(&jobs, &cx, json!({ "sha": "s", "wait_ms": 5_000 })).await;
    let mut runner = runner;
    // Three graceful restarts while the job runs (max_attempts is 3): it is
    // never `interrupted` and never waits for a lease.
    for restart in 1..=3 {
        let running = wait_until(&cx, &j.id, |j| {
            j.state == JobState::Running && j.progress > 0.0
        })
        .await;
        assert_eq!(
            running.attempts, 1,
            "restart {restart}: one attempt, the current one"
        );
        runner.shutdown(Duration::from_secs(5)).await;
        let left = stored::get(&cx.db, &j.id).await.unwrap().unwrap();
        assert_eq!(
            left.state,
            JobState::Queued,
            "restart {restart}: queued again at once"
        );
        assert_eq!(
            left.attempts, 0,
            "restart {restart}: the attempt is given back"
        );
        assert!(left.error.is_none() && left.finished_at.is_none());
        assert!(left.stage.contains("queued again"), "{}", left.stage);
        assert!(!blob_exists(&cx, "s").await);
        // Nothing for recovery to do: no lease to wait for.
        assert_eq!(
            stored::recover(&cx.db).await.unwrap(),
            stored::Recovered::default()
        );
        runner = restart_runner(&cx).await;
    }
    runner.abort();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_computation_that_ignores_the_stop_is_requeued_and_its_lease_not_renewed() {
    let (_d, jobs, cx, runner) = setup().await;
    // Progress reports 2 s apart: the stop is noticed long after the grace.
    let j = submit_settings(&jobs, &cx, json!({ "sha": "slow", "wait_ms": 20_000 })).await;
    wait_until(&cx, &j.id, |j| {
        j.state == JobState::Running && j.progress > 0.0
    })
    .await;
    runner.shutdown(Duration::from_millis(100)).await;
    let left = stored::get(&cx.db, &j.id).await.unwrap().unwrap();
    assert_eq!(left.state, JobState::Queued);
    assert_eq!(left.attempts, 0);
    // Heartbeats (every 50 ms) would have revived it by now.
    tokio::time::sleep(Duration::from_millis(500)).await;
    let later = stored::get(&cx.db, &j.id).await.unwrap().unwrap();
    assert_eq!(later.state, JobState::Queued);
    assert_eq!(later.worker, None);
    // The next start claims it at once.
    let next = restart_runner(&cx).await;
    let again = wait_until(&cx, &j.id, |j| j.state == JobState::Running).await;
    assert_eq!(again.attempts, 1);
    next.abort();
}

/// A new runner over the same database (the process restarted).
async fn restart_runner(cx: &JobContext) -> RunnerHandle {
    start(writer_jobs(), cx.clone()).await.unwrap()
}
