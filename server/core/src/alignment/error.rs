//! The one error of alignment: an unusable input, naming the offending field
//! (a parameter of the called function, or `shared` / `control.<column>` /
//! `nav.<column>` for [`super::align_logs`]) and saying what is wrong in
//! words a pilot or analyst reads. Never a panic.

use std::fmt;

/// Why two logs cannot be aligned.
#[derive(Debug, Clone, PartialEq)]
pub enum AlignError {
    /// An input is malformed: lengths differ, time stamps do not increase, a
    /// column is missing, an option is out of its domain.
    InvalidInput {
        /// Offending parameter or column.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// An input holds NaN or ±infinity.
    NonFinite {
        /// Offending parameter or column.
        field: String,
        /// Index of the first non-finite sample.
        index: usize,
        /// What is wrong, with the bad value.
        message: String,
    },
    /// Fewer samples than the method needs (16 per log).
    TooShort {
        /// Offending parameter or column.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// The shared channel does not vary, so there is nothing to correlate.
    FlatSignal {
        /// Offending parameter or column.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// The logs cannot overlap long enough within the search range.
    InsufficientOverlap {
        /// Offending parameter or column.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// The shared channel is strongly anti-correlated between the logs: one
    /// of them uses the opposite sign convention (e.g. depth vs. height).
    AntiCorrelated {
        /// Offending parameter or column.
        field: String,
        /// What is wrong.
        message: String,
    },
}

impl AlignError {
    /// The name of the offending parameter or column.
    pub fn field(&self) -> &str {
        match self {
            AlignError::InvalidInput { field, .. }
            | AlignError::NonFinite { field, .. }
            | AlignError::TooShort { field, .. }
            | AlignError::FlatSignal { field, .. }
            | AlignError::InsufficientOverlap { field, .. }
            | AlignError::AntiCorrelated { field, .. } => field,
        }
    }

    /// The human-readable message (without the field name).
    pub fn message(&self) -> &str {
        match self {
            AlignError::InvalidInput { message, .. }
            | AlignError::NonFinite { message, .. }
            | AlignError::TooShort { message, .. }
            | AlignError::FlatSignal { message, .. }
            | AlignError::InsufficientOverlap { message, .. }
            | AlignError::AntiCorrelated { message, .. } => message,
        }
    }

    pub(crate) fn invalid(field: &str, message: impl Into<String>) -> Self {
        AlignError::InvalidInput {
            field: field.to_owned(),
            message: message.into(),
        }
    }

    pub(crate) fn too_short(field: &str, message: impl Into<String>) -> Self {
        AlignError::TooShort {
            field: field.to_owned(),
            message: message.into(),
        }
    }

    pub(crate) fn flat(field: &str, message: impl Into<String>) -> Self {
        AlignError::FlatSignal {
            field: field.to_owned(),
            message: message.into(),
        }
    }

    pub(crate) fn overlap(field: &str, message: impl Into<String>) -> Self {
        AlignError::InsufficientOverlap {
            field: field.to_owned(),
            message: message.into(),
        }
    }

    pub(crate) fn anti_correlated(field: &str, message: impl Into<String>) -> Self {
        AlignError::AntiCorrelated {
            field: field.to_owned(),
            message: message.into(),
        }
    }
}

impl fmt::Display for AlignError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.field(), self.message())
    }
}

impl std::error::Error for AlignError {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_names_field_and_message() {
        let e = AlignError::flat("shared", "the shared channel z does not change");
        assert_eq!(e.field(), "shared");
        assert_eq!(
            e.to_string(),
            "shared: the shared channel z does not change"
        );
        let e = AlignError::NonFinite {
            field: "nav_x".into(),
            index: 4,
            message: "nav_x[4] = NaN".into(),
        };
        assert_eq!(e.message(), "nav_x[4] = NaN");
        let boxed: Box<dyn std::error::Error> = Box::new(e.clone());
        assert_eq!(boxed.to_string(), "nav_x: nav_x[4] = NaN");
    }
}
