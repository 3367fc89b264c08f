//! Missing-physics discovery reports: the reports on a model, and one report
//! with the models it links (examined, augmented) and its runs' names.

use std::collections::BTreeMap;

use axum::Json;
use axum::extract::{Path, State};
use serde::Serialize;

use super::{AppState, found};
use crate::error::{ApiResult, ErrorBody};
use crate::storage::discrepancies::{self, DiscrepancySummary};
use crate::storage::models::{self, ModelSummary};
use crate::storage::runs;

/// Discovery reports on a model, newest first.
#[utoipa::path(get, path = "/api/models/{id}/discrepancies", tag = "discovery",
    params(("id" = String, Path, description = "Model id")),
    responses((status = 200, description = "Reports, newest first", body = [DiscrepancySummary]),
              (status = 404, description = "No such model", body = ErrorBody)))]
pub async fn list_model_discrepancies(
    State(s): State<AppState>,
    Path(id): Path<String>,
) -> ApiResult<Json<Vec<DiscrepancySummary>>> {
    found(models::get(&s.db, &id).await?, "model", &id)?;
    Ok(Json(discrepancies::list_for_model(&s.db, &id).await?))
}

/// One discovery report.
#[derive(Debug, Serialize, utoipa::ToSchema)]
pub struct DiscrepancyView {
    /// Metadata and the story in sentences.
    pub discrepancy: DiscrepancySummary,
    /// The model examined.
    pub model: ModelSummary,
    /// The augmented model stored as its next version, when terms were named.
    pub augmented_model: Option<ModelSummary>,
    /// Settings as used.
    pub settings: serde_json::Value,
    /// Runs the augmentation was fitted on.
    pub run_ids: Vec<String>,
    /// Runs held out for the before/after comparison.
    pub validation_run_ids: Vec<String>,
    /// Names of those runs by id.
    pub run_names: BTreeMap<String, String>,
    /// Per grid speed: where the mismatch lives, ranked hypotheses with their
    /// evidence, chosen terms, before/after fits and plots, ambiguities with
    /// the deciding experiment, unexplained structure.
    #[schema(value_type = seatrial_core::identification::discover_campaign::DiscrepancyReport)]
    pub report: serde_json::Value,
}

/// One discovery report with the models it links.
#[utoipa::path(get, path = "/api/discrepancies/{id}", tag = "discovery",
    params(("id" = String, Path, description = "Report id")),
    responses((status = 200, description = "The report", body = DiscrepancyView),
              (status = 404, description = "No such report", body = ErrorBody)))]
pub async fn get_discrepancy(
    State(s): State<AppState>,
    Path(id): Path<String>,
) -> ApiResult<Json<DiscrepancyView>> {
    let d = found(
        discrepancies::get(&s.db, &id).await?,
        "discrepancy report",
        &id,
    )?;
    let model = found(
        models::get(&s.db, &d.summary.model_id).await?,
        "model",
        &d.summary.model_id,
    )?
    .summary;
    let augmented_model = match &d.summary.augmented_model_id {
        Some(mid) => models::get(&s.db, mid).await?.map(|m| m.summary),
        None => None,
    };
    // By id: a deleted run keeps its name in the report.
    let mut run_names = std::collections::BTreeMap::new();
    for rid in d.run_ids.iter().chain(&d.validation_run_ids) {
        if let Some(r) = runs::get(&s.db, rid).await? {
            run_names.insert(r.id, r.name);
        }
    }
    Ok(Json(DiscrepancyView {
        discrepancy: d.summary,
        model,
        augmented_model,
        settings: d.settings,
        run_ids: d.run_ids,
        validation_run_ids: d.validation_run_ids,
        run_names,
        report: d.report,
    }))
}
