//! The contract between the job machinery and one kind of job: check at
//! submission, load the inputs, compute on a blocking thread, persist the
//! output in the transaction that marks the job succeeded.

use std::future::Future;
use std::pin::Pin;

use seatrial_core::estimation::{Cancelled, Progress};
use sqlx::SqliteConnection;

use crate::error::ApiError;
use crate::storage::Db;
use crate::storage::blobs::BlobStore;
use crate::storage::jobs::{Job, JobError, JobRequest};

/// A boxed, `Send` future: async trait methods are not dyn-compatible.
pub type BoxFuture<'a, T> = Pin<Box<dyn Future<Output = T> + Send + 'a>>;

/// What handlers may read: the database and the uploaded files.
#[derive(Clone, Debug)]
pub struct JobContext {
    /// Database pool.
    pub db: Db,
    /// Uploaded files (run logs), content-addressed.
    pub blobs: BlobStore,
}

/// Why a computation did not produce an output.
#[derive(Debug)]
pub enum JobFailure {
    /// The progress sink said stop (a cancel request): the job ends `cancelled`.
    Cancelled,
    /// The job cannot be done (bad data, no convergence, …): it ends `failed`
    /// with this error; retry may queue it again.
    Failed(JobError),
}

impl JobFailure {
    /// A failure in plain words.
    pub fn new(message: impl Into<String>) -> Self {
        JobFailure::Failed(JobError::new(message))
    }

    /// A failure blamed on a request field (e.g. `settings.order`, `run_ids[2]`).
    pub fn field(field: impl Into<String>, message: impl Into<String>) -> Self {
        JobFailure::Failed(JobError {
            message: message.into(),
            field: Some(field.into()),
        })
    }
}

impl std::fmt::Display for JobFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            JobFailure::Cancelled => f.write_str("cancelled"),
            JobFailure::Failed(e) => f.write_str(&e.message),
        }
    }
}

/// `progress.update(..)?` inside a computation stops it on cancel.
impl From<Cancelled> for JobFailure {
    fn from(_: Cancelled) -> Self {
        JobFailure::Cancelled
    }
}

/// Database or I/O trouble while loading: the job fails with the cause.
impl From<anyhow::Error> for JobFailure {
    fn from(e: anyhow::Error) -> Self {
        JobFailure::new(format!("{e:#}"))
    }
}

impl From<sqlx::Error> for JobFailure {
    fn from(e: sqlx::Error) -> Self {
        JobFailure::new(format!("database error: {e}"))
    }
}

/// The output of a computation, able to store itself.
///
/// `persist` runs on a connection inside the transaction that also moves the
/// job to `succeeded`: what it writes (a model row, say) commits with that
/// state, or not at all. It returns the job's `result` JSON
/// (e.g. `{"model_id": "…"}`). Do not commit or begin a transaction on it.
pub trait Persist: Send {
    /// Stores the output; returns the job's result.
    fn persist<'a>(
        self: Box<Self>,
        conn: &'a mut SqliteConnection,
        job: &'a Job,
    ) -> BoxFuture<'a, anyhow::Result<serde_json::Value>>;
}

/// An output that is its own result and stores nothing else.
impl Persist for serde_json::Value {
    fn persist<'a>(
        self: Box<Self>,
        _conn: &'a mut SqliteConnection,
        _job: &'a Job,
    ) -> BoxFuture<'a, anyhow::Result<serde_json::Value>> {
        Box::pin(async move { Ok(*self) })
    }
}

/// The CPU work of one job, with its inputs owned: run on a blocking thread.
/// Call `progress.update(fraction, stage)?` between units of work.
pub type Compute =
    Box<dyn FnOnce(&mut dyn Progress) -> Result<Box<dyn Persist>, JobFailure> + Send>;

/// Wraps a closure as a [`Compute`] (its signature is inferred from the
/// bound, and the output is boxed for you).
pub fn compute<O, F>(f: F) -> Compute
where
    O: Persist + 'static,
    F: FnOnce(&mut dyn Progress) -> Result<O, JobFailure> + Send + 'static,
{
    Box::new(move |p: &mut dyn Progress| f(p).map(|o| Box::new(o) as Box<dyn Persist>))
}

/// One kind of job (`identify`, `discover`, …). See the [module
/// documentation](crate::jobs) for an example.
pub trait JobHandler: Send + Sync + 'static {
    /// At submission, before anything is queued: validate what only this
    /// kind knows — `method`, `settings`, `model_id`, whether the runs suit
    /// it. Return a 404 (`ApiError::missing`) or 422 (`ApiError::invalid`)
    /// naming the field. The generic checks have passed already: the kind
    /// exists, `settings` is an object, the campaign exists, every run exists,
    /// was accepted at upload and belongs to that campaign.
    fn check<'a>(
        &'a self,
        cx: &'a JobContext,
        request: &'a JobRequest,
    ) -> BoxFuture<'a, Result<(), ApiError>>;

    /// In the worker, async: read the runs, blobs and models the job needs
    /// into owned values and return the computation over them. Errors fail
    /// the job (the data may have changed since `check`).
    fn load<'a>(
        &'a self,
        cx: &'a JobContext,
        job: &'a Job,
    ) -> BoxFuture<'a, Result<Compute, JobFailure>>;
}
