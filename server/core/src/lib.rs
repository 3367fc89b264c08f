//! Pure numerics for sea-trial system identification of ROVs and DP ships.
//!
//! No I/O, no async, no database: plain functions and types over vectors and
//! matrices, in the spirit of `scipy.signal` and `python-control`. The service
//! (`seatrial`) parses, calls into this crate, stores and responds.
//!
//! Map of the domain:
//! - [`signals`]: excitation signals (PRBS, square wave, multisine), shaping to
//!   actuator limits, persistence of excitation.
//! - [`spectra`]: Welch PSD, cross-PSD, coherence, transfer-function estimates
//!   with `scipy.signal`'s definitions.
//! - [`planning`]: vessel profiles, LPV speed grid, experiment families and the
//!   campaign plan.
//! - [`models`]: state-space and Fossen-form vessel models (M, D, C(ν), g(η)),
//!   ZOH discretization, LPV models scheduled on forward speed.
//! - [`simulation`]: truth simulators (6-DOF ROV, 3-DOF DP ship) that the
//!   estimators are proven against.
//! - [`estimation`]: restoring forces, λ-filter Kalman identification,
//!   parallel state-augmented EKF, N4SID.
//! - [`validation`]: prediction and simulation NRMSE, divergence, residual tests.
//! - [`responses`]: a model's Bode, poles and zeros, step and impulse
//!   responses, Hankel singular values (for the plots).
//! - [`traces`]: a record decimated for a time plot, statistics of a window.
//! - [`numbers`]: numbers in sentences (three significant digits, units).
//! - [`discrepancy`]: missing-physics discovery — locate where a model and
//!   the recordings part, name the left-out physics, model it.

pub mod alignment;
pub mod design;
pub mod discrepancy;
pub mod estimation;
pub mod identification;
pub mod kernels;
pub mod logs;
pub mod models;
pub mod numbers;
mod par;
pub mod planning;
pub mod quality;
pub mod responses;
pub mod rng;
pub mod signals;
pub mod simulation;
pub mod spectra;
pub mod timeseries;
pub mod traces;
pub mod validation;
