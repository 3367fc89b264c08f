//! Validation of identified models on runs not used for estimation
//! (thesis sec. 2.6): prediction and simulation NRMSE, residual tests.
//!
//! - [`validate`] ([`report`]): per output channel the 1-step, k-step,
//!   restarted free-run (every `restart_s`, default 10 s) and whole-record
//!   free-run fits (eq. 1.13), residual analysis, input–residual
//!   cross-correlation, a verdict in plain words and plot series;
//! - [`divergence`]: a prediction that leaves the plausible range (100
//!   measured ranges around the mean, or non-finite) is cut there and
//!   reported as a finding with its time and channel, its fit `None`;
//! - [`residuals`]: autocorrelation with 99 % bounds, Ljung–Box, zero
//!   crossings, normal-probability plot and Jarque–Bera;
//! - [`correlation`]: sample auto/cross-correlation (direct or FFT);
//! - [`distributions`]: Φ, Φ⁻¹, incomplete gamma, χ² and binomial tails.

mod channel;
pub mod correlation;
pub mod distributions;
pub mod divergence;
pub mod error;
pub mod metrics;
pub mod predictor;
pub mod report;
pub mod residuals;
mod verdict;

#[cfg(test)]
mod residual_tests;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod unstable_tests;

pub use divergence::{Divergence, DivergenceReason, PLAUSIBLE_RANGES, PlausibleBand};
pub use error::ValidationError;
pub use metrics::{nrmse_fit, nrmse_fit_columns};
pub use predictor::{Predictor, ValidationRecord, restart_windows};
pub use report::{
    ChannelPlot, ChannelValidation, Divergences, RestartedWindows, ValidationReport,
    ValidationSettings, validate,
};
pub use residuals::{
    AutocorrelationTest, CrossCorrelation, LjungBox, Normality, OffsetTest, ProbabilityPlot,
    ResidualAnalysis, ResidualSettings, ZeroCrossings, analyze_residuals,
    input_residual_correlation,
};
