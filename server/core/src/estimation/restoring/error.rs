//! The one error of restoring-force estimation, naming the offending field
//! (`nu`, `eta`, `tau`, `h`, `settings.*`, `segments`) and, when the static
//! runs cannot separate the terms, the experiment that is missing.

use std::fmt;

/// Why W − B, z_G·W − z_B·B and τ_θ cannot be estimated.
#[derive(Debug, Clone, PartialEq)]
pub enum RestoringError {
    /// Shapes differ, a setting is out of its domain.
    InvalidInput {
        /// Offending field.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// A signal holds NaN or ±∞.
    NonFinite {
        /// Offending field.
        field: String,
        /// Row of the first non-finite sample.
        index: usize,
        /// What is wrong.
        message: String,
    },
    /// Fewer steady segments than the least-squares fit needs.
    TooFewSteadySegments {
        /// Always `segments`.
        field: String,
        /// Segments found.
        found: usize,
        /// Segments required.
        required: usize,
        /// What is wrong and what to record.
        message: String,
    },
    /// The attitudes held do not separate the terms of g(η).
    NotIdentifiable {
        /// The signal that did not vary enough (`eta.theta/phi`).
        field: String,
        /// What is wrong and which static experiment is missing.
        message: String,
    },
}

impl RestoringError {
    /// The name of the offending field.
    pub fn field(&self) -> &str {
        match self {
            RestoringError::InvalidInput { field, .. }
            | RestoringError::NonFinite { field, .. }
            | RestoringError::TooFewSteadySegments { field, .. }
            | RestoringError::NotIdentifiable { field, .. } => field,
        }
    }

    /// The message, without the field name.
    pub fn message(&self) -> &str {
        match self {
            RestoringError::InvalidInput { message, .. }
            | RestoringError::NonFinite { message, .. }
            | RestoringError::TooFewSteadySegments { message, .. }
            | RestoringError::NotIdentifiable { message, .. } => message,
        }
    }

    pub(crate) fn invalid(field: &str, message: impl Into<String>) -> Self {
        RestoringError::InvalidInput {
            field: field.to_owned(),
            message: message.into(),
        }
    }

    pub(crate) fn non_finite(field: &str, index: usize) -> Self {
        RestoringError::NonFinite {
            field: field.to_owned(),
            index,
            message: format!("row {index} holds NaN or an infinite value"),
        }
    }
}

impl fmt::Display for RestoringError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.field(), self.message())
    }
}

impl std::error::Error for RestoringError {}
