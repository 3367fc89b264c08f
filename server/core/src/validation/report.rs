//! One call that validates an identified model on a record (thesis sec.
//! 2.6): per output channel the NRMSE fits (eq. 1.13) of 1-step predictions
//! (eq. 2.16/2.18), k-step predictions and free-run simulation (eq.
//! 2.20–2.21), the residual analysis of the 1-step and k-step errors (eq.
//! 2.19), input–residual cross-correlations, and thinned series to plot.

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::error::ValidationError;
use super::metrics::nrmse_fit;
use super::predictor::{Predictor, ValidationRecord};
use super::residuals::{
    CrossCorrelation, ResidualAnalysis, ResidualSettings, analyze_residuals,
    input_residual_correlation,
};
use super::verdict::{Fits, channel_findings};

/// What [`validate`] computes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct ValidationSettings {
    /// Prediction horizon k of the k-step predictions ŷ(t|t−k) (≥ 1; the
    /// thesis uses 10 for MPC).
    #[serde(default = "default_k")]
    pub k: usize,
    /// Largest lag L of the correlation functions (> k − 1).
    #[serde(default = "default_max_lag")]
    pub max_lag: usize,
    /// Confidence level of the bounds and tests (0.99 in the thesis).
    #[serde(default = "default_confidence")]
    pub confidence: f64,
    /// Samples kept per plotted series (the record is thinned to at most
    /// this many for display).
    #[serde(default = "default_plot_points")]
    pub plot_points: usize,
    /// Keep every sample in the plotted series.
    #[serde(default)]
    pub full_resolution: bool,
    /// Names of the input columns of `u` (`tau_X`, `gamma_M`, …); empty for
    /// `u_1`, `u_2`, ….
    #[serde(default)]
    pub input_names: Vec<String>,
}

fn default_k() -> usize {
    10
}
fn default_max_lag() -> usize {
    50
}
fn default_confidence() -> f64 {
    0.99
}
fn default_plot_points() -> usize {
    1000
}

impl Default for ValidationSettings {
    fn default() -> Self {
        ValidationSettings {
            k: default_k(),
            max_lag: default_max_lag(),
            confidence: default_confidence(),
            plot_points: default_plot_points(),
            full_resolution: false,
            input_names: Vec::new(),
        }
    }
}

/// The validation of a model on one record.
///
/// Non-finite numbers (predictions that do not exist, e.g. the first k
/// samples of a k-step prediction) serialize as `null` with `serde_json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct ValidationReport {
    /// Sample time h (s).
    pub sample_time_s: f64,
    /// Samples in the record.
    pub n_samples: usize,
    /// Horizon of the k-step predictions.
    pub k: usize,
    /// Largest correlation lag.
    pub max_lag: usize,
    /// Confidence level of bounds and tests.
    pub confidence: f64,
    /// Input names, in column order of `u`.
    pub inputs: Vec<String>,
    /// One entry per output channel, in column order of `y`.
    pub channels: Vec<ChannelValidation>,
}

/// Validation of one output channel.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct ChannelValidation {
    /// Output name (from the model).
    pub output: String,
    /// NRMSE fit (eq. 1.13) of the 1-step predictions; 1 is perfect, 0 no
    /// better than the mean. `None` when undefined (constant output).
    pub fit_one_step: Option<f64>,
    /// NRMSE fit of the k-step predictions.
    pub fit_k_step: Option<f64>,
    /// NRMSE fit of the free-run simulation.
    pub fit_simulation: Option<f64>,
    /// Residual analysis of the 1-step errors e(t) = y(t) − ŷ(t|t−1).
    pub one_step: ResidualAnalysis,
    /// Residual analysis of the k-step errors, judged beyond lag k − 1.
    pub k_step: ResidualAnalysis,
    /// Cross-correlation of each input with the 1-step errors.
    pub input_correlations: Vec<CrossCorrelation>,
    /// The 1-step residuals pass the whiteness test.
    pub residuals_white: bool,
    /// What the tests say, in plain words, most important first.
    pub findings: Vec<String>,
    /// The findings in one line.
    pub verdict: String,
    /// Measured and predicted series for display.
    pub plot: ChannelPlot,
}

