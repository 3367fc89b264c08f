//! Validation of identified models on runs not used for estimation
//! (thesis sec. 2.6): prediction and simulation NRMSE, residual tests.

pub mod correlation;
pub mod distributions;
pub mod error;
pub mod metrics;
pub mod predictor;
pub mod report;
pub mod residuals;
mod verdict;

#[cfg(test)]
mod tests;

pub use error::ValidationError;
pub use metrics::{nrmse_fit, nrmse_fit_columns};
pub use predictor::{Predictor, ValidationRecord};
pub use report::{ChannelPlot, ChannelValidation, ValidationReport, ValidationSettings, validate};
pub use residuals::{
    AutocorrelationTest, CrossCorrelation, LjungBox, Normality, OffsetTest, ProbabilityPlot,
    ResidualAnalysis, ResidualSettings, ZeroCrossings, analyze_residuals,
    input_residual_correlation,
};
