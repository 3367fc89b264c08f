//! Why an identification could not be done, naming the setting or run.

use crate::estimation::Cancelled;

/// An identification failure: the field (setting path, `run_ids`, a run id)
/// and what to do about it.
#[derive(Debug, Clone, PartialEq)]
pub enum IdentifyError {
    /// The request or the data cannot give a model; `field` names where.
    Invalid {
        /// Setting path (`settings.structure`), `run_ids`, or `runs[<id>]`.
        field: String,
        /// What is wrong and what to do.
        message: String,
    },
    /// Stopped on request.
    Cancelled,
}

impl IdentifyError {
    /// An error naming `field`.
    pub fn invalid(field: impl Into<String>, message: impl Into<String>) -> Self {
        IdentifyError::Invalid {
            field: field.into(),
            message: message.into(),
        }
    }

    /// The field at fault (`""` for a cancellation).
    pub fn field(&self) -> &str {
        match self {
            IdentifyError::Invalid { field, .. } => field,
            IdentifyError::Cancelled => "",
        }
    }
}

impl std::fmt::Display for IdentifyError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            IdentifyError::Invalid { field, message } => write!(f, "{field}: {message}"),
            IdentifyError::Cancelled => f.write_str("cancelled"),
        }
    }
}

impl std::error::Error for IdentifyError {}

impl From<Cancelled> for IdentifyError {
    fn from(_: Cancelled) -> Self {
        IdentifyError::Cancelled
    }
}

/// A λ-filter estimation's failure, naming its field.
impl From<crate::estimation::lambda::LambdaError> for IdentifyError {
    fn from(e: crate::estimation::lambda::LambdaError) -> Self {
        match e {
            crate::estimation::lambda::LambdaError::Cancelled => IdentifyError::Cancelled,
            e => IdentifyError::invalid(e.field().to_string(), e.to_string()),
        }
    }
}
