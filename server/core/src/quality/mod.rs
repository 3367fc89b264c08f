//! Data-quality report of a sea-trial log: does it hold what an
//! identification needs, and if not, what should the crew do?
//!
//! [`quality_report`] takes a uniformly sampled log ([`UniformRecord`], with
//! its blocks of valid samples) and a [`QualitySpec`] naming the inputs
//! (generalized forces `tau_*` or thruster commands), the outputs (body
//! velocities) and the input→output pair of each identified DOF, and
//! returns a [`QualityReport`] with everything a web page plots and a
//! supervisor acts on:
//!
//! - spectra (module `spectra`): Welch PSD of every input and output, and
//!   for every input→output pair |CSD|, coherence, and the H1 frequency
//!   response (magnitude, dB, unwrapped phase); all from one
//!   [`crate::spectra::multi_welch`] pass (one FFT per channel and segment);
//! - excitation (module `excitation`): per input, the order of persistence
//!   of excitation, the usable band, the RMS and a Nyquist check;
//! - regressor (module `regressor`): the singular values of the ARX
//!   regressor Φ = (Φ_y Φ_x) and the number of identifiable parameters;
//! - plan adherence (module `adherence`): lag, correlation, amplitude ratio,
//!   NRMSE and coverage of each logged column against its planned schedule;
//! - verdicts (module `verdict`): `Good`, `Weak` or `Insufficient` per DOF,
//!   with a reason naming the DOF, the evidence and the action.
//!
//! Everything is pure and deterministic; invalid input is a
//! [`QualityError`], never a panic.

mod adherence;
mod excitation;
mod fastmath;
mod gram;
mod record;
mod regressor;
mod report;
mod spectra;
mod verdict;
mod words;

#[cfg(test)]
mod tests;

use std::fmt;

use serde::{Deserialize, Serialize};

use crate::planning::Dof;
use crate::spectra::SpectraError;
#[cfg(doc)]
use crate::timeseries::UniformRecord;

pub use adherence::{
    AMPLITUDE_RATIO_RANGE, MIN_ADHERENCE_CORRELATION, MIN_COVERAGE, MIN_OVERLAP_FRACTION,
};
pub use excitation::{NYQUIST_POWER_LIMIT, NYQUIST_TOP_FRACTION, PE_CAP};
pub use record::MAX_PAIR_BINS;
pub use regressor::{
    DEFAULT_REGRESSOR_LAGS, DIRECTION_WEIGHT, MAX_REGRESSOR_COLUMNS, SINGULAR_VALUE_THRESHOLD,
    regressor_analysis,
};
pub use report::{default_quality_nperseg, quality_report};
pub use verdict::{
    FLAT_INPUT_RELATIVE_RMS, GOOD_COHERENCE, MIN_COHERENT_FRACTION, MIN_INPUT_SHARE,
    MIN_MEDIAN_COHERENCE, MIN_PE_ORDER, MIN_SEGMENTS, units_first,
};

// ---------------------------------------------------------------------------
// Request
// ---------------------------------------------------------------------------

/// The input→output channel pair that identifies one DOF.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct DofChannels {
    /// The degree of freedom.
    pub dof: Dof,
    /// Its input column, e.g. `tau_Y` or `thr_3`; must be one of
    /// [`QualitySpec::inputs`].
    pub input: String,
    /// Its output column, e.g. `v`; must be one of [`QualitySpec::outputs`].
    pub output: String,
}

/// The planned schedules a log should follow.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct PlannedReference {
    /// Sample rate of the schedules (Hz), finite and `> 0`.
    pub sample_rate_hz: f64,
    /// `(log column, schedule column name, schedule samples)`: the log
    /// column (`v`, `tau_Y`, `thr_3`…) that should match the schedule, the
    /// schedule's own name, and its samples from its start at
    /// `sample_rate_hz`.
    pub columns: Vec<(String, String, Vec<f64>)>,
}

