//! seatrial: the service. Sea-trial system identification of ROVs and
//! dynamically positioned ships — plan campaigns, score runs, identify and
//! validate models. Numerics live in `seatrial-core`; this crate is the thin
//! layer of storage (SQLite via sqlx) and HTTP (axum).

pub mod clock;
pub mod coverage;
pub mod demo;
pub mod error;
pub mod http;
pub mod intake;
pub mod jobs;
pub mod processing;
pub mod runtime;
pub mod storage;
