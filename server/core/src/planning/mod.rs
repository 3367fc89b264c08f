//! Trial-campaign planning: vessel profiles, the LPV forward-speed grid,
//! experiment families (thesis ch. 3; Fossen et al. sec. 4.2), excitation
//! design per grid point × DOF × repetition, and the plan with its run order
//! and trial time.

pub mod analysis;
pub mod autopilot;
pub mod campaign;
pub mod deciding;
pub mod design;
pub mod dof;
mod dp_manoeuvres;
mod dynamic_runs;
pub mod error;
pub mod examples;
pub mod plan;
pub mod revision;
pub mod statics;
mod validation_run;
pub mod vessel;
pub mod waveform;

pub use autopilot::{Autopilot, AutopilotLoop, RestoringFeedForward};
pub use campaign::{CampaignSpec, ExperimentFamily, Quantity, SignalKind, SpeedGrid, SpeedUnit};
pub use dof::{Dof, KNOT};
pub use error::{MAX_NAME_LEN, PlanError, check_name};
pub use plan::{Experiment, Plan, PlanTotals, PlannedExperiment, Schedule, generate_plan};
pub use vessel::VesselProfile;

#[cfg(test)]
mod attitude_tests;
#[cfg(test)]
mod dp_layout_tests;
#[cfg(test)]
mod tests;