/// What to assess in a log.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct QualitySpec {
    /// The DOFs to give a verdict on (may be empty: spectra only).
    #[serde(default)]
    pub dofs: Vec<DofChannels>,
    /// Input columns (forces, thruster commands), at least one, distinct.
    pub inputs: Vec<String>,
    /// Output columns (velocities), at least one, distinct.
    pub outputs: Vec<String>,
    /// Welch segment length; `None` for [`default_quality_nperseg`].
    #[serde(default)]
    pub nperseg: Option<usize>,
    /// Rate the controller ran at (Hz), when known; sharpens the Nyquist
    /// warning.
    #[serde(default)]
    pub controller_rate_hz: Option<f64>,
    /// `na = nb` of the regressor (lags of every output and input), ≥ 1.
    #[serde(default = "default_regressor_lags")]
    pub regressor_lags: usize,
    /// Planned schedules, for the plan-adherence check.
    #[serde(default)]
    pub planned: Option<PlannedReference>,
}

fn default_regressor_lags() -> usize {
    DEFAULT_REGRESSOR_LAGS
}

impl QualitySpec {
    /// A spec for these inputs and outputs with no DOF verdicts, the default
    /// segment length and regressor lags, and no plan.
    pub fn new(inputs: Vec<String>, outputs: Vec<String>) -> Self {
        QualitySpec {
            dofs: Vec::new(),
            inputs,
            outputs,
            nperseg: None,
            controller_rate_hz: None,
            regressor_lags: DEFAULT_REGRESSOR_LAGS,
            planned: None,
        }
    }

    /// The same spec with one more DOF verdict.
    pub fn with_dof(mut self, dof: Dof, input: &str, output: &str) -> Self {
        self.dofs.push(DofChannels {
            dof,
            input: input.to_owned(),
            output: output.to_owned(),
        });
        self
    }
}

// ---------------------------------------------------------------------------
// Report
// ---------------------------------------------------------------------------

/// The data-quality report of a log. Spectra are given in full, one value
/// per entry of `freqs_hz`; a caller may decimate them for display.
///
/// Non-finite numbers (an H1 of 0 is −∞ dB) serialize as `null` with
/// `serde_json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct QualityReport {
    /// Sample rate of the log (Hz).
    pub sample_rate_hz: f64,
    /// Samples in the log, valid or not.
    pub n_samples: usize,
    /// Samples inside the valid blocks.
    pub n_valid_samples: usize,
    /// Duration of the valid samples (s).
    pub valid_duration_s: f64,
    /// How the spectra were estimated.
    pub welch: WelchSummary,
    /// Frequency grid of every spectrum (Hz).
    pub freqs_hz: Vec<f64>,
    /// One entry per input, in [`QualitySpec::inputs`] order.
    pub inputs: Vec<InputQuality>,
    /// One entry per output, in [`QualitySpec::outputs`] order.
    pub outputs: Vec<OutputQuality>,
    /// Every input × output pair, input-major (`inputs[0]→outputs[0]`,
    /// `inputs[0]→outputs[1]`, …).
    pub pairs: Vec<PairSpectra>,
    /// Identifiability of the ARX regressor.
    pub regressor: RegressorReport,
    /// One entry per planned column (empty without a plan).
    pub adherence: Vec<Adherence>,
    /// One verdict per DOF of [`QualitySpec::dofs`].
    pub dofs: Vec<DofVerdict>,
    /// Record-wide warnings in plain words (Nyquist, plan, regressor).
    pub warnings: Vec<String>,
}

/// The Welch parameters used for every spectrum of the report.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct WelchSummary {
    /// Segment length (samples).
    pub nperseg: usize,
    /// Overlap between segments (samples), `nperseg / 2`.
    pub noverlap: usize,
    /// Segments averaged over all valid blocks.
    pub n_segments: usize,
    /// Frequency resolution `fs / nperseg` (Hz).
    pub df_hz: f64,
    /// Segment duration (s).
    pub segment_s: f64,
}

