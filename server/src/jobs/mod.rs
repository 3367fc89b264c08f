//! Persisted background jobs: identification, discovery and whatever else
//! takes longer than a request should.
//!
//! A job is a row of the `job` table ([`crate::storage::jobs`]) that moves
//! `queued → running → succeeded | failed | cancelled`, or `interrupted` when
//! the server died under it more often than `max_attempts` allows. The
//! [runner](runner) claims queued jobs (one worker per slot), computes on a
//! blocking thread, streams progress to subscribers ([`events`]) and to the
//! database about once a second ([`heartbeat`]), and records the end in one
//! transaction with what the handler stores.
//!
//! # Writing a handler
//!
//! A kind of job is a [`JobHandler`] registered under its name in the
//! [`JobRegistry`] built at start-up. It has three phases:
//!
//! 1. `check` (async, at `POST /api/jobs`): validate what only this kind
//!    knows and answer 404/422 naming the field; nothing is queued on error.
//! 2. `load` (async, in the worker): read what the job needs into owned
//!    values and return the [`Compute`] closure over them, which runs on a
//!    blocking thread and reports through
//!    [`Progress`](seatrial_core::estimation::Progress) — `?` on its result
//!    stops at a cancel.
//! 3. [`Persist`] (async): the computation's output stores itself on a
//!    connection inside the transaction that marks the job `succeeded`, and
//!    returns the job's `result` JSON.
//!
//! ```no_run
//! use seatrial::error::ApiError;
//! use seatrial::jobs::{BoxFuture, Compute, JobContext, JobFailure, JobHandler, JobRegistry, Persist};
//! use seatrial::storage::jobs::{Job, JobRequest};
//! use sqlx::SqliteConnection;
//!
//! /// Mean of each run's sample count (a stand-in for real numerics).
//! struct MeanRows;
//!
//! /// The output: stores a row and names it in the job's result.
//! struct Summary {
//!     mean: f64,
//! }
//!
//! impl Persist for Summary {
//!     fn persist<'a>(
//!         self: Box<Self>,
//!         conn: &'a mut SqliteConnection,
//!         job: &'a Job,
//!     ) -> BoxFuture<'a, anyhow::Result<serde_json::Value>> {
//!         Box::pin(async move {
//!             let id = seatrial::storage::new_id();
//!             sqlx::query("INSERT INTO summary (id, job_id, mean) VALUES ($1, $2, $3)")
//!                 .bind(&id)
//!                 .bind(&job.id)
//!                 .bind(self.mean)
//!                 .execute(&mut *conn)
//!                 .await?;
//!             Ok(serde_json::json!({ "summary_id": id }))
//!         })
//!     }
//! }
//!
//! impl JobHandler for MeanRows {
//!     fn check<'a>(&'a self, _cx: &'a JobContext, req: &'a JobRequest) -> BoxFuture<'a, Result<(), ApiError>> {
//!         Box::pin(async move {
//!             match req.method.as_deref() {
//!                 None | Some("mean") => Ok(()),
//!                 Some(m) => Err(ApiError::invalid("method", format!("unknown method '{m}'; use 'mean'"))),
//!             }
//!         })
//!     }
//!
//!     fn load<'a>(&'a self, cx: &'a JobContext, job: &'a Job) -> BoxFuture<'a, Result<Compute, JobFailure>> {
//!         Box::pin(async move {
//!             let mut sizes = Vec::new();
//!             for id in &job.request.run_ids {
//!                 let run = seatrial::storage::runs::get(&cx.db, id)
//!                     .await?
//!                     .ok_or_else(|| JobFailure::new(format!("run '{id}' was deleted")))?;
//!                 sizes.push(run.files.iter().map(|f| f.size_bytes as f64).sum::<f64>());
//!             }
//!             Ok(seatrial::jobs::compute(move |progress| {
//!                 let mut sum = 0.0;
//!                 for (i, s) in sizes.iter().enumerate() {
//!                     progress.update(i as f64 / sizes.len() as f64, "averaging")?;
//!                     sum += s;
//!                 }
//!                 Ok(Summary { mean: sum / sizes.len().max(1) as f64 })
//!             }))
//!         })
//!     }
//! }
//!
//! let registry = JobRegistry::new().with("mean-rows", MeanRows);
//! ```
//!
//! # Restarts
//!
//! A job survives the server: a row left `running` by a server that died
//! is queued again once its lease expires — it restarts from the beginning,
//! which its `stage` says, and counts one more attempt — or becomes
//! `interrupted` when its attempts are used up; `retry` queues it again. A
//! graceful shutdown neither cancels nor fails running jobs and spends no
//! attempt: it stops claiming and renewing leases, lets the computations
//! unwind, and queues their jobs again at once with the attempt given back
//! and no lease, so the next start claims them without waiting.

pub mod design;
pub mod discover;
pub mod events;
mod flown_autopilot;
pub mod handler;
pub mod heartbeat;
pub mod identify;
pub mod live;
pub mod next_dive;
pub mod precision;
pub mod progress;
pub mod registry;
pub mod run_inputs;
pub mod runner;
pub mod service;
pub mod submit;

pub use handler::{BoxFuture, Compute, JobContext, JobFailure, JobHandler, Persist, compute};
pub use progress::JobEvent;
pub use registry::JobRegistry;
pub use runner::{RunnerHandle, start};
pub use service::{Jobs, JobsConfig};
pub use submit::submit;

#[cfg(test)]
mod tests;
