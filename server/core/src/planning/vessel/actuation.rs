//! How a vessel is actuated: generalized forces τ per DOF, or thrusters
//! through τ = T K u (eq. 4/7 of Fossen et al.) whose columns an azimuth's
//! logged angle α(t) turns.

use serde::{Deserialize, Serialize};

use super::HeadingUnit;
use crate::planning::error::{PlanError, positive};

/// What a thruster does, to assign it to the decoupled DP manoeuvres
/// (sec. 4.2 of Fossen et al.).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum ThrusterKind {
    /// Main propeller: surge (manoeuvre 1).
    Main,
    /// Tunnel thruster: sway and yaw (manoeuvre 2).
    Tunnel,
    /// Azimuth thruster: run alone (manoeuvre 3).
    Azimuth,
}

/// What a log's thruster column `thr_j` records, and how it is read as the
/// command u_j of τ = T K u. Thrust goes with |p − p₀|(p − p₀) for a
/// controllable-pitch propeller (Fossen et al. 1995, eq. 5) and with |n|·n
/// for a fixed-pitch one at shaft speed n (Fossen 2011, sec. 12.2); a
/// measured thrust is u itself up to scale. Sea-trial loggers record shaft
/// speed or pitch, not forces.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum ThrusterSignal {
    /// The normalized command u_j itself.
    #[default]
    Command,
    /// Propeller shaft speed n (rpm, signed: negative astern):
    /// u = |n|·n / n_rated².
    ShaftSpeed {
        /// Rated shaft speed n_rated (rpm, > 0): u = ±1 there.
        rated_rpm: f64,
    },
    /// Propeller pitch p in the logger's unit (%, P/D, degrees):
    /// u = |p − p₀|(p − p₀) / (p_full − p₀)².
    Pitch {
        /// Pitch of zero thrust p₀.
        zero_thrust: f64,
        /// Pitch of full ahead thrust p_full (≠ p₀): u = 1 there.
        full_ahead: f64,
    },
    /// Measured thrust f (N): u = f / f_rated.
    Thrust {
        /// Rated thrust f_rated (N, > 0): u = ±1 there.
        rated_n: f64,
    },
}

impl ThrusterSignal {
    /// The command u of a logged value `x`.
    pub fn command(&self, x: f64) -> f64 {
        match *self {
            ThrusterSignal::Command => x,
            ThrusterSignal::ShaftSpeed { rated_rpm } => x.abs() * x / (rated_rpm * rated_rpm),
            ThrusterSignal::Pitch {
                zero_thrust,
                full_ahead,
            } => {
                let d = x - zero_thrust;
                let full = full_ahead - zero_thrust;
                d.abs() * d / (full * full)
            }
            ThrusterSignal::Thrust { rated_n } => x / rated_n,
        }
    }

    /// What is logged and how it is read, for notes: e.g. "shaft speed n
    /// (rpm), u = |n|·n/(180 rpm)²"; `None` for commands.
    pub fn describe(&self) -> Option<String> {
        use crate::numbers::sig3;
        match *self {
            ThrusterSignal::Command => None,
            ThrusterSignal::ShaftSpeed { rated_rpm } => Some(format!(
                "shaft speed n (rpm), u = |n|·n/({} rpm)²",
                sig3(rated_rpm)
            )),
            ThrusterSignal::Pitch {
                zero_thrust,
                full_ahead,
            } => Some(format!(
                "pitch p, u = |p − p₀|(p − p₀)/(p_full − p₀)² with p₀ = {}, p_full = {}",
                sig3(zero_thrust),
                sig3(full_ahead)
            )),
            ThrusterSignal::Thrust { rated_n } => {
                Some(format!("thrust f (N), u = f/({} N)", sig3(rated_n)))
            }
        }
    }

