//! Truth simulators: the known systems every estimator is tested against.
//!
//! - [`integrate`]: fixed-step RK4 with zero-order-hold inputs.
//! - [`exponential`]: ETDRK4 for models with a stiff linear part.
//! - [`rov`]: a 6-DOF ROV, M·ν̇ + C(ν)ν + D(ν)ν + g(η) = τ, with optional
//!   effects (quadratic damping, current, tether, actuator lag, delay,
//!   saturation) that a baseline model may leave out.
//! - [`dp_ship`]: Fossen's supply vessel, 3-DOF low-frequency model in surge,
//!   sway and yaw with thrusters τ = T·K·u (Fossen et al. 1995, eq. 26–30).

pub mod dp_ship;
pub mod exponential;
pub mod integrate;
pub mod rov;
pub mod trials;
