//! A job's events as a stream: from the watch channel while it runs in this
//! process, from the database otherwise (queued, or running in another
//! process); it ends after a terminal state, or at shutdown.

use std::time::Duration;

use futures_util::{Stream, StreamExt};
use tokio::sync::watch;

use super::progress::JobEvent;
use super::service::Jobs;
use crate::storage::jobs::JobState;
use crate::storage::{Db, jobs};

/// Fastest event rate per subscriber (progress coalesces in between).
const MIN_GAP: Duration = Duration::from_millis(100);
/// How often the database is read when the job does not run here.
const POLL: Duration = Duration::from_millis(250);

struct Follow {
    jobs: Jobs,
    db: Db,
    id: String,
    live: Option<watch::Receiver<JobEvent>>,
    last: Option<JobEvent>,
    done: bool,
}

/// The events of job `id` (which must exist), starting with its current state.
pub fn follow(jobs: Jobs, db: Db, id: String) -> impl Stream<Item = JobEvent> + Send + 'static {
    let shutdown = jobs.shutdown_token().clone().cancelled_owned();
    let start = Follow {
        jobs,
        db,
        id,
        live: None,
        last: None,
        done: false,
    };
    futures_util::stream::unfold(start, next).take_until(shutdown)
}

async fn next(mut f: Follow) -> Option<(JobEvent, Follow)> {
    if f.done {
        return None;
    }
    if f.last.is_some() {
        tokio::time::sleep(MIN_GAP).await;
    }
    loop {
        let event = if let Some(rx) = &mut f.live {
            if f.last.is_some() && rx.changed().await.is_err() {
                // The job stopped running here: its end is in the database.
                f.live = None;
                continue;
            }
            rx.borrow_and_update().clone()
        } else if let Some(rx) = f.jobs.live().subscribe(&f.id) {
            f.live = Some(rx);
            if f.last.is_none() {
                continue;
            }
            // Already sent something: wait for news from the channel.
            let rx = f.live.as_mut()?;
            rx.borrow_and_update().clone()
        } else {
            match jobs::get(&f.db, &f.id).await {
                Ok(Some(j)) => JobEvent::from(&j),
                Ok(None) => return None,
                Err(e) => {
                    tracing::warn!(job = %f.id, error = %e, "reading a job for its events failed");
                    tokio::time::sleep(POLL).await;
                    continue;
                }
            }
        };
        let event = monotone(f.last.as_ref(), event);
        if f.last.as_ref() == Some(&event) {
            if f.live.is_none() {
                tokio::time::sleep(POLL).await;
            }
            continue;
        }
        f.done = event.state.is_terminal();
        f.last = Some(event.clone());
        return Some((event, f));
    }
}

/// Progress never goes backwards within one running attempt: a reading of
/// the database (its heartbeat lags the live channel) or a stage that
/// reports from zero again keeps the highest fraction already sent. A new
/// attempt (queued again, then running) starts over.
fn monotone(last: Option<&JobEvent>, mut e: JobEvent) -> JobEvent {
    if let Some(l) = last
        && l.state == e.state
        && e.state == JobState::Running
        && e.progress < l.progress
    {
        e.progress = l.progress;
    }
    e
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ev(state: JobState, progress: f64, stage: &str) -> JobEvent {
        JobEvent {
            state,
            progress,
            stage: stage.into(),
        }
    }

    #[test]
    fn progress_never_goes_backwards_while_running() {
        let mut last: Option<JobEvent> = None;
        let mut sent = Vec::new();
        for e in [
            ev(JobState::Queued, 0.0, "queued"),
            ev(JobState::Running, 0.39, "fit"),
            ev(JobState::Running, 0.36, "fit"),
            ev(JobState::Running, 1.0, "fit"),
            ev(JobState::Running, 0.79, "store"),
            ev(JobState::Queued, 0.0, "retry"),
            ev(JobState::Running, 0.1, "fit"),
        ] {
            let e = monotone(last.as_ref(), e);
            sent.push(e.progress);
            last = Some(e);
        }
        assert_eq!(sent, [0.0, 0.39, 0.39, 1.0, 1.0, 0.0, 0.1]);
    }
}
