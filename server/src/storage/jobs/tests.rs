use super::job::empty_object;
use super::*;

async fn db() -> (tempfile::TempDir, Db) {
    let dir = tempfile::tempdir().unwrap();
    let db = crate::storage::open(&dir.path().join("t.db"))
        .await
        .unwrap();
    (dir, db)
}

fn request() -> JobRequest {
    JobRequest {
        kind: "sum".into(),
        settings: empty_object(),
        ..Default::default()
    }
}

#[test]
fn timestamps_are_fixed_width_and_ordered() {
    let a = OffsetDateTime::from_unix_timestamp(1_800_000_000).unwrap();
    let b = a + time::Duration::milliseconds(5);
    let c = a + time::Duration::milliseconds(500);
    let (sa, sb, sc) = (timestamp(a), timestamp(b), timestamp(c));
    assert_eq!(sa, "2027-01-15T08:00:00.000Z");
    assert!(sa < sb && sb < sc);
    assert_eq!(sa.len(), sc.len());
    // Still RFC 3339.
    let rfc = time::format_description::well_known::Rfc3339;
    assert_eq!(OffsetDateTime::parse(&sb, &rfc).unwrap(), b);
}

#[tokio::test]
async fn concurrent_claims_take_each_job_once() {
    let (_d, db) = db().await;
    for _ in 0..20 {
        insert(&db, &request(), 3).await.unwrap();
    }
    let mut tasks = Vec::new();
    for w in 0..4 {
        let db = db.clone();
        tasks.push(tokio::spawn(async move {
            let mut got = Vec::new();
            let lease = std::time::Duration::from_secs(30);
            while let Some(j) = claim(&db, &format!("w{w}"), lease).await.unwrap() {
                got.push(j.id);
            }
            got
        }));
    }
    let mut all = Vec::new();
    for t in tasks {
        all.extend(t.await.unwrap());
    }
    let n = all.len();
    all.sort();
    all.dedup();
    assert_eq!((n, all.len()), (20, 20));
}

#[tokio::test]
async fn claim_takes_the_oldest_and_counts_the_attempt() {
    let (_d, db) = db().await;
    let first = insert(&db, &request(), 3).await.unwrap();
    insert(&db, &request(), 3).await.unwrap();
    let j = claim(&db, "w", std::time::Duration::from_secs(30))
        .await
        .unwrap()
        .unwrap();
    assert_eq!(j.id, first.id);
    assert_eq!((j.state, j.attempts), (JobState::Running, 1));
    assert_eq!(j.worker.as_deref(), Some("w"));
}

#[tokio::test]
async fn recovery_requeues_then_interrupts_expired_leases_only() {
    let (_d, db) = db().await;
    let j = insert(&db, &request(), 2).await.unwrap();
    let live = insert(&db, &request(), 2).await.unwrap();
    let zero = std::time::Duration::ZERO;
    let long = std::time::Duration::from_secs(60);
    claim(&db, "dead", zero).await.unwrap().unwrap();
    claim(&db, "alive", long).await.unwrap().unwrap();
    tokio::time::sleep(std::time::Duration::from_millis(5)).await;
    let r = recover(&db).await.unwrap();
    assert_eq!((r.requeued, r.interrupted), (1, 0));
    let again = get(&db, &j.id).await.unwrap().unwrap();
    assert_eq!(again.state, JobState::Queued);
    assert!(
        again.stage.contains("restarts from the beginning"),
        "{}",
        again.stage
    );
    assert_eq!(
        get(&db, &live.id).await.unwrap().unwrap().state,
        JobState::Running
    );
    // Second crash: attempts (2) reach max_attempts (2).
    claim(&db, "dead", zero).await.unwrap().unwrap();
    tokio::time::sleep(std::time::Duration::from_millis(5)).await;
    let r = recover(&db).await.unwrap();
    assert_eq!((r.requeued, r.interrupted), (0, 1));
    let gone = get(&db, &j.id).await.unwrap().unwrap();
    assert_eq!(gone.state, JobState::Interrupted);
    assert!(gone.error.is_some() && gone.finished_at.is_some());
    // Retry grants new attempts.
    let RetryOutcome::Queued(q) = retry(&db, &j.id, 2).await.unwrap() else {
        panic!("not retried")
    };
    assert_eq!(
        (q.state, q.attempts, q.max_attempts),
        (JobState::Queued, 2, 4)
    );
    assert!(q.error.is_none() && q.finished_at.is_none());
}

#[tokio::test]
async fn cancel_is_immediate_when_queued_and_flagged_when_running() {
    let (_d, db) = db().await;
    let running = insert(&db, &request(), 3).await.unwrap();
    let queued = insert(&db, &request(), 3).await.unwrap();
    let lease = std::time::Duration::from_secs(30);
    claim(&db, "w", lease).await.unwrap().unwrap();
    let CancelOutcome::Cancelled(c) = request_cancel(&db, &queued.id).await.unwrap() else {
        panic!("queued job not cancelled")
    };
    assert_eq!(c.state, JobState::Cancelled);
    let CancelOutcome::Requested(r) = request_cancel(&db, &running.id).await.unwrap() else {
        panic!("running job not flagged")
    };
    assert!(r.cancel_requested && r.state == JobState::Running);
    assert_eq!(
        heartbeat(&db, &running.id, "w", 0.5, "s", lease)
            .await
            .unwrap(),
        Heartbeat::CancelRequested
    );
    assert_eq!(
        heartbeat(&db, &running.id, "other", 0.5, "s", lease)
            .await
            .unwrap(),
        Heartbeat::Lost
    );
    assert!(matches!(
        request_cancel(&db, &queued.id).await.unwrap(),
        CancelOutcome::Finished(JobState::Cancelled)
    ));
    assert!(matches!(
        request_cancel(&db, "nope").await.unwrap(),
        CancelOutcome::NotFound
    ));
}

#[tokio::test]
async fn finish_refuses_a_job_that_is_no_longer_the_workers() {
    let (_d, db) = db().await;
    let j = insert(&db, &request(), 3).await.unwrap();
    claim(&db, "w", std::time::Duration::from_secs(30))
        .await
        .unwrap();
    let mut conn = db.acquire().await.unwrap();
    let ok = Finish::Succeeded(serde_json::json!({"x": 1}));
    assert!(
        !finish(&mut conn, &j.id, "other", &ok, 0.5, "s")
            .await
            .unwrap()
    );
    assert!(finish(&mut conn, &j.id, "w", &ok, 0.5, "s").await.unwrap());
    let done = get(&db, &j.id).await.unwrap().unwrap();
    assert_eq!((done.state, done.progress), (JobState::Succeeded, 1.0));
    assert_eq!(done.result, Some(serde_json::json!({"x": 1})));
    assert!(!finish(&mut conn, &j.id, "w", &ok, 0.5, "s").await.unwrap());
}

#[tokio::test]
async fn list_filters_by_campaign_and_state() {
    let (_d, db) = db().await;
    let a = insert(&db, &request(), 3).await.unwrap();
    insert(&db, &request(), 3).await.unwrap();
    request_cancel(&db, &a.id).await.unwrap();
    assert_eq!(list(&db, None, None).await.unwrap().len(), 2);
    let c = list(&db, None, Some(JobState::Cancelled)).await.unwrap();
    assert_eq!(c.len(), 1);
    assert_eq!(c[0].id, a.id);
    assert!(list(&db, Some("x"), None).await.unwrap().is_empty());
    assert!(
        list(&db, Some("x"), Some(JobState::Queued))
            .await
            .unwrap()
            .is_empty()
    );
}
