//! Model-based experiment design: how precisely a plan will determine each
//! parameter of the identification, predicted before the ship leaves port.
//!
//! The prediction flies the plan with a prior model through the project's
//! own simulators (`simulation::trials` for ROVs, `simulation::dp_ship` for
//! DP ships), logs it with the stated sensor noise, and identifies the
//! simulated campaign with the method the campaign will use. The standard
//! deviations the identification then reports are the prediction: for the
//! λ-filter method the posterior of its linear regression (the inverse
//! Fisher information of the λ parameters, carried to M, D̄ by the delta
//! method; g(η) pooled over the grid), for the parallel EKF the
//! prediction-error refinement's Cramér–Rao bound √diag J⁻¹ with J the
//! Fisher information of the Kalman predictor's innovations.
//!
//! A parameter counts as *determined* when its predicted relative std is at
//! most [`DETERMINED_RELATIVE_STD`]. The relative std of a matrix entry
//! X_ij is std / √|X_ii X_jj| (an off-diagonal coupling measured against
//! its diagonal, not against its own, possibly zero, value); of a constant
//! load b_i, std / the DOF's force limit; of any other parameter,
//! std / |value|.

mod predict;
mod prior;
mod table;

pub use predict::{PredictSettings, predict_precision};
pub use prior::{Prior, PriorSource};
pub use table::{ParameterPrecision, PrecisionPrediction};

use std::fmt;

/// Largest predicted relative std at which a parameter counts as determined.
pub const DETERMINED_RELATIVE_STD: f64 = 0.1;

/// Parameters named as weakest in a prediction.
pub const WEAKEST_SHOWN: usize = 5;

/// Why a prediction could not be made.
#[derive(Debug, Clone, PartialEq)]
pub enum DesignError {
    /// An input is wrong or the plan cannot be flown or identified; names
    /// the field at fault (e.g. `plan.experiments[DYN-0kn-sway-r1]`).
    Invalid {
        /// The field.
        field: String,
        /// What is wrong, in words.
        reason: String,
    },
    /// The progress sink asked to stop.
    Cancelled,
}

impl DesignError {
    pub(crate) fn new(field: impl Into<String>, reason: impl Into<String>) -> Self {
        DesignError::Invalid {
            field: field.into(),
            reason: reason.into(),
        }
    }

    /// The field at fault (`job` when cancelled).
    pub fn field(&self) -> &str {
        match self {
            DesignError::Invalid { field, .. } => field,
            DesignError::Cancelled => "job",
        }
    }
}

impl fmt::Display for DesignError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DesignError::Invalid { field, reason } => write!(f, "{field}: {reason}"),
            DesignError::Cancelled => f.write_str("cancelled"),
        }
    }
}

impl std::error::Error for DesignError {}

#[cfg(test)]
mod tests;