/// Spectrum and excitation figures of one input.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct InputQuality {
    /// Column name.
    pub name: String,
    /// Mean over the valid samples (the operating point).
    pub mean: f64,
    /// RMS of the deviation from `mean` (the standard deviation).
    pub rms: f64,
    /// One-sided Welch PSD (units² / Hz).
    pub psd: Vec<f64>,
    /// Order of persistence of excitation of the deviation from the mean,
    /// the largest over the valid blocks, capped at `pe_cap`.
    pub pe_order: usize,
    /// Cap of the PE computation (`pe_order == pe_cap` means "at least").
    pub pe_cap: usize,
    /// Band where the PSD is within 10 dB of its peak (Hz), if any.
    pub usable_band_hz: Option<[f64; 2]>,
    /// Power near the Nyquist frequency of the log.
    pub nyquist: NyquistCheck,
}

/// Share of an input's power close to the log's Nyquist frequency: an input
/// that still has power there was probably logged slower than it changed.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct NyquistCheck {
    /// Nyquist frequency of the log (Hz).
    pub nyquist_hz: f64,
    /// The band checked, the top [`NYQUIST_TOP_FRACTION`] below Nyquist (Hz).
    pub band_hz: [f64; 2],
    /// Fraction of the input's power (DC excluded) in `band_hz`.
    pub power_fraction: f64,
    /// The warning, when `power_fraction > NYQUIST_POWER_LIMIT`.
    pub warning: Option<String>,
}

/// Spectrum of one output.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct OutputQuality {
    /// Column name.
    pub name: String,
    /// Mean over the valid samples.
    pub mean: f64,
    /// RMS of the deviation from `mean`.
    pub rms: f64,
    /// One-sided Welch PSD (units² / Hz).
    pub psd: Vec<f64>,
}

/// Cross-spectral figures of one input→output pair.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct PairSpectra {
    /// Input column.
    pub input: String,
    /// Output column.
    pub output: String,
    /// |Pxy|, magnitude of scipy's `csd(input, output)`.
    pub csd_magnitude: Vec<f64>,
    /// Magnitude-squared coherence (0 where a PSD is 0).
    pub coherence: Vec<f64>,
    /// |H1| = |Pxy / Pxx| (units of output per unit of input).
    pub h1_magnitude: Vec<f64>,
    /// 20·log10 |H1| (dB; −∞, serialized as null, where H1 = 0).
    #[cfg_attr(feature = "openapi", schema(value_type = Vec<Option<f64>>))]
    pub h1_magnitude_db: Vec<f64>,
    /// Unwrapped phase of H1 (rad, `numpy.unwrap(angle(H1))`).
    pub h1_phase_unwrapped_rad: Vec<f64>,
}

/// Singular-value analysis of the ARX regressor Φ = (Φ_y Φ_x).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct RegressorReport {
    /// `na = nb`, the lags of each output and input.
    pub lags: usize,
    /// Column names, outputs then inputs, each lag 1..=lags: `v(t-1)`…
    pub columns: Vec<String>,
    /// Rows of Φ (one per sample with all lags inside a valid block).
    pub n_rows: usize,
    /// Singular values of the unit-RMS-column Φ, descending, divided by
    /// the largest (all 0 when Φ is 0).
    pub singular_values: Vec<f64>,
    /// `σᵢ/σ₁` above which a direction counts as identifiable
    /// ([`SINGULAR_VALUE_THRESHOLD`]).
    pub threshold: f64,
    /// Number of singular values above the threshold: the parameters the
    /// data can determine.
    pub identifiable: usize,
    /// Number of columns (parameters of the full MIMO ARX model).
    pub n_columns: usize,
    /// The directions below the threshold, grouped by the columns that make
    /// them up: which regressors are (nearly) collinear or dead.
    pub deficient_directions: Vec<DeficientDirection>,
}

