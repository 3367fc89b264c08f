//! Model-based experiment design: how precisely a plan will determine each
//! parameter of the identification, predicted before the ship leaves port.
//!
//! The prediction flies the plan with a prior model through the project's
//! own simulators (`simulation::trials` for ROVs, its controller reading
//! the noisy sensors; `simulation::dp_ship` for DP ships) over several
//! noise realisations, logs each with the stated sensor noise, and
//! identifies each as the campaign will be identified. The spread of the
//! estimates is the predicted std: the precision the plan buys against the
//! noise — for the parallel EKF it agrees with the Cramér–Rao bound √diag J⁻¹
//! of the refinement's Fisher information, for the λ-filter method with the
//! λ regression's posterior only where the model's structure fits the
//! prior. Beside it stands the std the identification will *report* (the
//! median over the realisations), which also carries the structure's misfit:
//! a parameter whose reported std is several times its spread is limited by
//! the model, not by the ship time.
//!
//! A parameter counts as *determined* when its predicted relative std is at
//! most [`DETERMINED_RELATIVE_STD`]. The relative std of a matrix entry
//! X_ij is std / √|X_ii X_jj| (an off-diagonal coupling measured against
//! its diagonal, not against its own, possibly zero, value); of a constant
//! load b_i, std / the DOF's force limit; of any other parameter,
//! std / |value|.
//!
//! [`design_campaign`] then designs the campaign for precision per
//! ship-hour: the λ regression's Fisher information ([`information`]) of
//! noise-free flights ranks hundreds of candidate plans in seconds, where
//! the prediction above takes seconds per plan; the prediction confirms the
//! chosen design.

pub mod information;
mod next_dive;
mod predict;
mod prior;
mod search;
mod table;

pub use next_dive::{NextDive, ProposedRun, propose_next_dive};
pub use predict::{MAX_REALISATIONS, PredictSettings, predict_precision};
pub use prior::{Prior, PriorSource};
pub use search::{DofChoice, ExperimentDesign, TradePoint, design_campaign};
pub use table::{ParameterPrecision, PrecisionPrediction};

use std::fmt;

/// Largest predicted relative std at which a parameter counts as determined.
pub const DETERMINED_RELATIVE_STD: f64 = 0.1;

/// Reported std over predicted std beyond which a parameter counts as
/// limited by the model's structure rather than by the noise.
pub const STRUCTURE_LIMITED: f64 = 3.0;

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
