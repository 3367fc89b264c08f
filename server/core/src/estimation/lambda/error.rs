//! Typed errors of the λ-filter identification; every variant names the
//! offending field as the API spells it (`runs[2].gamma`, `settings.t_lambda`).

use std::fmt;

use crate::estimation::Cancelled;

/// Why a λ-filter identification could not run.
#[derive(Debug, Clone, PartialEq)]
pub enum LambdaError {
    /// Matrices whose shapes disagree (ν vs γ, columns vs DOFs, masks).
    Shape {
        /// The offending field.
        field: String,
        /// What was wrong with it.
        message: String,
    },
    /// A NaN or infinite value in a signal or a setting.
    NonFinite {
        /// The offending field.
        field: String,
        /// First offending sample (row), if it is a signal.
        index: Option<usize>,
        /// What was wrong with it.
        message: String,
    },
    /// Too few samples (or runs) for the number of free parameters.
    TooFewSamples {
        /// The offending field.
        field: String,
        /// What was wrong with it.
        message: String,
    },
    /// A parameter out of its domain (T ≤ 0, T not ≫ h, h ≤ 0, …).
    InvalidParameter {
        /// The offending field.
        field: String,
        /// What was wrong with it.
        message: String,
    },
    /// A matrix that must be inverted (B, M₀, the posterior information) or
    /// whose logarithm must exist (Φ) is singular or has none.
    Singular {
        /// The offending field.
        field: String,
        /// What was wrong with it.
        message: String,
    },
    /// The progress sink asked to stop.
    Cancelled,
}

impl LambdaError {
    /// The offending field (`""` for [`LambdaError::Cancelled`]).
    pub fn field(&self) -> &str {
        match self {
            LambdaError::Shape { field, .. }
            | LambdaError::NonFinite { field, .. }
            | LambdaError::TooFewSamples { field, .. }
            | LambdaError::InvalidParameter { field, .. }
            | LambdaError::Singular { field, .. } => field,
            LambdaError::Cancelled => "",
        }
    }

    pub(crate) fn shape(field: impl Into<String>, message: impl Into<String>) -> Self {
        LambdaError::Shape {
            field: field.into(),
            message: message.into(),
        }
    }

    pub(crate) fn too_few(field: impl Into<String>, message: impl Into<String>) -> Self {
        LambdaError::TooFewSamples {
            field: field.into(),
            message: message.into(),
        }
    }

    pub(crate) fn invalid(field: impl Into<String>, message: impl Into<String>) -> Self {
        LambdaError::InvalidParameter {
            field: field.into(),
            message: message.into(),
        }
    }

    pub(crate) fn singular(field: impl Into<String>, message: impl Into<String>) -> Self {
        LambdaError::Singular {
            field: field.into(),
            message: message.into(),
        }
    }

    pub(crate) fn non_finite(
        field: impl Into<String>,
        index: Option<usize>,
        message: impl Into<String>,
    ) -> Self {
        LambdaError::NonFinite {
            field: field.into(),
            index,
            message: message.into(),
        }
    }
}

impl fmt::Display for LambdaError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LambdaError::Shape { field, message } => write!(f, "shape of `{field}`: {message}"),
            LambdaError::NonFinite { field, message, .. } => {
                write!(f, "non-finite value in `{field}`: {message}")
            }
            LambdaError::TooFewSamples { field, message } => {
                write!(f, "too few samples in `{field}`: {message}")
            }
            LambdaError::InvalidParameter { field, message } => {
                write!(f, "invalid parameter `{field}`: {message}")
            }
            LambdaError::Singular { field, message } => write!(f, "singular `{field}`: {message}"),
            LambdaError::Cancelled => f.write_str("cancelled"),
        }
    }
}

impl std::error::Error for LambdaError {}

impl From<Cancelled> for LambdaError {
    fn from(_: Cancelled) -> Self {
        LambdaError::Cancelled
    }
}

/// Requires every value of `x` to be finite.
pub(crate) fn require_finite_matrix(
    field: &str,
    x: &nalgebra::DMatrix<f64>,
) -> Result<(), LambdaError> {
    for r in 0..x.nrows() {
        for c in 0..x.ncols() {
            let v = x[(r, c)];
            if !v.is_finite() {
                return Err(LambdaError::non_finite(
                    field,
                    Some(r),
                    format!("row {r}, column {c} is {v}"),
                ));
            }
        }
    }
    Ok(())
}

/// Requires a finite, strictly positive scalar.
pub(crate) fn require_positive(field: &str, v: f64) -> Result<(), LambdaError> {
    if !v.is_finite() {
        return Err(LambdaError::non_finite(
            field,
            None,
            format!("must be finite, got {v}"),
        ));
    }
    if v <= 0.0 {
        return Err(LambdaError::invalid(field, format!("must be > 0, got {v}")));
    }
    Ok(())
}
