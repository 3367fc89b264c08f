//! Errors of the N4SID identification, each naming the offending field.

use crate::estimation::Cancelled;

/// Why [`n4sid`](super::n4sid) could not return a model.
#[derive(Debug, Clone, PartialEq)]
pub enum N4sidError {
    /// `experiments` is empty.
    NoExperiments,
    /// A signal has the wrong shape (`field` is "u" or "y").
    Shape {
        experiment: usize,
        field: &'static str,
        expected: String,
        found: String,
    },
    /// A signal holds NaN or ±∞.
    NonFinite {
        experiment: usize,
        field: &'static str,
        row: usize,
        column: usize,
    },
    /// A channel is identically zero over all experiments (no scale).
    ZeroChannel { field: &'static str, column: usize },
    /// An experiment is shorter than the 2i samples of one Hankel column, or
    /// all together give fewer Hankel columns than rows 2i(m + l).
    TooFewSamples {
        field: &'static str,
        samples: usize,
        required: usize,
    },
    /// An invalid setting (`field` names it).
    Setting { field: &'static str, reason: String },
    /// The fixed order exceeds what the data and horizon can reveal.
    OrderTooLarge {
        field: &'static str,
        order: usize,
        max: usize,
    },
    /// The inputs are not persistently exciting of order 2i: [U_f; U_p] is
    /// rank deficient (`block_row` is the first dependent row).
    NotPersistentlyExciting { block_row: usize },
    /// The Riccati equation of the innovation form has no stabilizing
    /// solution (e.g. the residual covariance R is singular).
    Riccati { reason: String },
    /// A dense factorization failed (should not happen on finite data).
    Numerical { step: &'static str },
    /// The progress sink asked to stop.
    Cancelled,
}

impl From<Cancelled> for N4sidError {
    fn from(_: Cancelled) -> Self {
        N4sidError::Cancelled
    }
}

impl std::fmt::Display for N4sidError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        use N4sidError::*;
        match self {
            NoExperiments => f.write_str("experiments: no experiment given"),
            Shape {
                experiment,
                field,
                expected,
                found,
            } => write!(
                f,
                "experiments[{experiment}].{field}: expected {expected}, found {found}"
            ),
            NonFinite {
                experiment,
                field,
                row,
                column,
            } => write!(
                f,
                "experiments[{experiment}].{field}: non-finite value at row {row}, column {column}"
            ),
            ZeroChannel { field, column } => {
                write!(f, "{field}: column {column} is zero in every experiment")
            }
            TooFewSamples {
                field,
                samples,
                required,
            } => write!(
                f,
                "{field}: {samples} samples, at least {required} required"
            ),
            Setting { field, reason } => write!(f, "settings.{field}: {reason}"),
            OrderTooLarge { field, order, max } => {
                write!(
                    f,
                    "settings.{field}: order {order} exceeds the maximum {max}"
                )
            }
            NotPersistentlyExciting { block_row } => write!(
                f,
                "u: inputs not persistently exciting of order 2i (row {block_row} of [U_f; U_p] is dependent)"
            ),
            Riccati { reason } => write!(f, "Kalman gain: {reason}"),
            Numerical { step } => write!(f, "numerical failure in {step}"),
            Cancelled => f.write_str("cancelled"),
        }
    }
}

impl std::error::Error for N4sidError {}
