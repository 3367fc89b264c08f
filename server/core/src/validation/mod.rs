//! Validation of identified models on runs not used for estimation
//! (thesis sec. 2.6): prediction and simulation NRMSE, residual tests.

pub mod metrics;
pub mod predictor;

pub use metrics::{nrmse_fit, nrmse_fit_columns};
pub use predictor::{Predictor, ValidationRecord};
