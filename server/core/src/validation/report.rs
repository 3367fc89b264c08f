//! One call that validates an identified model on a record (thesis sec.
//! 2.6): per output channel the NRMSE fits (eq. 1.13) of 1-step predictions
//! (eq. 2.16/2.18), k-step predictions, free runs restarted from the
//! measured state every `restart_s` and the whole-record free-run
//! simulation (eq. 2.20–2.21); where a prediction diverged (see
//! [`super::divergence`]); the residual analysis of the 1-step and k-step
//! errors (eq. 2.19), input–residual cross-correlations, and thinned series
//! to plot.

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::channel::{Checked, check_free_run, check_k_step, check_restarted, residual};
use super::divergence::{Channel, Divergence, PlausibleBand, channel_words};
use super::error::ValidationError;
use super::predictor::{Predictor, ValidationRecord};
use super::residuals::{
    CrossCorrelation, ResidualAnalysis, ResidualSettings, analyze_residuals,
    input_residual_correlation,
};
use super::verdict::{Facts, channel_findings};
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
    /// Period of the restarted free runs (s): the model is started again
    /// from the measured state every `restart_s` (10 s, the window engineers
    /// judge controllers over), rounded to whole samples.
    #[serde(default = "default_restart_s")]
    pub restart_s: f64,
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
fn default_restart_s() -> f64 {
    10.0
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
            restart_s: default_restart_s(),
            full_resolution: false,
            input_names: Vec::new(),
        }
    }
}

/// The validation of a model on one record. Every number is finite: a
/// prediction that diverged is cut where it left the plausible range and
/// its fit is `None` (see [`Divergence`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct ValidationReport {
    /// Sample time h (s).
    pub sample_time_s: f64,
    /// Samples in the record.
    pub n_samples: usize,
    /// Horizon of the k-step predictions.
    pub k: usize,
    /// Period of the restarted free runs as used: a whole number of samples
    /// (s).
    pub restart_s: f64,
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
    /// better than the mean. `None` when undefined (constant output) or the
    /// prediction diverged.
    pub fit_one_step: Option<f64>,
    /// NRMSE fit of the k-step predictions (`None` likewise).
    pub fit_k_step: Option<f64>,
    /// NRMSE fit of the free runs restarted every `restart_s`, over the
    /// windows that did not diverge (`None` when all did).
    pub fit_restarted: Option<f64>,
    /// NRMSE fit of the whole-record free-run simulation (`None` when it
    /// diverged).
    pub fit_simulation: Option<f64>,
    /// The restarted free runs: windows and how many diverged.
    pub restarted: RestartedWindows,
    /// Where each prediction left the plausible range, if it did.
    pub diverged: Divergences,
    /// Residual analysis of the 1-step errors e(t) = y(t) − ŷ(t|t−1);
    /// `None` when the 1-step prediction diverged.
    pub one_step: Option<ResidualAnalysis>,
    /// Residual analysis of the k-step errors, judged beyond lag k − 1;
    /// `None` when the k-step prediction diverged.
    pub k_step: Option<ResidualAnalysis>,
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

/// The windows of the restarted free runs of one channel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct RestartedWindows {
    /// Windows in the record (the last may be shorter).
    pub windows: usize,
    /// Windows whose free run left the plausible range; left out of
    /// `fit_restarted`.
    pub diverged: usize,
}

/// Where the predictions of a channel diverged (`None`: they did not).
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct Divergences {
    /// First implausible 1-step prediction.
    pub one_step: Option<Divergence>,
    /// First implausible k-step prediction.
    pub k_step: Option<Divergence>,
    /// The first restarted window that diverged.
    pub restarted: Option<Divergence>,
    /// The whole-record free run.
    pub simulation: Option<Divergence>,
}

/// Measured, predicted and simulated series of a channel on a common,
/// possibly thinned, time grid. Predictions are `null` where none exists
/// (the first k rows of a k-step prediction) and after a divergence.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct ChannelPlot {
    /// Every `stride`-th sample is kept.
    pub stride: usize,
    /// Time of each kept sample from the record start (s).
    pub time_s: Vec<f64>,
    /// Measured y.
    pub measured: Vec<f64>,
    /// 1-step predictions ŷ(t|t−1).
    pub one_step: Vec<Option<f64>>,
    /// k-step predictions ŷ(t|t−k).
    pub k_step: Vec<Option<f64>>,
    /// Free runs restarted from the measured state every `restart_s`.
    pub restarted: Vec<Option<f64>>,
    /// Whole-record free-run simulation.
    pub simulated: Vec<Option<f64>>,
}

