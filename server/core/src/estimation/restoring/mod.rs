//! Restoring forces and the tether moment from static runs (thesis sec.
//! 2.5, eq. 2.1–2.8).
//!
//! With all velocities zero the model M·ν̇ + (C(ν) + D(ν))·ν + g(η) = τ
//! (eq. 1.3) reduces to τ = g(η) (eq. 2.1). Holding station at several
//! pitch and roll angles and recording the thrust needed gives W − B,
//! z_G·W − z_B·B and the tether's constant pitch moment τ_θ (eq. 1.6) by
//! least squares; γ = τ − g(η) (eq. 2.8) is then the input of the dynamic
//! identification.
//!
//! - [`segments`]: steady segments found automatically (ν ≈ 0, constant
//!   attitude and τ for a few seconds);
//! - [`fit`]: the least-squares estimate with standard deviations and the
//!   identifiability check;
//! - [`params`]: g(η) and γ for the estimated parameters.

pub mod error;
pub mod fit;
pub mod params;
pub mod segments;

#[cfg(test)]
mod tests;

pub use error::RestoringError;
pub use fit::{RestoringEstimate, RestoringSettings, estimate_restoring, fit_restoring};
pub use params::RestoringParams;
pub use segments::{StaticRecord, SteadySegment, SteadySettings, find_steady_segments};
