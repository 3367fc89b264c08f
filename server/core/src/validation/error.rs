//! The one error of validation: an unusable record, setting or model output,
//! naming the offending field (`u`, `y`, `settings.k`, `residual`,
//! `predict_k_step`, …) and saying what is wrong in plain words. Never a
//! panic.

use std::fmt;

/// Why a model cannot be validated on a record.
#[derive(Debug, Clone, PartialEq)]
pub enum ValidationError {
    /// Shapes differ, a setting is out of its domain.
    InvalidInput {
        /// Offending field.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// A signal holds NaN or ±∞ where a number is needed.
    NonFinite {
        /// Offending field.
        field: String,
        /// Row of the first non-finite sample.
        index: usize,
        /// What is wrong.
        message: String,
    },
    /// Fewer samples than the tests need.
    TooShort {
        /// Offending field.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// The model returned predictions of the wrong shape.
    ModelOutput {
        /// The model method (`predict_k_step`, `simulate`).
        field: String,
        /// What is wrong.
        message: String,
    },
}

impl ValidationError {
    /// The name of the offending field.
    pub fn field(&self) -> &str {
        match self {
            ValidationError::InvalidInput { field, .. }
            | ValidationError::NonFinite { field, .. }
            | ValidationError::TooShort { field, .. }
            | ValidationError::ModelOutput { field, .. } => field,
        }
    }

    /// The message, without the field name.
    pub fn message(&self) -> &str {
        match self {
            ValidationError::InvalidInput { message, .. }
            | ValidationError::NonFinite { message, .. }
            | ValidationError::TooShort { message, .. }
            | ValidationError::ModelOutput { message, .. } => message,
        }
    }

    pub(crate) fn invalid(field: &str, message: impl Into<String>) -> Self {
        ValidationError::InvalidInput {
            field: field.to_owned(),
            message: message.into(),
        }
    }

    pub(crate) fn non_finite(field: &str, index: usize) -> Self {
        ValidationError::NonFinite {
            field: field.to_owned(),
            index,
            message: format!("sample {index} is NaN or infinite"),
        }
    }

    pub(crate) fn too_short(field: &str, message: impl Into<String>) -> Self {
        ValidationError::TooShort {
            field: field.to_owned(),
            message: message.into(),
        }
    }

    pub(crate) fn model_output(field: &str, message: impl Into<String>) -> Self {
        ValidationError::ModelOutput {
            field: field.to_owned(),
            message: message.into(),
        }
    }
}

impl fmt::Display for ValidationError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.field(), self.message())
    }
}

impl std::error::Error for ValidationError {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_names_the_field() {
        let e = ValidationError::non_finite("y", 7);
        assert_eq!(e.field(), "y");
        assert_eq!(e.to_string(), "y: sample 7 is NaN or infinite");
    }
}
