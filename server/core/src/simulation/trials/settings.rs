//! How a simulated trial is flown and logged ([`TrialSettings`]: noise,
//! controller feedback, lead-in, integration substeps) and why a run could
//! not be flown ([`TrialError`]).

use std::fmt;

use crate::logs::schema::pose_column;
use crate::planning::Dof;
use crate::simulation::rov::SimError;

/// Why a run could not be flown; names the field at fault.
#[derive(Debug, Clone, PartialEq)]
pub enum TrialError {
    /// An input is missing, inconsistent or out of range.
    Invalid {
        /// The field, e.g. `settings.noise.nu[v]` or `schedule.columns[2]`.
        field: String,
        /// What is wrong, in words.
        reason: String,
    },
    /// The truth simulator refused the parameters or diverged.
    Simulation {
        /// Code of the experiment being flown.
        code: String,
        /// The simulator's error.
        source: SimError,
    },
}

impl TrialError {
    pub(crate) fn invalid(field: impl Into<String>, reason: impl Into<String>) -> Self {
        TrialError::Invalid {
            field: field.into(),
            reason: reason.into(),
        }
    }

    /// The field at fault (`truth…` for simulator errors).
    pub fn field(&self) -> String {
        match self {
            TrialError::Invalid { field, .. } => field.clone(),
            TrialError::Simulation { .. } => "truth".into(),
        }
    }
}

impl fmt::Display for TrialError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TrialError::Invalid { field, reason } => write!(f, "{field}: {reason}"),
            TrialError::Simulation { code, source } => write!(f, "{code}: {source}"),
        }
    }
}

impl std::error::Error for TrialError {}

/// Standard deviations of the white measurement noise the logger adds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeasurementNoise {
    /// On u v w (m/s) and p q r (rad/s).
    pub nu: [f64; 6],
    /// On x y z (m) and φ θ ψ (rad).
    pub eta: [f64; 6],
}

impl MeasurementNoise {
    /// No noise.
    pub const NONE: MeasurementNoise = MeasurementNoise {
        nu: [0.0; 6],
        eta: [0.0; 6],
    };
}

impl Default for MeasurementNoise {
    /// A work-class ROV's navigation: DVL velocities ±1 cm/s, gyro rates
    /// ±0.005 rad/s, USBL position ±0.5 m, depth sensor ±5 cm, attitude
    /// ±0.002 rad, heading ±0.005 rad.
    fn default() -> Self {
        MeasurementNoise {
            nu: [0.01, 0.01, 0.01, 0.005, 0.005, 0.005],
            eta: [0.5, 0.5, 0.05, 0.002, 0.002, 0.005],
        }
    }
}

/// What the vehicle's controller feeds back.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Feedback {
    /// The true ν and η (the log alone is noisy): the plan's excitation
    /// exactly as designed.
    #[default]
    True,
    /// The measured ν and η, with the logger's noise drawn at every
    /// controller sample; the log records what the controller saw. Sensor
    /// noise then also moves the vehicle through the loop, as at sea.
    Measured,
}

/// How to fly and log.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrialSettings {
    /// Measurement noise of the logger.
    pub noise: MeasurementNoise,
    /// Seed of the measurement noise ([`fly_campaign`] derives one per run).
    pub seed: u64,
    /// Cut every run after this many seconds (demos, tests); `None` = full.
    pub max_duration_s: Option<f64>,
    /// Unlogged lead-in holding the first references (s); `None` =
    /// [`LEAD_IN_TIME_CONSTANTS`] × the largest modeled time constant.
    pub lead_in_s: Option<f64>,
    /// RK4 steps per controller interval.
    pub substeps: usize,
    /// What the controller feeds back.
    pub feedback: Feedback,
}

impl Default for TrialSettings {
    fn default() -> Self {
        TrialSettings {
            noise: MeasurementNoise::default(),
            seed: 0,
            max_duration_s: None,
            lead_in_s: None,
            substeps: 5,
            feedback: Feedback::True,
        }
    }
}

impl TrialSettings {
    /// Checks the settings; errors name the field.
    pub fn validate(&self) -> Result<(), TrialError> {
        for d in Dof::ALL {
            let i = d.index();
            for (name, v) in [
                (
                    format!("settings.noise.nu[{}]", d.velocity_symbol()),
                    self.noise.nu[i],
                ),
                (
                    format!("settings.noise.eta[{}]", pose_column(d)),
                    self.noise.eta[i],
                ),
            ] {
                if !(v.is_finite() && v >= 0.0) {
                    return Err(TrialError::invalid(
                        name,
                        format!("must be a finite standard deviation ≥ 0 (got {v})"),
                    ));
                }
            }
        }
        if let Some(m) = self.max_duration_s
            && !(m.is_finite() && m > 0.0)
        {
            return Err(TrialError::invalid(
                "settings.max_duration_s",
                format!("must be a finite number of seconds > 0 (got {m})"),
            ));
        }
        if let Some(l) = self.lead_in_s
            && !(l.is_finite() && l >= 0.0)
        {
            return Err(TrialError::invalid(
                "settings.lead_in_s",
                format!("must be a finite number of seconds ≥ 0 (got {l})"),
            ));
        }
        if self.substeps == 0 || self.substeps > 1000 {
            return Err(TrialError::invalid(
                "settings.substeps",
                format!("must be between 1 and 1000 (got {})", self.substeps),
            ));
        }
        Ok(())
    }
}