/// A group of regressor columns that are (nearly) linearly dependent: the
/// part of the regressor's deficient subspace (the directions with
/// `σᵢ/σ₁ ≤ threshold`) that these columns span. Columns of different
/// groups are independent of each other's dependency: e.g. one group for a
/// dead input's lags, one for two collinear inputs at lag 1, one at lag 2.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct DeficientDirection {
    /// Deficient directions in the group (parameters lost).
    pub dimension: usize,
    /// The largest normalized singular value `σᵢ/σ₁` of its directions
    /// (≈ 1e-8 or less: exact dependence; near the threshold: nearly).
    pub singular_value: f64,
    /// Share of the group's deficiency on input columns. At ≥ 0.5 the
    /// inputs are to blame (dead or collinear inputs: a defect of the
    /// experiment); below, the outputs' own lags are (nearly) dependent —
    /// dynamics of lower order than `lags`, or very smooth outputs — which
    /// the model structure, not the log, must answer.
    pub input_share: f64,
    /// The columns, in regressor order, with the share of each lying in the
    /// deficient subspace (1: wholly determined by the others or zero).
    pub columns: Vec<ColumnWeight>,
}

/// One column of a [`DeficientDirection`].
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct ColumnWeight {
    /// Column name, e.g. `tau_Y(t-1)`.
    pub column: String,
    /// Share of the column in the deficient subspace, in (0, 1].
    pub weight: f64,
}

/// How well one logged column followed its planned schedule.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct Adherence {
    /// Log column.
    pub log_column: String,
    /// Schedule column name.
    pub schedule_column: String,
    /// Time of the schedule's start in the log, from the log's first sample
    /// (s); negative when the log started after the schedule.
    pub lag_s: f64,
    /// Pearson correlation of log and schedule over their overlap at the lag.
    pub correlation: f64,
    /// Standard deviation of the log over that of the schedule, at the lag;
    /// `None` when the schedule does not vary over the overlap (a hold) or
    /// nothing overlaps: there is no amplitude to compare.
    pub amplitude_ratio: Option<f64>,
    /// RMS of (log − schedule) over the schedule's standard deviation, at
    /// the lag (an offset between them counts); `None` likewise.
    pub nrmse: Option<f64>,
    /// Fraction of the schedule's samples that fall on valid log samples.
    pub coverage: f64,
    /// `correlation ≥ MIN_ADHERENCE_CORRELATION`, amplitude ratio within
    /// `AMPLITUDE_RATIO_RANGE` and `coverage ≥ MIN_COVERAGE`.
    pub followed: bool,
    /// The finding in plain words.
    pub message: String,
}

/// Data-quality verdict of one DOF.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// The log identifies this DOF.
    Good,
    /// Usable with caution; the reason says what limits it.
    Weak,
    /// The log cannot identify this DOF; fly it again.
    Insufficient,
    /// The log's units look wrong (milliseconds, degrees): fix them and
    /// upload again before the excitation is judged.
    CheckUnits,
}

/// The verdict on one DOF, its reason and the evidence behind it.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct DofVerdict {
    /// The DOF.
    pub dof: Dof,
    /// Its input column.
    pub input: String,
    /// Its output column.
    pub output: String,
    /// `good`, `weak`, `insufficient` or `check_units`.
    pub verdict: Verdict,
    /// Plain words naming the DOF, the evidence and the action.
    pub reason: String,
    /// The numbers the verdict rests on.
    pub evidence: DofEvidence,
}

