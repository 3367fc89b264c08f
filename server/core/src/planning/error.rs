//! The one error of planning: an impossible or unsafe request, naming the
//! offending field (a JSON path into the request) and, where there is one,
//! the limit it broke. The service maps it to 422.

use std::fmt;

/// A planning request that cannot be met.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanError {
    /// JSON path of the offending field, e.g. `grid.speeds[7]`.
    pub field: String,
    /// What is wrong, in words a pilot or supervisor reads.
    pub message: String,
    /// The limit that was broken, in SI units, when one applies.
    pub limit: Option<f64>,
}

impl PlanError {
    /// An invalid value without a numeric limit.
    pub fn invalid(field: impl Into<String>, message: impl Into<String>) -> Self {
        PlanError {
            field: field.into(),
            message: message.into(),
            limit: None,
        }
    }

    /// A value beyond a numeric limit.
    pub fn over_limit(field: impl Into<String>, message: impl Into<String>, limit: f64) -> Self {
        PlanError {
            field: field.into(),
            message: message.into(),
            limit: Some(limit),
        }
    }
}

/// Longest name (vessel, campaign, run, thruster), in bytes.
pub const MAX_NAME_LEN: usize = 200;

/// Checks a name people gave: not blank, at most [`MAX_NAME_LEN`] bytes, no
/// control characters (a newline or escape sequence in a name breaks
/// headers, files and terminals); the message never quotes the name.
pub fn check_name(field: &str, name: &str) -> Result<(), PlanError> {
    if name.trim().is_empty() {
        return Err(PlanError::invalid(field, "must not be empty"));
    }
    if name.chars().count() > MAX_NAME_LEN {
        return Err(PlanError::invalid(
            field,
            format!("must be at most {MAX_NAME_LEN} characters"),
        ));
    }
    if let Some((i, c)) = name.chars().enumerate().find(|(_, c)| c.is_control()) {
        return Err(PlanError::invalid(
            field,
            format!(
                "must not contain control characters (U+{:04X} at character {})",
                u32::from(c),
                i + 1
            ),
        ));
    }
    Ok(())
}

impl fmt::Display for PlanError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.field, self.message)
    }
}

impl std::error::Error for PlanError {}

/// Checks that a number is finite and strictly positive.
pub(crate) fn positive(field: &str, value: f64) -> Result<f64, PlanError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(PlanError::invalid(
            field,
            format!("must be a finite number greater than zero (got {value})"),
        ))
    }
}
