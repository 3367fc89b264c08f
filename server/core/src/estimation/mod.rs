//! Parameter and model estimation from sea-trial runs.
//!
//! - [`restoring`]: W−B, z_G·W−z_B·B and the tether moment from static runs
//!   (thesis eq. 2.1–2.4), giving g(η) for γ = τ − g(η).
//! - [`lambda`]: continuous-time Kalman-filter identification through the
//!   state-variable filter λ(s) = 1/(1+sT) (thesis eq. 1.9–1.10, 2.9–2.15,
//!   app. 7.1), diagonal or coupled, one sub-model per LPV grid point.
//! - [`ekf`]: the state-augmented EKF run in parallel over N runs, in momentum
//!   form with a bias state, staged SI1→SI2→SI3 (Fossen et al. 1995).
//! - [`n4sid`]: subspace identification by LQ of the block-Hankel data.
//!
//! Several runs are always a multi-experiment set (each with its own initial
//! state), never concatenated.

pub mod ekf;
pub mod lambda;
pub mod n4sid;
pub mod progress;
pub mod restoring;

pub use progress::{Cancelled, NoProgress, Progress, SubProgress};
