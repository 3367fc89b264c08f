//! What an identification hands to storage: the model document, its
//! validation on held-out runs, and the provenance of the data.

use serde::Serialize;

use super::document::ModelDocument;
use crate::validation::ValidationReport;

/// Validation of the model on one held-out run.
#[derive(Debug, Clone, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct RunValidation {
    /// The run.
    pub run_id: String,
    /// Its name.
    pub run_name: String,
    /// Fits (1-step, k-step, simulation), residual tests and plot series.
    pub report: ValidationReport,
}

/// A finished identification.
#[derive(Debug, Clone)]
pub struct Identified {
    /// The model.
    pub document: ModelDocument,
    /// Validation per held-out run.
    pub validation: Vec<RunValidation>,
    /// Runs the model was estimated from.
    pub estimation_run_ids: Vec<String>,
    /// Runs held out for validation.
    pub validation_run_ids: Vec<String>,
    /// The settings as used (defaults filled in).
    pub settings_used: serde_json::Value,
}
