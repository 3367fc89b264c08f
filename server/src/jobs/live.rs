//! Jobs running in this process: their latest event (for SSE and fresh
//! progress) and their stop flags (for an in-process cancel).

use std::collections::HashMap;
use std::sync::atomic::Ordering;
use std::sync::{Arc, Mutex};

use tokio::sync::watch;

use super::progress::{JobEvent, StopFlags};

struct Entry {
    events: watch::Receiver<JobEvent>,
    flags: Arc<StopFlags>,
}

/// Running jobs of this process, by id.
#[derive(Clone, Default)]
pub struct LiveJobs {
    inner: Arc<Mutex<HashMap<String, Entry>>>,
}

impl LiveJobs {
    fn map(&self) -> std::sync::MutexGuard<'_, HashMap<String, Entry>> {
        // A panic while holding this short lock leaves the map consistent.
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Registers a job that starts running here.
    pub fn insert(&self, id: &str, events: watch::Receiver<JobEvent>, flags: Arc<StopFlags>) {
        self.map().insert(id.to_string(), Entry { events, flags });
    }

    /// The job stopped running here.
    pub fn remove(&self, id: &str) {
        self.map().remove(id);
    }

    /// Follows a job running here.
    pub fn subscribe(&self, id: &str) -> Option<watch::Receiver<JobEvent>> {
        self.map().get(id).map(|e| e.events.clone())
    }

    /// The latest event of a job running here.
    pub fn latest(&self, id: &str) -> Option<JobEvent> {
        self.map().get(id).map(|e| e.events.borrow().clone())
    }

    /// Asks a job running here to stop at its next progress report.
    /// `false` when it does not run here (the heartbeat of the process that
    /// runs it reads the database flag instead).
    pub fn cancel(&self, id: &str) -> bool {
        match self.map().get(id) {
            Some(e) => {
                e.flags.cancel.store(true, Ordering::Relaxed);
                true
            }
            None => false,
        }
    }

    /// How many jobs run here.
    pub fn len(&self) -> usize {
        self.map().len()
    }

    /// None run here.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}
