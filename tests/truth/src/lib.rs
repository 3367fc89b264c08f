//! # seatrial-truth
//!
//! An independent truth for seatrial's tests: a 6-DOF ROV plant written from
//! Fossen, *Handbook of Marine Craft Hydrodynamics and Motion Control* (2011),
//!
//!   M ν̇_r + C_RB(ν)ν + C_A(ν_r)ν_r + D(ν_r)ν_r + g(η) = τ,  η̇ = J(η)ν,
//!
//! flown by another team's 20 Hz autopilot, logged at 10 Hz the way the
//! Surveyor ROV trials were (every second command), through a campaign of
//! static, dynamic and validation runs. It shares no code with `seatrial`
//! or `seatrial-core` (nalgebra and std only): its own RNG, kinematics,
//! forces and RK4.
//!
//! [`dp_ship`] adds a DP surface vessel (Fossen, Sagatun & Sørensen 1995)
//! flown through decoupled manoeuvres and logged position-only at 1 Hz;
//! [`dp_layouts`] flies the same hull with a four-thruster layout, or logs
//! the commanded generalized forces instead of the thruster commands.
//!
//! Conventions: NED/body frames, SI and radians; z and w positive down;
//! g(η) on the left-hand side (a heavy vessel, W − B > 0, has g_Z < 0);
//! clock offset: nav t + offset = control t; ψ is logged wrapped to (−π, π].

pub mod campaign;
pub mod controller;
pub mod dp_layouts;
pub mod dp_ship;
pub mod forces;
pub mod json;
pub mod kinematics;
pub mod linearization;
pub mod plant;
pub mod predict;
pub mod rng;
pub mod signals;
pub mod usv;
pub mod vessel;
mod vessel_draw;

pub use campaign::{
    Campaign, CampaignSpec, Channel, Dof, ExternalRun, Log, NavLog, NoiseSpec, Role, Run, RunMeta,
    TruthRecord, campaign_as_external, external_envelope, fly_campaign, fly_external,
    fly_external_campaign, fly_external_runs, run_seed,
};
pub use linearization::{
    Linearization, effective_linearization, effective_linearization_given_quadratic,
};
pub use plant::{Plant, State};
pub use predict::{
    TruePredictions, free_run, free_run_restarted, predict_k_step, true_predictions,
};
pub use signals::SignalKind;
pub use vessel::{Actuator, Vessel};
pub use vessel_draw::{DAMPING_REFERENCE_SPEED, DIRECTIONAL_MARGIN};