    pub(super) fn validate(&self, field: &str) -> Result<(), PlanError> {
        match *self {
            ThrusterSignal::Command => Ok(()),
            ThrusterSignal::ShaftSpeed { rated_rpm } => {
                positive(&format!("{field}.rated_rpm"), rated_rpm).map(drop)
            }
            ThrusterSignal::Thrust { rated_n } => {
                positive(&format!("{field}.rated_n"), rated_n).map(drop)
            }
            ThrusterSignal::Pitch {
                zero_thrust,
                full_ahead,
            } => {
                for (name, v) in [("zero_thrust", zero_thrust), ("full_ahead", full_ahead)] {
                    if !v.is_finite() {
                        return Err(PlanError::invalid(
                            format!("{field}.{name}"),
                            "must be a finite number",
                        ));
                    }
                }
                if full_ahead == zero_thrust {
                    return Err(PlanError::invalid(
                        format!("{field}.full_ahead"),
                        "full-ahead pitch must differ from the zero-thrust pitch",
                    ));
                }
                Ok(())
            }
        }
    }
}

/// One thruster input channel u_i (eq. 5: u_i = |p_i − p_i0|(p_i − p_i0),
/// normalized so that |u_i| ≤ max_command).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct Thruster {
    /// Name the pilots use, e.g. "port main propeller".
    pub name: String,
    /// Role in the decoupled manoeuvres.
    pub kind: ThrusterKind,
    /// Largest |u_i| (normalized command, 1.0 = 100 % pitch).
    pub max_command: f64,
    /// Largest rate of change of u_i per second.
    pub max_rate: f64,
    /// Thrusters with the same group share one thrust coefficient K″ in
    /// the parallel EKF (as the paper's two mains share K1 = K2), at most
    /// four groups. Without any group, the paper's six-thruster layout
    /// takes eq. 47's groups, four or fewer thrusters one coefficient
    /// each, more thrusters one per kind.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coefficient_group: Option<String>,
    /// What the log's column `thr_j` records (default: the command u_j);
    /// read as u_j when a run is loaded, and said so in its summary.
    #[serde(default, skip_serializing_if = "is_command")]
    pub signal: ThrusterSignal,
    /// An azimuth whose logger records its angle α_j (column `azi_j`):
    /// its force then points along α(t) and its yaw moment follows from
    /// its position, so T″ varies over the run. Its column of
    /// `configuration` is T″ at the angle the plan holds.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub logged_angle: Option<LoggedAngle>,
}

/// An azimuth thruster's logged angle and position (Fossen 2011, sec.
/// 11.2.1: a thruster at (l_x, l_y) pushing at α gives the column
/// (cos α, sin α, l_x sin α − l_y cos α) of T).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct LoggedAngle {
    /// Unit of `azi_j`: the angle from the bow, positive to starboard
    /// (default radians).
    #[serde(default)]
    pub unit: HeadingUnit,
    /// Position forward of the origin l_x (m).
    pub x_m: f64,
    /// Position to starboard of the origin l_y (m).
    pub y_m: f64,
}

impl LoggedAngle {
    /// The column of T″ (Bis: direction cosines, yaw arm over the ship
    /// length `length_m`) at angle `alpha` (rad).
    pub fn column(&self, alpha: f64, length_m: f64) -> [f64; 3] {
        let (s, c) = alpha.sin_cos();
        [c, s, (self.x_m * s - self.y_m * c) / length_m]
    }
}

fn is_command(s: &ThrusterSignal) -> bool {
    *s == ThrusterSignal::Command
}

/// How the vessel is actuated.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum InputChannels {
    /// Generalized forces τ per modeled DOF (the thesis's logger records τ).
    GeneralizedForces,
    /// Thruster commands u with a thruster configuration matrix T
    /// (rows: modeled DOFs in order, columns: thrusters), τ = T K u.
    Thrusters {
        /// The thrusters, in the column order of T.
        thrusters: Vec<Thruster>,
        /// T, row-major: one row per modeled DOF.
        configuration: Vec<Vec<f64>>,
    },
}
