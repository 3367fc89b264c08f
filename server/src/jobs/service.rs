//! The handle the HTTP layer and the runner share: registry, settings,
//! running jobs, the wake-up for idle workers and the shutdown signal.

use std::sync::Arc;
use std::time::Duration;

use tokio::sync::Notify;
use tokio_util::sync::CancellationToken;

use super::live::LiveJobs;
use super::registry::JobRegistry;

/// Settings of the job runner.
#[derive(Debug, Clone)]
pub struct JobsConfig {
    /// Jobs computed at once (each takes a blocking thread and about a core).
    pub workers: usize,
    /// A running job belongs to its worker this long past its last heartbeat;
    /// after that, recovery may queue it again.
    pub lease: Duration,
    /// Progress to the database, lease renewal and the cancel poll, this often.
    pub heartbeat: Duration,
    /// Attempts (first run + restarts after a server died mid-run) before a
    /// job is `interrupted`; also what `retry` grants again.
    pub max_attempts: i64,
    /// Idle workers look for jobs queued by other processes this often
    /// (jobs queued here wake them at once).
    pub poll: Duration,
}

impl Default for JobsConfig {
    fn default() -> Self {
        JobsConfig {
            workers: default_workers(),
            lease: Duration::from_secs(30),
            heartbeat: Duration::from_secs(1),
            max_attempts: 3,
            poll: Duration::from_secs(2),
        }
    }
}

/// One worker per core but one, at least one: the HTTP side keeps a core
/// (1 on a 2-core machine).
pub fn default_workers() -> usize {
    std::thread::available_parallelism()
        .map_or(1, |n| n.get().saturating_sub(1))
        .max(1)
}

struct Inner {
    registry: JobRegistry,
    config: JobsConfig,
    live: LiveJobs,
    wake: Notify,
    shutdown: CancellationToken,
}

/// Shared job machinery (cheap to clone).
#[derive(Clone)]
pub struct Jobs {
    inner: Arc<Inner>,
}

impl Jobs {
    /// Jobs of the registered kinds.
    pub fn new(registry: JobRegistry, config: JobsConfig) -> Self {
        Jobs {
            inner: Arc::new(Inner {
                registry,
                config,
                live: LiveJobs::default(),
                wake: Notify::new(),
                shutdown: CancellationToken::new(),
            }),
        }
    }

    /// The kinds this server runs.
    pub fn registry(&self) -> &JobRegistry {
        &self.inner.registry
    }

    /// Settings.
    pub fn config(&self) -> &JobsConfig {
        &self.inner.config
    }

    /// Jobs running in this process.
    pub fn live(&self) -> &LiveJobs {
        &self.inner.live
    }

    /// A job was queued: wake an idle worker.
    pub fn wake(&self) {
        self.inner.wake.notify_one();
    }

    pub(crate) async fn woken(&self) {
        self.inner.wake.notified().await;
    }

    /// Cancelled when the server shuts down: workers stop claiming, running
    /// computations unwind without recording anything, event streams end.
    pub fn shutdown_token(&self) -> &CancellationToken {
        &self.inner.shutdown
    }
}

impl std::fmt::Debug for Jobs {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Jobs")
            .field("registry", &self.inner.registry)
            .field("config", &self.inner.config)
            .field("running_here", &self.inner.live.len())
            .finish()
    }
}