/// Measured, predicted and simulated series of a channel on a common,
/// possibly thinned, time grid.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct ChannelPlot {
    /// Every `stride`-th sample is kept.
    pub stride: usize,
    /// Time of each kept sample from the record start (s).
    pub time_s: Vec<f64>,
    /// Measured y.
    pub measured: Vec<f64>,
    /// 1-step predictions ŷ(t|t−1) (null where none exists).
    #[cfg_attr(feature = "openapi", schema(value_type = Vec<Option<f64>>))]
    pub one_step: Vec<f64>,
    /// k-step predictions ŷ(t|t−k) (null where none exists).
    #[cfg_attr(feature = "openapi", schema(value_type = Vec<Option<f64>>))]
    pub k_step: Vec<f64>,
    /// Free-run simulation.
    #[cfg_attr(feature = "openapi", schema(value_type = Vec<Option<f64>>))]
    pub simulated: Vec<f64>,
}

/// Validate `model` on `rec`: fits, residual tests and plot data per output
/// channel. Errors name the offending field; the model's predictions are
/// checked for shape and for NaN inside the record.
pub fn validate(
    model: &dyn Predictor,
    rec: &ValidationRecord<'_>,
    settings: &ValidationSettings,
) -> Result<ValidationReport, ValidationError> {
    let (n, p) = check_record(model, rec, settings)?;
    let inputs = input_names(rec.u.ncols(), settings)?;
    let one = model.predict_k_step(rec, 1);
    let kstep = model.predict_k_step(rec, settings.k);
    let sim = model.simulate(rec);
    for (field, m) in [
        ("predict_k_step(1)", &one),
        ("predict_k_step(k)", &kstep),
        ("simulate", &sim),
    ] {
        if m.shape() != (n, p) {
            return Err(ValidationError::model_output(
                field,
                format!(
                    "returned {}×{}, the record needs {n}×{p}",
                    m.nrows(),
                    m.ncols()
                ),
            ));
        }
    }
    let names = model.output_names();
    let alpha = 1.0 - settings.confidence;
    let stride = if settings.full_resolution {
        1
    } else {
        n.div_ceil(settings.plot_points)
    };
    let plot_rows: Vec<usize> = (0..n).step_by(stride).collect();
    let mut channels = Vec::with_capacity(p);
    for (j, name) in names.iter().enumerate() {
        let y = rec.y.column(j);
        let y = y.as_slice();
        let (c1, c2, cs) = (one.column(j), kstep.column(j), sim.column(j));
        let (c1, c2, cs) = (c1.as_slice(), c2.as_slice(), cs.as_slice());
        let (start1, e1) = residual(y, c1, "predict_k_step(1)")?;
        let (_, ek) = residual(y, c2, "predict_k_step(k)")?;
        let base = ResidualSettings {
            max_lag: settings.max_lag,
            ma_order: 0,
            confidence: settings.confidence,
            plot_points: 200,
        };
        let one_step = analyze_residuals(&e1, &base, &format!("{name} 1-step residual"))?;
        let k_settings = ResidualSettings {
            ma_order: settings.k - 1,
            ..base
        };
        let k_step = analyze_residuals(&ek, &k_settings, &format!("{name} k-step residual"))?;
        let input_correlations: Vec<CrossCorrelation> = inputs
            .iter()
            .enumerate()
            .filter_map(|(i, input)| {
                let col = rec.u.column(i);
                let u = &col.as_slice()[start1..];
                input_residual_correlation(&e1, u, input, settings.max_lag, settings.confidence)
            })
            .collect();
        let fit_simulation = nrmse_fit(y, cs);
        let findings = channel_findings(
            &one_step,
            &k_step,
            settings.k,
            &input_correlations,
            &Fits {
                simulation: fit_simulation,
            },
            alpha,
        );
        let pick = |s: &[f64]| plot_rows.iter().map(|&t| s[t]).collect::<Vec<f64>>();
        channels.push(ChannelValidation {
            output: name.clone(),
            fit_one_step: nrmse_fit(y, c1),
            fit_k_step: nrmse_fit(y, c2),
            fit_simulation,
            residuals_white: one_step.white,
            one_step,
            k_step,
            input_correlations,
            verdict: findings.join("; "),
            findings,
            plot: ChannelPlot {
                stride,
                time_s: plot_rows.iter().map(|&t| t as f64 * rec.h).collect(),
                measured: pick(y),
                one_step: pick(c1),
                k_step: pick(c2),
                simulated: pick(cs),
            },
        });
    }
    Ok(ValidationReport {
        sample_time_s: rec.h,
        n_samples: n,
        k: settings.k,
        max_lag: settings.max_lag,
        confidence: settings.confidence,
        inputs,
        channels,
    })
}

