//! Typed errors of the EKF: bad input names the offending field.

use crate::estimation::Cancelled;

/// Why an EKF run could not be done.
#[derive(Debug, Clone, PartialEq)]
pub enum EkfError {
    /// No runs were given (the parallel EKF needs N ≥ 1).
    NoRuns,
    /// A matrix or vector has the wrong shape.
    Shape {
        /// The field, e.g. `runs[1].z`.
        field: String,
        /// The shape it must have.
        expected: String,
        /// The shape it has.
        got: String,
    },
    /// A value is NaN or infinite.
    NotFinite {
        /// The field, e.g. `runs[0].u[12, 3]`.
        field: String,
    },
    /// A variance that must be positive (P0, R) or non-negative (Q) is not.
    NonPositive {
        /// The field, e.g. `r[2]`.
        field: String,
        /// Its value.
        value: f64,
    },
    /// A setting is out of its range (e.g. a parameter index ≥ 9).
    Invalid {
        /// The field.
        field: String,
        /// What is wrong.
        reason: String,
    },
    /// The innovation covariance H·P·Hᵀ + R lost positive definiteness
    /// (diverged filter) at this step.
    Diverged {
        /// Sample index.
        step: usize,
    },
    /// The caller cancelled through its progress sink.
    Cancelled,
}

impl std::fmt::Display for EkfError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            EkfError::NoRuns => f.write_str("runs: at least one run (N ≥ 1) is needed"),
            EkfError::Shape {
                field,
                expected,
                got,
            } => write!(f, "{field}: expected shape {expected}, got {got}"),
            EkfError::NotFinite { field } => write!(f, "{field}: value is NaN or infinite"),
            EkfError::NonPositive { field, value } => {
                write!(f, "{field}: variance {value} out of range")
            }
            EkfError::Invalid { field, reason } => write!(f, "{field}: {reason}"),
            EkfError::Diverged { step } => {
                write!(
                    f,
                    "filter diverged at sample {step}: innovation covariance not positive definite"
                )
            }
            EkfError::Cancelled => f.write_str("cancelled"),
        }
    }
}

impl std::error::Error for EkfError {}

impl From<Cancelled> for EkfError {
    fn from(_: Cancelled) -> Self {
        EkfError::Cancelled
    }
}

/// Checks that every entry of `values` is finite.
pub(crate) fn check_finite<'a>(
    field: &str,
    values: impl IntoIterator<Item = &'a f64>,
) -> Result<(), EkfError> {
    match values.into_iter().position(|v| !v.is_finite()) {
        Some(i) => Err(EkfError::NotFinite {
            field: format!("{field}[{i}]"),
        }),
        None => Ok(()),
    }
}

/// Checks a vector length.
pub(crate) fn check_len(field: &str, len: usize, expected: usize) -> Result<(), EkfError> {
    if len == expected {
        Ok(())
    } else {
        Err(EkfError::Shape {
            field: field.to_string(),
            expected: format!("{expected}"),
            got: format!("{len}"),
        })
    }
}

/// Checks variances: finite and > 0 (`strict`) or ≥ 0.
pub(crate) fn check_variances(field: &str, values: &[f64], strict: bool) -> Result<(), EkfError> {
    for (i, &v) in values.iter().enumerate() {
        let ok = v.is_finite() && if strict { v > 0.0 } else { v >= 0.0 };
        if !ok {
            return Err(EkfError::NonPositive {
                field: format!("{field}[{i}]"),
                value: v,
            });
        }
    }
    Ok(())
}
