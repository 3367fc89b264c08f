//! Off-line parallel state-augmented EKF identification (Fossen, Sagatun &
//! Sørensen 1995, "Identification of dynamically positioned ships").
//!
//! - [`model`]: the run-model interface x(k+1) = f(x, u, θ), z = H·x, and
//!   exact RK4 discretization of continuous models.
//! - [`filter`]: the augmented EKF of Table 1 in the parallel configuration
//!   over N runs with shared θ (eq. 20–25).
//! - [`covariance`]: blockwise Φ·P·Φᵀ and the Joseph-form update.
//! - [`dp_model`]: the momentum-form DP ship with bias (eq. 35–45).
//! - [`staged`]: decoupled SI1 → SI2 → SI3 with frozen parameters (Fig. 4),
//!   A = M⁻¹·A_h·M and B = M⁻¹·T·K (eq. 51–52).
//! - [`sensitivity`]: the Kalman predictor with θ fixed, its innovations'
//!   likelihood and their forward sensitivities to θ.
//! - [`refine`]: prediction-error refinement of θ on all runs after the
//!   staged EKF (Levenberg–Marquardt), with a calibrated covariance.
//! - [`predictor`]: the identified ship as a validation
//!   [`Predictor`](crate::validation::Predictor).

mod covariance;
pub mod dp_model;
pub mod error;
pub mod filter;
pub mod model;
pub mod predictor;
pub mod refine;
pub mod sensitivity;
pub mod staged;

#[cfg(test)]
mod tests;

pub use dp_model::DpMomentumModel;
pub use error::EkfError;
pub use filter::{EkfOutput, EkfSettings, RunData, parallel_ekf};
pub use model::{ContinuousRunModel, Rk4, RunModel};
pub use predictor::IdentifiedDpShip;
pub use refine::{
    DpRefinement, RefineSettings, Refinement, dp_predictor_nll, refine_dp_ship, refine_theta,
};
pub use sensitivity::{PredictorNoise, PredictorPass, predictor_pass};
pub use staged::{
    DpIdentConfig, DpIdentification, DpStage, DpStageResult, SI1_FREE, SI2_FREE, SI3_FREE,
    identify_dp_ship,
};
