//! Errors of model construction and evaluation. Each variant names the field
//! at fault so that the service can hand the message to the user verbatim.

use std::fmt;

/// Why a model could not be built, discretized or run.
#[derive(Debug, Clone, PartialEq)]
pub enum ModelError {
    /// A matrix or signal has the wrong shape.
    Shape {
        /// Name of the field (`A`, `B`, `u`, `x0`, `points[2].M`, …).
        name: String,
        /// The required shape in words, e.g. `3×3 (square, like A)`.
        expected: String,
        /// Rows × columns found.
        found: (usize, usize),
    },
    /// A matrix or signal holds NaN or ±∞.
    NonFinite {
        /// Name of the field.
        name: String,
    },
    /// The sample time is not a positive finite number.
    InvalidSampleTime {
        /// The offending h (s).
        h: f64,
    },
    /// A matrix that must be inverted is singular.
    Singular {
        /// Name of the field.
        name: String,
        /// What the inverse was needed for.
        why: &'static str,
    },
    /// The prediction horizon k must be at least 1.
    InvalidHorizon {
        /// The offending k.
        k: usize,
    },
    /// A scalar parameter is out of its range.
    InvalidParameter {
        /// Name of the parameter.
        name: &'static str,
        /// The offending value.
        value: f64,
        /// The requirement in words, e.g. `a finite number ≥ 0`.
        requirement: &'static str,
    },
    /// The list of modelled DOFs is empty or repeats a DOF.
    Dofs {
        /// What is wrong, in words.
        reason: String,
    },
    /// An LPV grid is inconsistent (ordering, counts, DOF sets).
    Grid {
        /// What is wrong, in words.
        reason: String,
    },
}

impl fmt::Display for ModelError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ModelError::Shape {
                name,
                expected,
                found,
            } => write!(
                f,
                "{name} is {}×{} but must be {expected}",
                found.0, found.1
            ),
            ModelError::NonFinite { name } => {
                write!(f, "{name} contains NaN or infinite entries")
            }
            ModelError::InvalidSampleTime { h } => {
                write!(f, "sample time h = {h} s must be positive and finite")
            }
            ModelError::Singular { name, why } => write!(f, "{name} is singular: {why}"),
            ModelError::InvalidHorizon { k } => {
                write!(f, "prediction horizon k = {k} must be at least 1 sample")
            }
            ModelError::InvalidParameter {
                name,
                value,
                requirement,
            } => write!(f, "{name} = {value} must be {requirement}"),
            ModelError::Dofs { reason } => write!(f, "dofs: {reason}"),
            ModelError::Grid { reason } => write!(f, "LPV grid: {reason}"),
        }
    }
}

impl std::error::Error for ModelError {}

/// Checks that `name` is `rows × cols`.
pub(crate) fn check_shape(
    name: &str,
    m: &nalgebra::DMatrix<f64>,
    rows: usize,
    cols: usize,
    expected: impl FnOnce() -> String,
) -> Result<(), ModelError> {
    if m.shape() != (rows, cols) {
        return Err(ModelError::Shape {
            name: name.to_string(),
            expected: expected(),
            found: m.shape(),
        });
    }
    Ok(())
}

/// Checks that every entry of `name` is finite.
pub(crate) fn check_finite<'a>(
    name: &str,
    values: impl IntoIterator<Item = &'a f64>,
) -> Result<(), ModelError> {
    if values.into_iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(ModelError::NonFinite {
            name: name.to_string(),
        })
    }
}

/// Checks that the sample time is positive and finite.
pub(crate) fn check_sample_time(h: f64) -> Result<(), ModelError> {
    if h.is_finite() && h > 0.0 {
        Ok(())
    } else {
        Err(ModelError::InvalidSampleTime { h })
    }
}
