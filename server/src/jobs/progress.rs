//! The `Progress` sink a running job's computation reports to: it publishes
//! to a watch channel (read by SSE and the heartbeat) and says stop when the
//! job is cancelled or abandoned.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use seatrial_core::estimation::{Cancelled, Progress};
use serde::Serialize;
use tokio::sync::{Notify, watch};
use tokio_util::sync::CancellationToken;

use crate::storage::jobs::{Job, JobState};

/// A job's state as streamed by `GET /api/jobs/{id}/events`.
#[derive(Debug, Clone, PartialEq, Serialize, utoipa::ToSchema)]
pub struct JobEvent {
    /// Lifecycle state; the stream ends after a terminal one.
    pub state: JobState,
    /// Fraction done of the current attempt, 0–1.
    pub progress: f64,
    /// What the job is doing.
    pub stage: String,
}

impl From<&Job> for JobEvent {
    fn from(j: &Job) -> Self {
        JobEvent {
            state: j.state,
            progress: j.progress,
            stage: j.stage.clone(),
        }
    }
}

/// Why a running computation should stop.
#[derive(Debug, Default)]
pub struct StopFlags {
    /// Someone asked to cancel (this process's endpoint, or the database flag
    /// another process set, read by the heartbeat): the job ends `cancelled`.
    pub cancel: AtomicBool,
    /// The job is no longer ours (lease lost): stop and record nothing.
    pub lost: AtomicBool,
}

impl StopFlags {
    /// Flags starting with a cancel already requested (or not).
    pub fn new(cancel: bool) -> Self {
        StopFlags {
            cancel: AtomicBool::new(cancel),
            lost: AtomicBool::new(false),
        }
    }

    /// Cancel requested.
    pub fn cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }

    /// Lease lost.
    pub fn is_lost(&self) -> bool {
        self.lost.load(Ordering::Relaxed)
    }
}

/// The sink handed to `Compute`.
pub struct JobProgress {
    events: watch::Sender<JobEvent>,
    flags: Arc<StopFlags>,
    /// The runner is shutting down: unwind, record nothing (recovery re-queues).
    shutdown: CancellationToken,
    stage_changed: Arc<Notify>,
}

impl JobProgress {
    /// A sink publishing to `events`.
    pub fn new(
        events: watch::Sender<JobEvent>,
        flags: Arc<StopFlags>,
        shutdown: CancellationToken,
        stage_changed: Arc<Notify>,
    ) -> Self {
        JobProgress {
            events,
            flags,
            shutdown,
            stage_changed,
        }
    }
}

impl Progress for JobProgress {
    fn update(&mut self, fraction: f64, stage: &str) -> Result<(), Cancelled> {
        let mut new_stage = false;
        self.events.send_if_modified(|e| {
            // Monotone: a stage that counts from zero again never shows
            // the engineer a bar going backwards.
            let f = if fraction.is_finite() {
                fraction.clamp(0.0, 1.0).max(e.progress)
            } else {
                e.progress
            };
            new_stage = e.stage != stage;
            if new_stage {
                e.stage = stage.to_string();
            }
            let changed = new_stage || e.progress != f;
            e.progress = f;
            changed
        });
        if new_stage {
            // The heartbeat writes stage changes to the database at once.
            self.stage_changed.notify_one();
        }
        if self.flags.cancelled() || self.flags.is_lost() || self.shutdown.is_cancelled() {
            Err(Cancelled)
        } else {
            Ok(())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn publishes_clamped_monotone_progress_and_stops_on_any_flag() {
        let (tx, rx) = watch::channel(JobEvent {
            state: JobState::Running,
            progress: 0.0,
            stage: "loading".into(),
        });
        let flags = Arc::new(StopFlags::new(false));
        let token = CancellationToken::new();
        let notify = Arc::new(Notify::new());
        let mut p = JobProgress::new(tx, flags.clone(), token.clone(), notify);
        assert!(p.update(0.25, "fit").is_ok());
        assert_eq!(rx.borrow().progress, 0.25);
        assert_eq!(rx.borrow().stage, "fit");
        assert!(p.update(7.0, "fit").is_ok());
        assert_eq!(rx.borrow().progress, 1.0);
        assert!(p.update(f64::NAN, "fit").is_ok());
        assert_eq!(rx.borrow().progress, 1.0);
        assert!(p.update(0.3, "store").is_ok());
        assert_eq!(rx.borrow().progress, 1.0, "never backwards");
        assert_eq!(rx.borrow().stage, "store");
        flags.cancel.store(true, Ordering::Relaxed);
        assert_eq!(p.update(1.0, "fit"), Err(Cancelled));
        flags.cancel.store(false, Ordering::Relaxed);
        token.cancel();
        assert_eq!(p.update(1.0, "fit"), Err(Cancelled));
    }
}