/// Validate `model` on `rec`: fits, divergence, residual tests and plot
/// data per output channel. Errors name the offending field; a model whose
/// k-step predictions are all missing (wrong record shape) is an error, a
/// prediction that blows up is a finding.
pub fn validate(
    model: &dyn Predictor,
    rec: &ValidationRecord<'_>,
    settings: &ValidationSettings,
) -> Result<ValidationReport, ValidationError> {
    let (n, p) = check_record(model, rec, settings)?;
    let inputs = input_names(rec.u.ncols(), settings)?;
    let every = restart_samples(settings.restart_s, rec.h);
    let one = model.predict_k_step(rec, 1);
    let kstep = model.predict_k_step(rec, settings.k);
    let restarted = model.simulate_restarted(rec, every);
    let sim = model.simulate(rec);
    for (field, m) in [
        ("predict_k_step(1)", &one),
        ("predict_k_step(k)", &kstep),
        ("simulate_restarted", &restarted),
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
        let ch = Channel {
            output: name,
            y,
            h: rec.h,
            band: PlausibleBand::of(y),
        };
        let col = |m: &DMatrix<f64>| m.column(j).iter().copied().collect::<Vec<f64>>();
        let preds = Predictions {
            one: check_k_step(&ch, &col(&one), 1, "predict_k_step(1)")?,
            k: check_k_step(&ch, &col(&kstep), settings.k, "predict_k_step(k)")?,
            restarted: check_restarted(&ch, &col(&restarted), every),
            sim: check_free_run(&ch, &col(&sim)),
        };
        let grid = Grid {
            every,
            stride,
            rows: &plot_rows,
        };
        channels.push(channel(&ch, rec, &inputs, settings, &grid, preds)?);
    }
    Ok(ValidationReport {
        sample_time_s: rec.h,
        n_samples: n,
        k: settings.k,
        restart_s: every as f64 * rec.h,
        max_lag: settings.max_lag,
        confidence: settings.confidence,
        inputs,
        channels,
    })
}

/// The four predictions of a channel after the plausibility check.
struct Predictions {
    one: Checked,
    k: Checked,
    restarted: (Checked, RestartedWindows),
    sim: Checked,
}

/// Restart period and plotted rows, in samples.
struct Grid<'a> {
    every: usize,
    stride: usize,
    rows: &'a [usize],
}

/// Residual tests, findings and plot of one channel.
fn channel(
    ch: &Channel<'_>,
    rec: &ValidationRecord<'_>,
    inputs: &[String],
    settings: &ValidationSettings,
    grid: &Grid<'_>,
    p: Predictions,
) -> Result<ChannelValidation, ValidationError> {
    let name = ch.output;
    let base = ResidualSettings {
        max_lag: settings.max_lag,
        ma_order: 0,
        confidence: settings.confidence,
        plot_points: 200,
    };
    let mut input_correlations = Vec::new();
    let one_step = match residual(ch.y, &p.one) {
        Some((start1, e1)) => {
            input_correlations = inputs
                .iter()
                .enumerate()
                .filter_map(|(i, input)| {
                    let col = rec.u.column(i);
                    let u = &col.as_slice()[start1..];
                    input_residual_correlation(&e1, u, input, settings.max_lag, settings.confidence)
                })
                .collect();
            Some(analyze_residuals(
                &e1,
                &base,
                &format!("{name} 1-step residual"),
            )?)
        }
        None => None,
    };
    let k_step = match residual(ch.y, &p.k) {
        Some((_, ek)) => {
            let k_settings = ResidualSettings {
                ma_order: settings.k - 1,
                ..base
            };
            Some(analyze_residuals(
                &ek,
                &k_settings,
                &format!("{name} k-step residual"),
            )?)
        }
        None => None,
    };
    let (rst, windows) = p.restarted;
    let diverged = Divergences {
        one_step: p.one.divergence,
        k_step: p.k.divergence,
        restarted: rst.divergence,
        simulation: p.sim.divergence,
    };
    let findings = channel_findings(&Facts {
        one_step: one_step.as_ref(),
        k_step: k_step.as_ref(),
        k: settings.k,
        cross: &input_correlations,
        alpha: 1.0 - settings.confidence,
        unit: channel_words(name).1,
        fit_restarted: rst.fit,
        fit_simulation: p.sim.fit,
        restart_s: grid.every as f64 * rec.h,
        restarted: &windows,
        diverged: &diverged,
    });
    let pick = |s: &[f64]| {
        grid.rows
            .iter()
            .map(|&t| s[t].is_finite().then_some(s[t]))
            .collect::<Vec<Option<f64>>>()
    };
    Ok(ChannelValidation {
        output: name.to_owned(),
        fit_one_step: p.one.fit,
        fit_k_step: p.k.fit,
        fit_restarted: rst.fit,
        fit_simulation: p.sim.fit,
        restarted: windows,
        diverged,
        residuals_white: one_step.as_ref().is_some_and(|a| a.white),
        one_step,
        k_step,
        input_correlations,
        verdict: findings.join("; "),
        findings,
        plot: ChannelPlot {
            stride: grid.stride,
            time_s: grid.rows.iter().map(|&t| t as f64 * rec.h).collect(),
            measured: grid.rows.iter().map(|&t| ch.y[t]).collect(),
            one_step: pick(&p.one.series),
            k_step: pick(&p.k.series),
            restarted: pick(&rst.series),
            simulated: pick(&p.sim.series),
        },
    })
}

/// Samples per restarted window: `restart_s` rounded, at least one.
fn restart_samples(restart_s: f64, h: f64) -> usize {
    ((restart_s / h).round() as usize).max(1)
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
    if !(s.restart_s.is_finite() && s.restart_s > 0.0) {
        return Err(ValidationError::invalid(
            "settings.restart_s",
            format!(
                "the restart period must be finite and > 0 s, got {}",
                s.restart_s
            ),
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
