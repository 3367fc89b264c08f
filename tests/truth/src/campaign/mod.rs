//! A sea-trial campaign flown the way a trial team flies one (thesis ch. 3):
//! per grid speed a static run and one dynamic run per DOF, then a long
//! validation run between and beyond the grid, each logged at 10 Hz as one
//! file and as a control/nav pair on two unsynchronized clocks.

mod external;
mod fly;
mod io;
mod plan;
mod spec;

pub use external::{
    Channel, ExternalRun, campaign_as_external, external_envelope, fly_external,
    fly_external_campaign, fly_external_runs,
};
pub use fly::{fly_campaign, run_seed};
pub use spec::{CampaignSpec, NoiseSpec};

use nalgebra::DMatrix;

use crate::controller::ControllerConfig;
use crate::signals::SignalKind;
use crate::vessel::Vessel;

/// A degree of freedom, in Fossen's order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Dof {
    /// x, u, X.
    Surge,
    /// y, v, Y.
    Sway,
    /// z, w, Z.
    Heave,
    /// φ, p, K.
    Roll,
    /// θ, q, M.
    Pitch,
    /// ψ, r, N.
    Yaw,
}

impl Dof {
    /// All six, surge first.
    pub const ALL: [Dof; 6] = [
        Dof::Surge,
        Dof::Sway,
        Dof::Heave,
        Dof::Roll,
        Dof::Pitch,
        Dof::Yaw,
    ];

    /// Index 0…5 into ν, η, τ.
    pub fn index(self) -> usize {
        self as usize
    }

    /// `surge`, `sway`, `heave`, `roll`, `pitch`, `yaw`.
    pub fn label(self) -> &'static str {
        ["surge", "sway", "heave", "roll", "pitch", "yaw"][self.index()]
    }
}

/// What a run is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Role {
    /// Held at the grid speed, nothing else excited.
    Static,
    /// One DOF excited around the grid speed.
    Dynamic,
    /// Held out: speeds between and beyond the grid, every DOF excited.
    Validation,
}

impl Role {
    /// `static`, `dynamic`, `validation`.
    pub fn label(self) -> &'static str {
        match self {
            Role::Static => "static",
            Role::Dynamic => "dynamic",
            Role::Validation => "validation",
        }
    }
}

/// Column names of the single-file log (SI, radians), in file order.
pub const SINGLE_COLUMNS: [&str; 19] = [
    "t", "tau_X", "tau_Y", "tau_Z", "tau_K", "tau_M", "tau_N", "u", "v", "w", "p", "q", "r", "x",
    "y", "z", "phi", "theta", "psi",
];
/// Column names of the control file: time, τ and the shared depth `z`.
pub const CONTROL_COLUMNS: [&str; 8] = [
    "t", "tau_X", "tau_Y", "tau_Z", "tau_K", "tau_M", "tau_N", "z",
];
/// Column names of the nav file: time, ν and η (η holds the shared `z`).
pub const NAV_COLUMNS: [&str; 13] = [
    "t", "u", "v", "w", "p", "q", "r", "x", "y", "z", "phi", "theta", "psi",
];

/// A 10 Hz log as written to the single file: N rows, control clock.
#[derive(Debug, Clone, PartialEq)]
pub struct Log {
    /// Time stamps (s), control clock.
    pub t: Vec<f64>,
    /// Logged τ = τ_cmd held at each stamp (N×6; N, N·m).
    pub tau: DMatrix<f64>,
    /// Measured ν (N×6; m/s, rad/s), noisy.
    pub nu: DMatrix<f64>,
    /// Measured η (N×6; m, rad), noisy; ψ wrapped to (−π, π].
    pub eta: DMatrix<f64>,
}

/// The nav computer's file: its own rate, its own noise, its own clock.
#[derive(Debug, Clone, PartialEq)]
pub struct NavLog {
    /// Nav-clock stamps (s): nav t + offset = control t.
    pub t: Vec<f64>,
    /// Measured ν (M×6).
    pub nu: DMatrix<f64>,
    /// Measured η (M×6); ψ wrapped.
    pub eta: DMatrix<f64>,
}

/// What really happened, for grading.
#[derive(Debug, Clone, PartialEq)]
pub struct TruthRecord {
    /// True ν at the log stamps (N×6), noise-free.
    pub nu: DMatrix<f64>,
    /// True η at the log stamps (N×6), ψ unwrapped.
    pub eta: DMatrix<f64>,
    /// Force on the hull at the log stamps (N×6): τ_cmd after actuator effects.
    pub tau_applied: DMatrix<f64>,
    /// Every 20 Hz command τ_cmd of the run (2N×6); row 2k is log row k.
    pub tau_cmd_20hz: DMatrix<f64>,
    /// Control-clock stamps of the 20 Hz commands.
    pub t_20hz: Vec<f64>,
}

/// A run's truth metadata.
#[derive(Debug, Clone, PartialEq)]
pub struct RunMeta {
    /// File stem, e.g. `u1.00_dyn_sway_prbs`.
    pub name: String,
    /// Static, dynamic or validation.
    pub role: Role,
    /// Grid speed u₀ (m/s); None for validation.
    pub grid_speed: Option<f64>,
    /// DOFs excited (empty for statics; all six for validation).
    pub excited: Vec<Dof>,
    /// Shape of the excitation.
    pub signal: SignalKind,
    /// Amplitude of the main excitation (m/s or rad or rad/s; 0 for statics).
    pub amplitude: f64,
    /// Half period (square) or bit time (PRBS) (s); None otherwise.
    pub switch_time_s: Option<f64>,
    /// Forward speeds flown in order (validation staircase; else `[u₀]`).
    pub speeds: Vec<f64>,
    /// First log stamp (s), control clock.
    pub start_s: f64,
    /// Logged duration (s): rows / 10.
    pub duration_s: f64,
    /// The campaign's clock offset (s): nav t + offset = control t.
    pub clock_offset_s: f64,
    /// Fraction of 20 Hz commands with any DOF at its limit.
    pub saturated_fraction: f64,
}

/// One flown run.
#[derive(Debug, Clone, PartialEq)]
pub struct Run {
    /// Truth metadata.
    pub meta: RunMeta,
    /// The 10 Hz single-file log.
    pub log: Log,
    /// The nav file of the two-file variant (the control file is `log`'s
    /// t, τ and z).
    pub nav: NavLog,
    /// Noise-free truth.
    pub truth: TruthRecord,
}

/// A flown campaign.
#[derive(Debug, Clone, PartialEq)]
pub struct Campaign {
    /// The true vessel.
    pub vessel: Vessel,
    /// What was asked for.
    pub spec: CampaignSpec,
    /// The seed it was flown with.
    pub seed: u64,
    /// The one campaign-wide clock offset (s): nav t + offset = control t.
    pub clock_offset_s: f64,
    /// The autopilot the team flew with.
    pub controller: ControllerConfig,
    /// Runs in flying order.
    pub runs: Vec<Run>,
}

impl Campaign {
    /// Runs of `role` at grid speed `u0` (to 1 mm/s).
    pub fn runs_at(&self, u0: f64, role: Role) -> Vec<&Run> {
        self.runs
            .iter()
            .filter(|r| {
                r.meta.role == role && r.meta.grid_speed.is_some_and(|g| (g - u0).abs() < 1e-3)
            })
            .collect()
    }

    /// The validation runs.
    pub fn validation_runs(&self) -> Vec<&Run> {
        self.runs
            .iter()
            .filter(|r| r.meta.role == Role::Validation)
            .collect()
    }
}
