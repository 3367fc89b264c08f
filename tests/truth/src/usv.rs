//! A second, independent surface-vessel truth: the 3-DOF (surge, sway,
//! yaw) maneuvering model of Fossen (2021, *Handbook of Marine Craft
//! Hydrodynamics and Motion Control*, 2nd ed., ch. 6–8) with current,
//!
//!   M_RB ν̇ + M_A ν̇_r + C_RB(ν)ν + C_A(ν_r)ν_r + D_L ν_r + d_NL(ν_r) = τ,
//!   η̇ = R(ψ)ν,   ν_r = ν − ν_c,   ν_c = R(ψ)ᵀ[V_c cos β_c, V_c sin β_c, 0]ᵀ,
//!
//! flown on two published vessels — the Otter USV (Fossen's
//! PythonVehicleSimulator `otter.py`, MSS `otter.m`) and the supply vessel
//! of Fossen, Sagatun & Sørensen (1996) in SI (MSS `supply.m`) — through
//! logged sea-trial campaigns. Each physical effect is a switch
//! ([`Effects`]): the current (none, constant, slowly varying), quadratic
//! surge damping X_|u|u |u_r| u_r, strip-theory cross-flow drag with
//! Hoerner's 2-D drag coefficient, and C_A(ν_r)ν_r with its Munk moment
//! (Y_v̇ − X_u̇) u_r v_r. [`Effects::CLEAN`] keeps only D_L and C_RB.
//!
//! Written from the equations; it shares no code with `seatrial` or
//! `seatrial-core`, nor with this crate's 6-DOF plant (it reads
//! [`crate::dp_ship`]'s published Bis constants, [`crate::rng`] and
//! [`crate::signals`]' PRBS only).
//!
//! - [`model`]: the equations, M_RB, M_A, C_RB, C_A, D_L, d_NL, RK4.
//! - [`cross_flow`]: Hoerner's curve and the cross-flow integrals.
//! - [`current`]: constant and Gauss–Markov currents, ν_c and ν̇_c.
//! - [`vessels`]: the Otter and the supply vessel, ±20 % draws.
//! - [`signals`]: PRBS and held-level excitation.
//! - [`campaign`]: the trials and their CSV logs.

pub mod campaign;
pub mod cross_flow;
pub mod current;
pub mod model;
pub mod signals;
pub mod vessels;

#[cfg(test)]
mod tests;

pub use campaign::{
    COMMANDS_HEADER, FORCES_HEADER, Noise, SUBSTEPS, SUPPLY_RATE_HZ, SupplyTrial, SurfaceCampaign,
    SurfaceRun, USV_RATE_HZ, UsvLogged, UsvTrial, fly_supply_campaign, fly_usv_campaign,
    wrap_heading,
};
pub use cross_flow::{CrossFlow, HOERNER_CURVE, hoerner_cd};
pub use current::{Current, CurrentNow, CurrentTrack};
pub use model::{Effects, Simulator, SurfaceVessel};
pub use vessels::{OTTER_PROPELLER_Y_M, OTTER_T, OTTER_THRUST_N, otter, supply};
