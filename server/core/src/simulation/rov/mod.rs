//! The 6-DOF ROV truth simulator that estimators (and, later, missing-physics
//! discovery) are proven against:
//!
//! M ν̇_r + C(ν_r)ν_r + D_l(u_r)ν_r + D_q(ν_r)ν_r + g(η) = τ_a + τ_t,
//! η̇ = J(η)ν, ν = ν_r + ν_c,
//!
//! with every effect beyond M ν̇ + D_l ν + g(η) = τ off by default.
//!
//! - [`params`]: [`RovTruth`] (M, damping, Coriolis switch, restoring,
//!   tether, current, actuators) and [`RovTruth::surveyor_like`].
//! - [`damping`]: speed-scheduled coupled D_l and diagonal quadratic D_q.
//! - [`restoring`]: g(η) from W, B, r_G, r_B (Fossen 2011, eq. 4.6).
//! - [`current`]: constant or Gauss–Markov ocean current in NED.
//! - [`actuators`]: delay, dead zone, saturation, first-order lag.
//! - [`kinematics`]: J(η) for zyx Euler angles.
//! - [`simulate`]: [`SimConfig`] and [`RovTruth::simulate`] (RK4, ZOH input,
//!   seeded measurement noise).
//! - [`record`]: [`RovRecord`] and its CSV in the log column convention.
//! - [`error`] holds [`SimError`], which names the field at fault.

pub mod actuators;
pub mod current;
pub mod damping;
pub mod error;
pub mod kinematics;
pub mod params;
pub mod record;
pub mod restoring;
pub mod simulate;
#[cfg(test)]
mod tests;

pub use actuators::Actuators;
pub use current::{Current, RandomWalkCurrent};
pub use damping::LinearDamping;
pub use error::SimError;
pub use params::{RovTruth, Tether};
pub use record::RovRecord;
pub use restoring::Restoring;
pub use simulate::SimConfig;
