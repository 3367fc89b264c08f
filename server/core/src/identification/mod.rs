//! Campaign identification: from stored runs (records plus what the plan says
//! they were) to a validated model document. Pure orchestration over the
//! estimators of [`crate::estimation`] and [`crate::validation`].
//!
//! - [`discover_campaign`]: missing-physics discovery on a stored LPV model,
//!   per grid speed, and the augmented model as its next version.
//! - [`attitude_loop`]: a 6-DOF LPV model with g(η) of its own attitude in
//!   the loop (free runs keep the restoring spring).
//! - [`augmented`]: an LPV model with discovered terms as a predictor.
//! - [`dataset`]: runs → segments (one per valid block, never concatenated).
//! - [`describe`]: what a run is (role, grid speed, excited DOFs, signal),
//!   inferred from its data; [`description`]: that, the plan and the
//!   supervisor's word merged, each value with its source.
//! - [`roles`]: static, estimation and held-out validation runs.
//! - [`lambda_campaign`]: LPV model by the λ-filter Kalman method;
//!   [`intersample`]: M and D̄ corrected for a controller faster than its log.
//! - [`n4sid_campaign`]: black-box LTI comparison model by N4SID.
//! - [`ekf_campaign`]: DP ship by the staged parallel EKF (Bis units: [`bis`]).
//! - [`document`]: the stored/served model: matrices, parameters with std.
//! - [`discrete`]: ZOH matrices at a chosen h.
//! - [`export`]: parameter CSV and the Fossen-form parameter set.
//! - [`predictor`]: a stored model back as a predictor; validation on any run.
//! - [`state_space`]: an N4SID model's restarted free runs from its Kalman
//!   predictor state.
//! - [`outcome`], [`error`]: what an identification returns.

mod attitude_fusion;
pub mod attitude_loop;
pub mod augmented;
pub mod autopilot_fit;
pub mod bis;
pub mod dataset;
pub mod describe;
pub mod description;
pub mod discover_campaign;
pub mod discover_gate;
pub mod discrete;
pub mod document;
pub mod ekf_campaign;
pub mod ekf_checks;
pub mod ekf_init;
pub mod ekf_layout;
mod ekf_refine;
mod ekf_settings;
pub mod error;
pub mod export;
pub mod export_mat;
pub mod export_matlab;
pub mod export_npz;
pub mod export_state_space;
pub mod export_terms;
pub mod heading_loop;
pub mod intersample;
mod joint_restoring;
pub mod lambda_campaign;
mod lambda_consistency;
mod lambda_coriolis;
mod lambda_data;
mod lambda_extension;
pub mod lambda_information;
mod lambda_known;
mod lambda_noise;
mod lambda_physical;
mod lambda_quadratic;
mod lambda_settings;
mod lambda_structure;
mod lambda_submodels;
mod lambda_unforced;
mod lambda_validation;
pub mod mat;
pub mod n4sid_campaign;
mod ned_current;
pub mod npz;
pub mod outcome;
pub mod predictor;
pub mod roles;
pub mod state_space;
mod through_water;
mod velocity_noise;

pub use dataset::{DatasetError, RunInput, Segment, segments};
pub use describe::{DescribeError, DofActivity, InferredDescription, infer_description};
pub use description::{
    PlanDescription, RunDescription, RunRole, RunSignal, Source, UserDescription, describe_run,
};
pub use discover_campaign::{CampaignDiscovery, DiscoverCampaignSettings, discover_campaign};
pub use document::{Method, ModelDocument, ModelKind, ParameterRow};
pub use ekf_campaign::{EkfCampaignSettings, identify_ekf_campaign};
pub use error::IdentifyError;
pub use lambda_campaign::{LambdaCampaignSettings, identify_lambda_campaign};
pub use n4sid_campaign::{N4sidCampaignSettings, identify_n4sid_campaign};
pub use outcome::{Identified, RunValidation};

#[cfg(test)]
mod tests;
