//! While a job runs: its progress to the database (about once a second and
//! at once on a stage change), its lease renewed, and the database's
//! `cancel_requested` read back, so a cancel sent to another process works.

use std::convert::Infallible;
use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::time::Duration;

use tokio::sync::{Notify, watch};
use tokio_util::sync::CancellationToken;

use super::progress::{JobEvent, StopFlags};
use crate::storage::Db;
use crate::storage::jobs::{self, Heartbeat};

/// Stage changes faster than this are written together.
const MIN_GAP: Duration = Duration::from_millis(100);

/// Whose heartbeat, and how often.
pub struct Beat {
    /// Database.
    pub db: Db,
    /// The job.
    pub id: String,
    /// The worker holding it.
    pub worker: String,
    /// Interval.
    pub every: Duration,
    /// Lease granted at each beat.
    pub lease: Duration,
    /// The server's stop: no lease is renewed after it (the job is queued
    /// again by the graceful shutdown, or recovered after the lease).
    pub stop: CancellationToken,
}

/// Runs until dropped (the runner drops it when the computation returns).
pub async fn run(
    beat: Beat,
    events: watch::Receiver<JobEvent>,
    flags: Arc<StopFlags>,
    stage_changed: Arc<Notify>,
) -> Infallible {
    let Beat {
        db,
        id,
        worker,
        every,
        lease,
        stop,
    } = beat;
    let mut tick = tokio::time::interval(every);
    tick.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
    loop {
        tokio::select! {
            _ = tick.tick() => {}
            () = stage_changed.notified() => {}
            () = stop.cancelled() => return std::future::pending().await,
        }
        if stop.is_cancelled() {
            return std::future::pending().await;
        }
        let e = events.borrow().clone();
        match jobs::heartbeat(&db, &id, &worker, e.progress, &e.stage, lease).await {
            Ok(Heartbeat::Continue) => {}
            Ok(Heartbeat::CancelRequested) => flags.cancel.store(true, Ordering::Relaxed),
            Ok(Heartbeat::Lost) => {
                tracing::warn!(job = %id, %worker, "lease lost (the job was recovered elsewhere); abandoning it");
                flags.lost.store(true, Ordering::Relaxed);
                return std::future::pending().await;
            }
            // A busy or briefly unreachable database: the lease has slack.
            Err(err) => tracing::warn!(job = %id, error = %err, "heartbeat failed"),
        }
        tokio::time::sleep(MIN_GAP).await;
    }
}
