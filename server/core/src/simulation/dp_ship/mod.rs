//! Fossen, Sagatun & Sørensen's supply vessel (1995): the 3-DOF
//! low-frequency DP model in surge, sway and yaw in the Bis system, with
//! thrusters τ = T″·K″·u, momentum h = M″·ν, a slowly varying bias b_h and
//! position/heading measurements — the truth the parallel EKF of
//! [`crate::estimation::ekf`] is proven against.
//!
//! - [`paper`]: the published numbers (eq. 29, 30, 48, 49, 51, 52).
//! - [`model`]: M, T, A_h, K, C(ν), J(ψ), θ″ ↔ (A_h, K), eq. 51–52.
//! - [`manoeuvres`]: the six decoupled manoeuvres (Fig. 5–7).
//! - [`trial`]: simulation of a run with bias and measurement noise.
//! - [`fly`]: a planned DP campaign flown and logged as SI CSV.

pub mod fly;
pub mod manoeuvres;
pub mod model;
pub mod paper;
pub mod trial;

#[cfg(test)]
mod tests;

pub use fly::{DpFlightSettings, FlownDpRun, fly_dp_campaign, fly_dp_experiment};
pub use manoeuvres::{Manoeuvre, manoeuvre_inputs};
pub use model::{DpShip, N_GROUPS, N_THETA, THETA_NAMES, ThrustLayout};
pub use trial::{DpRun, TrialConfig, simulate_campaign, simulate_trial};
