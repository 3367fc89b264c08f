//! Validation of identified models on runs not used for estimation
//! (thesis sec. 2.6): prediction and simulation NRMSE, residual tests.
//!
//! - [`validate`] ([`report`]): per output channel the 1-step, k-step and
//!   free-run fits (eq. 1.13), residual analysis, input–residual
//!   cross-correlation, a verdict in plain words and plot series;
//! - [`residuals`]: autocorrelation with 99 % bounds, Ljung–Box, zero
//!   crossings, normal-probability plot and Jarque–Bera;
//! - [`correlation`]: sample auto/cross-correlation (direct or FFT);
//! - [`distributions`]: Φ, Φ⁻¹, incomplete gamma, χ² and binomial tails.

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
