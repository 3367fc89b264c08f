//! Errors of the ROV truth simulator; each names the field at fault.

use std::fmt;

/// Why a simulation could not be set up or run.
#[derive(Debug, Clone, PartialEq)]
pub enum SimError {
    /// A matrix or signal has the wrong shape.
    Shape {
        /// Name of the field.
        name: String,
        /// The required shape in words.
        expected: String,
        /// Rows × columns found.
        found: (usize, usize),
    },
    /// A field holds NaN or ±∞.
    NonFinite {
        /// Name of the field.
        name: String,
    },
    /// A scalar parameter is out of its range.
    InvalidParameter {
        /// Name of the field (e.g. `actuators.time_constants[surge]`).
        name: String,
        /// The offending value.
        value: f64,
        /// The requirement in words.
        requirement: &'static str,
    },
    /// The inertia matrix is not symmetric positive definite.
    InertiaNotSpd {
        /// What is wrong, in words.
        reason: String,
    },
    /// The linear-damping table is inconsistent.
    DampingTable {
        /// What is wrong, in words.
        reason: String,
    },
    /// The state left the domain of the model during the run.
    Diverged {
        /// Time (s) of the first bad sample.
        t: f64,
        /// What happened, in words.
        reason: &'static str,
    },
}

impl fmt::Display for SimError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SimError::Shape {
                name,
                expected,
                found,
            } => write!(
                f,
                "{name} is {}×{} but must be {expected}",
                found.0, found.1
            ),
            SimError::NonFinite { name } => write!(f, "{name} contains NaN or infinite entries"),
            SimError::InvalidParameter {
                name,
                value,
                requirement,
            } => write!(f, "{name} = {value} must be {requirement}"),
            SimError::InertiaNotSpd { reason } => {
                write!(f, "M must be symmetric positive definite: {reason}")
            }
            SimError::DampingTable { reason } => write!(f, "damping: {reason}"),
            SimError::Diverged { t, reason } => {
                write!(f, "simulation stopped at t = {t} s: {reason}")
            }
        }
    }
}

impl std::error::Error for SimError {}

/// Checks that all `values` of `name` are finite.
pub(crate) fn finite<'a>(
    name: &str,
    values: impl IntoIterator<Item = &'a f64>,
) -> Result<(), SimError> {
    if values.into_iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(SimError::NonFinite { name: name.into() })
    }
}

/// Checks `value ≥ 0` and finite (or +∞ when `allow_inf`).
pub(crate) fn non_negative(name: String, value: f64, allow_inf: bool) -> Result<(), SimError> {
    let ok = value >= 0.0 && (value.is_finite() || (allow_inf && value == f64::INFINITY));
    if ok {
        Ok(())
    } else {
        Err(SimError::InvalidParameter {
            name,
            value,
            requirement: if allow_inf {
                "≥ 0 (or +∞)"
            } else {
                "a finite number ≥ 0"
            },
        })
    }
}
