//! The runner end to end on a real database: the handler's writes commit
//! with the job's end or not at all; panics fail the job; a graceful
//! shutdown records nothing and leaves the job to recovery.

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
    let jobs = Jobs::new(
        JobRegistry::new().with("write", Writer),
        JobsConfig {
            workers: 1,
            lease: Duration::from_secs(5),
            heartbeat: Duration::from_millis(50),
            max_attempts: 3,
            poll: Duration::from_millis(50),
        },
    );
    let runner = start(jobs.clone(), cx.clone()).await.unwrap();
    (dir, jobs, cx, runner)
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
async fn graceful_shutdown_records_nothing_and_recovery_requeues_at_once() {
    let (_d, jobs, cx, runner) = setup().await;
    let j = submit_settings(&jobs, &cx, json!({ "sha": "s", "wait_ms": 20_000 })).await;
    wait_until(&cx, &j.id, |j| {
        j.state == JobState::Running && j.progress > 0.0
    })
    .await;
    runner.shutdown(Duration::from_secs(5)).await;
    let left = stored::get(&cx.db, &j.id).await.unwrap().unwrap();
    assert_eq!(
        left.state,
        JobState::Running,
        "neither cancelled nor failed"
    );
    assert!(left.error.is_none() && left.finished_at.is_none());
    assert!(!blob_exists(&cx, "s").await);
    // The lease was ended: the next start's recovery takes it back at once.
    let r = stored::recover(&cx.db).await.unwrap();
    assert_eq!(r.requeued, 1);
    assert_eq!(
        stored::get(&cx.db, &j.id).await.unwrap().unwrap().state,
        JobState::Queued
    );
}
