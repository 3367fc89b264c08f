//! Typed errors of discovery: every invalid input names its field.

use std::fmt;

use crate::estimation::Cancelled;

/// Why discovery could not run.
#[derive(Debug, Clone, PartialEq)]
pub enum DiscoveryError {
    /// An input is malformed; `field` names it (e.g. `estimation_runs[1].nu`).
    Invalid {
        /// The offending field.
        field: String,
        /// What is wrong, in words.
        message: String,
    },
    /// The caller cancelled through its progress sink.
    Cancelled,
}

impl DiscoveryError {
    /// An invalid-field error.
    pub fn invalid(field: impl Into<String>, message: impl Into<String>) -> Self {
        DiscoveryError::Invalid {
            field: field.into(),
            message: message.into(),
        }
    }

    /// The offending field ("" when cancelled).
    pub fn field(&self) -> &str {
        match self {
            DiscoveryError::Invalid { field, .. } => field,
            DiscoveryError::Cancelled => "",
        }
    }
}

impl fmt::Display for DiscoveryError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DiscoveryError::Invalid { field, message } => write!(f, "`{field}`: {message}"),
            DiscoveryError::Cancelled => f.write_str("cancelled"),
        }
    }
}

impl std::error::Error for DiscoveryError {}

impl From<Cancelled> for DiscoveryError {
    fn from(_: Cancelled) -> Self {
        DiscoveryError::Cancelled
    }
}
