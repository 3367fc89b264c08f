//! What a plan holds: each experiment with its reference schedule, in the
//! order it is flown, and the totals.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::planning::analysis::ChannelAnalysis;
use crate::planning::campaign::ExperimentFamily;
use crate::planning::dof::Dof;
use crate::planning::waveform::Waveform;

/// One reference column of a schedule.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct ChannelPlan {
    /// CSV column: `u_ref`…`r_ref` (velocity), `phi_ref`, `theta_ref`
    /// (roll and pitch attitude), `tau_Y`… (force), `thr_1`… (thrusters).
    pub column: String,
    /// SI unit of the column.
    pub unit: String,
    /// DOF of the column (velocity or force channels).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dof: Option<Dof>,
    /// Thruster index (0-based) for thruster channels.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub thruster: Option<usize>,
    /// True when this channel carries the excitation; false when held.
    pub excited: bool,
    /// Shape.
    pub waveform: Waveform,
    /// Operating point.
    pub offset: f64,
    /// Amplitude about the operating point.
    pub amplitude: f64,
    /// Clip bound: the reference stays in [−limit, limit].
    pub limit: f64,
    /// Slew-rate limit applied (unit/s).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rate_limit: Option<f64>,
    /// Excitation figures (excited channels only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub analysis: Option<ChannelAnalysis>,
}

/// One planned experiment (without its samples).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct Experiment {
    /// Position in the run order, from 1.
    pub seq: u32,
    /// Human code, e.g. `DYN-1.5kn-sway-r1`.
    pub code: String,
    /// Family.
    pub family: ExperimentFamily,
    /// Index into the grid (none for the validation run, which spans it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub grid_index: Option<usize>,
    /// Grid speed (m/s).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub grid_speed_mps: Option<f64>,
    /// Excited DOFs.
    pub dofs: Vec<Dof>,
    /// Sign of a static run (+1 / −1).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sign: Option<i8>,
    /// Repetition, from 1.
    pub repetition: u32,
    /// For a deciding run (see `CampaignSpec::deciding`): the two
    /// look-alike hypotheses it separates.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub separates: Option<[String; 2]>,
    /// What the pilot does, in words.
    pub instruction: String,
    /// Run length (s).
    pub duration_s: f64,
    /// Schedule sample rate: the controller rate (Hz).
    pub sample_rate_hz: f64,
    /// Columns.
    pub channels: Vec<ChannelPlan>,
    /// Things the supervisor should know.
    pub warnings: Vec<String>,
}

/// Sampled reference columns of one experiment, at `sample_rate_hz`.
#[derive(Debug, Clone, PartialEq)]
pub struct Schedule {
    /// Sample rate (Hz); t_k = k / rate.
    pub sample_rate_hz: f64,
    /// Column names, as in [`Experiment::channels`].
    pub columns: Vec<String>,
    /// One vector per column, all of equal length.
    pub values: Vec<Vec<f64>>,
}

impl Schedule {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.values.first().map_or(0, Vec::len)
    }

    /// True when there are no samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// An experiment with its schedule.
#[derive(Debug, Clone, PartialEq)]
pub struct PlannedExperiment {
    /// Description and checks.
    pub experiment: Experiment,
    /// Samples.
    pub schedule: Schedule,
}

/// Totals of a plan.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct PlanTotals {
    /// Number of experiments.
    pub experiments: usize,
    /// Experiments per family.
    pub per_family: BTreeMap<String, usize>,
    /// Sum of run lengths (s).
    pub run_time_s: f64,
    /// Set-up time between runs (s).
    pub setup_time_s: f64,
    /// Total trial time (s).
    pub total_time_s: f64,
}

/// A complete plan.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// Experiments in run order.
    pub experiments: Vec<PlannedExperiment>,
    /// Totals.
    pub totals: PlanTotals,
}

impl Plan {
    /// The grid speeds its experiments are flown at (m/s), ascending, each once.
    pub fn grid_speeds(&self) -> Vec<f64> {
        let mut g: Vec<f64> = self
            .experiments
            .iter()
            .filter_map(|p| p.experiment.grid_speed_mps)
            .collect();
        g.sort_by(f64::total_cmp);
        g.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
        g
    }
}
