//! A job's events as a stream: from the watch channel while it runs in this
//! process, from the database otherwise (queued, or running in another
//! process); it ends after a terminal state, or at shutdown.

use std::time::Duration;

use futures_util::{Stream, StreamExt};
use tokio::sync::watch;

use super::progress::JobEvent;
use super::service::Jobs;
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