/// Record size, after checking the record, the settings and the names.
fn check_record(
    model: &dyn Predictor,
    rec: &ValidationRecord<'_>,
    s: &ValidationSettings,
) -> Result<(usize, usize), ValidationError> {
    if !(rec.h.is_finite() && rec.h > 0.0) {
        return Err(ValidationError::invalid(
            "h",
            format!("sample time must be finite and > 0, got {}", rec.h),
        ));
    }
    let (n, p) = rec.y.shape();
    if p == 0 {
        return Err(ValidationError::invalid("y", "has no output channel"));
    }
    if rec.u.nrows() != n {
        return Err(ValidationError::invalid(
            "u",
            format!("has {} rows, y has {n}", rec.u.nrows()),
        ));
    }
    for (field, m) in [("y", rec.y), ("u", rec.u)] {
        if let Some(i) = first_non_finite_row(m) {
            return Err(ValidationError::non_finite(field, i));
        }
    }
    if s.k == 0 {
        return Err(ValidationError::invalid(
            "settings.k",
            "the horizon must be ≥ 1",
        ));
    }
    if s.max_lag < s.k {
        return Err(ValidationError::invalid(
            "settings.max_lag",
            format!(
                "must be ≥ k = {} so that lags beyond the k-step horizon are tested",
                s.k
            ),
        ));
    }
    if !(s.confidence > 0.0 && s.confidence < 1.0) {
        return Err(ValidationError::invalid(
            "settings.confidence",
            format!("must lie strictly between 0 and 1, got {}", s.confidence),
        ));
    }
    if s.plot_points < 2 {
        return Err(ValidationError::invalid(
            "settings.plot_points",
            "must be ≥ 2",
        ));
    }
    let needed = s.k + s.max_lag + 2;
    if n < needed {
        return Err(ValidationError::too_short(
            "y",
            format!(
                "{n} samples; k = {} and max_lag = {} need at least {needed}",
                s.k, s.max_lag
            ),
        ));
    }
    let names = model.output_names();
    if names.len() != p {
        return Err(ValidationError::invalid(
            "output_names",
            format!("the model names {} outputs, y has {p} columns", names.len()),
        ));
    }
    Ok((n, p))
}

fn input_names(m: usize, s: &ValidationSettings) -> Result<Vec<String>, ValidationError> {
    if s.input_names.is_empty() {
        return Ok((1..=m).map(|i| format!("u_{i}")).collect());
    }
    if s.input_names.len() != m {
        return Err(ValidationError::invalid(
            "settings.input_names",
            format!("{} names for {m} input columns", s.input_names.len()),
        ));
    }
    Ok(s.input_names.clone())
}

fn first_non_finite_row(m: &DMatrix<f64>) -> Option<usize> {
    (0..m.nrows()).find(|&i| m.row(i).iter().any(|v| !v.is_finite()))
}

/// Residual y − ŷ from the first row with a prediction to the end, and that
/// row. A NaN after it is a model failure.
fn residual(y: &[f64], yhat: &[f64], field: &str) -> Result<(usize, Vec<f64>), ValidationError> {
    let Some(start) = yhat.iter().position(|v| v.is_finite()) else {
        return Err(ValidationError::model_output(
            field,
            "returned no finite prediction",
        ));
    };
    if let Some(i) = yhat[start..].iter().position(|v| !v.is_finite()) {
        return Err(ValidationError::model_output(
            field,
            format!(
                "prediction at row {} is NaN or infinite inside the record",
                start + i
            ),
        ));
    }
    Ok((
        start,
        y[start..]
            .iter()
            .zip(&yhat[start..])
            .map(|(a, b)| a - b)
            .collect(),
    ))
}