/// The figures behind a [`DofVerdict`].
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct DofEvidence {
    /// PE order of the input (capped at [`PE_CAP`]).
    pub pe_order: usize,
    /// RMS of the input about its mean.
    pub input_rms: f64,
    /// Welch segments averaged.
    pub n_segments: usize,
    /// Usable band of the input (Hz).
    pub usable_band_hz: Option<[f64; 2]>,
    /// Median coherence over the usable band.
    pub median_coherence: Option<f64>,
    /// Fraction of the usable band's bins with coherence ≥
    /// [`GOOD_COHERENCE`].
    pub coherent_fraction: Option<f64>,
    /// Lowest and highest frequency of the usable band with coherence ≥
    /// [`GOOD_COHERENCE`] (Hz), if any.
    pub good_coherence_span_hz: Option<[f64; 2]>,
    /// The input's Nyquist warning fired.
    pub nyquist_warning: bool,
    /// Whether the DOF's planned columns were followed (`None`: no plan
    /// for its input or output).
    pub plan_followed: Option<bool>,
    /// Identifiable parameters of the DOF's own regressor (its output's and
    /// input's lags); informative only, see `input_deficient`.
    pub identifiable: usize,
    /// Columns of the DOF's own regressor (`2 · lags`).
    pub n_columns: usize,
    /// A deficient direction of the full regressor that lies mostly on
    /// input columns (`input_share ≥ 0.5`) involves the DOF's input.
    pub input_deficient: bool,
}

// ---------------------------------------------------------------------------
// Errors
// ---------------------------------------------------------------------------

/// Why a quality report could not be made. Every variant names the
/// offending field (a path into the request or the record) and says what
/// is wrong in words.
#[derive(Debug, Clone, PartialEq)]
pub enum QualityError {
    /// The record is unusable: bad sample rate, ragged columns, no valid
    /// samples, or a valid block outside the record.
    InvalidRecord {
        /// `sample_rate_hz`, `data[i]` or `valid[i]`.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// The spec is inconsistent or out of range.
    InvalidSpec {
        /// Path into the spec, e.g. `dofs[1].input`, `nperseg`.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// A column named by the spec is not in the record.
    MissingColumn {
        /// Path into the spec, e.g. `inputs[2]`.
        field: String,
        /// The missing column name.
        name: String,
    },
    /// A column holds NaN or ±∞ inside a valid block.
    NonFinite {
        /// The column name.
        field: String,
        /// Index of the first such sample.
        index: usize,
        /// Description including the value.
        message: String,
    },
    /// A spectral computation rejected its input.
    Spectra(SpectraError),
}

impl QualityError {
    /// The offending field.
    pub fn field(&self) -> &str {
        match self {
            QualityError::InvalidRecord { field, .. }
            | QualityError::InvalidSpec { field, .. }
            | QualityError::MissingColumn { field, .. }
            | QualityError::NonFinite { field, .. } => field,
            QualityError::Spectra(e) => e.field(),
        }
    }

    /// The message, without the field.
    pub fn message(&self) -> String {
        match self {
            QualityError::InvalidRecord { message, .. }
            | QualityError::InvalidSpec { message, .. }
            | QualityError::NonFinite { message, .. } => message.clone(),
            QualityError::MissingColumn { name, .. } => {
                format!("column `{name}` is not in the log")
            }
            QualityError::Spectra(e) => e.message().to_owned(),
        }
    }

    pub(crate) fn record(field: impl Into<String>, message: impl Into<String>) -> Self {
        QualityError::InvalidRecord {
            field: field.into(),
            message: message.into(),
        }
    }

    pub(crate) fn spec(field: impl Into<String>, message: impl Into<String>) -> Self {
        QualityError::InvalidSpec {
            field: field.into(),
            message: message.into(),
        }
    }
}

impl fmt::Display for QualityError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            QualityError::Spectra(e) => write!(f, "spectra: {e}"),
            other => write!(f, "{}: {}", other.field(), other.message()),
        }
    }
}

impl std::error::Error for QualityError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            QualityError::Spectra(e) => Some(e),
            _ => None,
        }
    }
}

impl From<SpectraError> for QualityError {
    fn from(e: SpectraError) -> Self {
        QualityError::Spectra(e)
    }
}
