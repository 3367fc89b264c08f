//! Identified models: list, one model (document, validation, ZOH matrices at
//! a chosen h), side-by-side comparison; the exports are in `model_export`.

use axum::Json;
use axum::extract::{Path, State};
use axum::http::HeaderMap;
use axum::response::{IntoResponse, Response};
use seatrial_core::identification::discrete::{DiscreteModel, discretize};
use seatrial_core::identification::document::ModelDocument;
use serde::{Deserialize, Serialize};

use super::model_cache::CachedModel;
use super::query::{ApiQuery, Paging, with_total};
use super::{AppState, blocking, campaign_and_vessel, found};
use crate::clock::CampaignClocks;
use crate::error::{ApiError, ApiResult, ErrorBody};
use crate::jobs::run_inputs::StoredRun;
use crate::processing::{self, RunSummary};
use crate::storage::models::{self, ModelSummary, StoredModel};
use crate::storage::runs;
use seatrial_core::identification::predictor::validate_on_run_with;
use seatrial_core::traces;
use seatrial_core::validation::ValidationSettings;

/// Filters of the model list.
#[derive(Debug, Deserialize, utoipa::IntoParams)]
#[into_params(parameter_in = Query)]
pub struct ModelFilter {
    /// Only models of this campaign.
    pub campaign_id: Option<String>,
    /// Only the versions of this lineage.
    pub lineage_id: Option<String>,
    /// `true`: the deleted versions instead of the live ones (default false).
    pub deleted: Option<bool>,
}

/// Models, newest first (metadata only), without the deleted versions
/// (`?deleted=true` lists those); `limit`/`offset` page the list and the
/// `X-Total-Count` header gives how many match.
#[utoipa::path(get, path = "/api/models", tag = "models", params(ModelFilter, Paging),
    responses((status = 200, description = "Models, newest first", body = [ModelSummary],
                headers(("x-total-count" = i64, description = "Models that match the filters (all pages)"))),
              (status = 400, description = "Malformed query parameter", body = ErrorBody),
              (status = 422, description = "`limit` outside 1–1000", body = ErrorBody)))]
pub async fn list_models(
    State(s): State<AppState>,
    ApiQuery(f): ApiQuery<ModelFilter>,
    ApiQuery(p): ApiQuery<Paging>,
) -> ApiResult<Response> {
    let page = p.page()?;
    let (items, total) = models::page(
        &s.db,
        f.campaign_id.as_deref(),
        f.lineage_id.as_deref(),
        f.deleted.unwrap_or(false),
        page,
    )
    .await?;
    Ok(with_total(items, total))
}

/// A model with provenance, its document and its validation reports.
#[derive(Debug, Serialize, utoipa::ToSchema)]
pub struct ModelView {
    /// Metadata and version.
    pub model: ModelSummary,
    /// Method settings as used.
    pub settings: serde_json::Value,
    /// Estimation runs.
    pub run_ids: Vec<String>,
    /// Runs held out for validation.
    pub validation_run_ids: Vec<String>,
    /// The model: matrices, parameters with standard deviations.
    pub document: ModelDocument,
    /// Validation reports per held-out run.
    #[schema(value_type = Vec<seatrial_core::identification::RunValidation>)]
    pub validation: serde_json::Value,
    /// ZOH-discretized Φ, Γ at the requested `h` (only with `?h=`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub discrete: Option<DiscreteModel>,
}

/// Options of one model.
#[derive(Debug, Deserialize, utoipa::IntoParams)]
#[into_params(parameter_in = Query)]
pub struct ModelQuery {
    /// Sample time h (s) at which to add the ZOH-discretized Φ, Γ.
    pub h: Option<f64>,
}

pub(super) fn view(m: StoredModel) -> ApiResult<ModelView> {
    let document: ModelDocument = serde_json::from_value(m.document).map_err(|e| {
        ApiError::Internal(anyhow::anyhow!("stored model document unreadable: {e}"))
    })?;
    Ok(ModelView {
        model: m.summary,
        settings: m.settings,
        run_ids: m.run_ids,
        validation_run_ids: m.validation_run_ids,
        document,
        validation: m.validation,
        discrete: None,
    })
}

/// One model: provenance, matrices and parameters with standard deviations,
/// validation reports; with `?h=` also the ZOH-discretized Φ, Γ at that h.
#[utoipa::path(get, path = "/api/models/{id}", tag = "models",
    params(("id" = String, Path, description = "Model id"), ModelQuery),
    responses((status = 200, description = "The model", body = ModelView),
              (status = 400, description = "Malformed query parameter (`h` not a number)", body = ErrorBody),
              (status = 404, description = "No such model", body = ErrorBody),
              (status = 422, description = "`h` unusable (not positive; a subspace model's own h differs)", body = ErrorBody)))]
pub async fn get_model(
    State(s): State<AppState>,
    Path(id): Path<String>,
    ApiQuery(q): ApiQuery<ModelQuery>,
    request: HeaderMap,
) -> ApiResult<Response> {
    if let Some(h) = q.h {
        let m = found(models::get(&s.db, &id).await?, "model", &id)?;
        let mut v = view(m)?;
        v.discrete = Some(discretize(&v.document, h).map_err(|msg| ApiError::invalid("h", msg))?);
        return Ok(Json(v).into_response());
    }
    let summary = found(models::summary(&s.db, &id).await?, "model", &id)?;
    let key = serde_json::to_string(&summary)
        .map_err(|e| ApiError::Internal(anyhow::anyhow!("model summary: {e}")))?;
    if let Some(cached) = s.model_cache.get(&id, &key) {
        return Ok(cached.respond(&request));
    }
    let m = found(models::get(&s.db, &id).await?, "model", &id)?;
    let built = blocking(move || -> ApiResult<CachedModel> {
        let key = serde_json::to_string(&m.summary)
            .map_err(|e| ApiError::Internal(anyhow::anyhow!("model summary: {e}")))?;
        let json = serde_json::to_vec(&view(m)?)
            .map_err(|e| ApiError::Internal(anyhow::anyhow!("model view: {e}")))?;
        Ok(CachedModel::new(key, json))
    })
    .await??;
    let built = std::sync::Arc::new(built);
    s.model_cache.put(&id, built.clone());
    Ok(built.respond(&request))
}

/// Which models to compare on which run.
#[derive(Debug, Deserialize, utoipa::IntoParams)]
#[into_params(parameter_in = Query)]
pub struct CompareQuery {
    /// First model.
    pub a: String,
    /// Second model.
    pub b: String,
    /// Further models to overlay, comma-separated ids (at most 6 models in all).
    pub more: Option<String>,
    /// The run both are validated on (best one neither was estimated from).
    pub run_id: String,
    /// Horizon of the k-step predictions (default 10).
    pub k: Option<usize>,
    /// Period of the restarted free runs in seconds (default 10).
    pub restart_s: Option<f64>,
    /// Validate on the window from this time only (s, log time; default:
    /// the first sample).
    pub from_s: Option<f64>,
    /// … up to this time (s; default: the last sample).
    pub to_s: Option<f64>,
}

/// One model's validation in a comparison.
#[derive(Debug, Serialize, utoipa::ToSchema)]
pub struct ComparedModel {
    /// The model.
    pub model: ModelSummary,
    /// True when the run was among the model's estimation runs (its fits
    /// then flatter it).
    pub run_used_for_estimation: bool,
    /// Fits, residual tests and plot series on the run.
    #[schema(value_type = seatrial_core::validation::ValidationReport)]
    pub report: serde_json::Value,
}

/// Models side by side on the same run.
#[derive(Debug, Serialize, utoipa::ToSchema)]
pub struct Comparison {
    /// The run.
    pub run_id: String,
    /// Its name.
    pub run_name: String,
    /// The window validated on, `[from, to]` in s of log time (its first and
    /// last sample): the whole run unless `from_s`/`to_s` cut it.
    pub window_s: [f64; 2],
    /// The models, in the order asked (a, b, then `more`).
    pub models: Vec<ComparedModel>,
}

/// Most models in one comparison.
const MAX_COMPARED: usize = 6;

/// Validate two models (or up to six with `more`) on the same run, side by
/// side (1-step, k-step, restarted free-run and simulation fits,
/// divergences; residual tests with the input–residual cross-correlations),
/// on the whole run or the window `from_s`–`to_s` of it (as if the log held
/// only those samples).
#[utoipa::path(get, path = "/api/models/compare", tag = "models", params(CompareQuery),
    responses((status = 200, description = "Both validations", body = Comparison),
              (status = 400, description = "Missing or malformed query parameter", body = ErrorBody),
              (status = 404, description = "No such model or run", body = ErrorBody),
              (status = 422, description = "The run cannot validate a model (vessel, columns, kind), `restart_s` is not a positive number of seconds, a window (`from_s`, `to_s`) not finite, empty or outside the run, or more than 6 models; `field` names it", body = ErrorBody)))]
pub async fn compare_models(
    State(s): State<AppState>,
    ApiQuery(q): ApiQuery<CompareQuery>,
) -> ApiResult<Json<Comparison>> {
    let more: Vec<String> = q
        .more
        .as_deref()
        .unwrap_or("")
        .split(',')
        .map(str::trim)
        .filter(|x| !x.is_empty())
        .map(String::from)
        .collect();
    if more.len() + 2 > MAX_COMPARED {
        return Err(ApiError::invalid(
            "more",
            format!(
                "at most {MAX_COMPARED} models in one comparison, got {}",
                more.len() + 2
            ),
        ));
    }
    let asked: Vec<(&'static str, &String)> = [("a", &q.a), ("b", &q.b)]
        .into_iter()
        .chain(more.iter().map(|id| ("more", id)))
        .collect();
    let fields: Vec<&'static str> = asked.iter().map(|(f, _)| *f).collect();
    let mut stored = Vec::new();
    for (field, id) in asked.iter().copied() {
        let m = models::get(&s.db, id)
            .await?
            .ok_or_else(|| ApiError::missing(field, format!("no model with id '{id}'")))?;
        stored.push(m);
    }
    let run = runs::get(&s.db, &q.run_id)
        .await?
        .ok_or_else(|| ApiError::missing("run_id", format!("no run with id '{}'", q.run_id)))?;
    if run.status != "accepted" {
        return Err(ApiError::invalid(
            "run_id",
            format!("run '{}' was {}", run.id, run.status),
        ));
    }
    let (campaign, vessel) = campaign_and_vessel(&s.db, &run).await?;
    for (field, m) in fields.iter().copied().zip(&stored) {
        if m.summary.vessel_id != campaign.vessel_id {
            return Err(ApiError::invalid(
                field,
                "the model belongs to another vessel than the run",
            ));
        }
    }
    let clocks = CampaignClocks::load(&s.db, &run.campaign_id).await?;
    let stored_run = StoredRun::of(&s.job_context(), run.clone(), &clocks);
    let k = q.k.unwrap_or(10).max(1);
    let restart_s = q.restart_s.unwrap_or(10.0);
    if !(restart_s.is_finite() && restart_s > 0.0) {
        return Err(ApiError::invalid(
            "restart_s",
            format!("the restart period must be a positive number of seconds, got {restart_s}"),
        ));
    }
    let docs: Vec<ModelDocument> = stored
        .iter()
        .map(|m| view(m.clone()).map(|v| v.document))
        .collect::<Result<_, _>>()?;
    let profile = vessel.profile.clone();
    let (from_s, to_s) = (q.from_s, q.to_s);
    let (window_s, reports) = blocking(
        move || -> Result<([f64; 2], Vec<serde_json::Value>), ApiError> {
            let mut summary = RunSummary::default();
            let record = processing::load_record(
                &profile,
                &stored_run.files,
                &stored_run.meta,
                &stored_run.priors,
                &mut summary,
            )
            .map_err(|e| ApiError::invalid("run_id", e.message))?;
            let record = if from_s.is_some() || to_s.is_some() {
                traces::cut(&record, from_s, to_s)
                    .map_err(|(field, m)| ApiError::invalid(field, m))?
            } else {
                record
            };
            let last = record.t0 + record.len().saturating_sub(1) as f64 / record.sample_rate_hz;
            let window_s = [record.t0, last];
            let input = stored_run.input(record);
            let forces = processing::generalized_force_columns(&profile);
            docs.iter()
                .zip(fields)
                .map(|(doc, field)| {
                    let settings = ValidationSettings {
                        k,
                        restart_s,
                        ..ValidationSettings::default()
                    };
                    let rep = validate_on_run_with(doc, &input, &forces, settings)
                        .map_err(|e| ApiError::invalid(field, e.to_string()))?;
                    serde_json::to_value(&rep).map_err(|e| ApiError::Internal(e.into()))
                })
                .collect::<Result<_, _>>()
                .map(|reports| (window_s, reports))
        },
    )
    .await??;
    Ok(Json(Comparison {
        run_id: run.id.clone(),
        run_name: run.name.clone(),
        window_s,
        models: stored
            .into_iter()
            .zip(reports)
            .map(|(m, report)| ComparedModel {
                run_used_for_estimation: m.run_ids.contains(&run.id),
                model: m.summary,
                report,
            })
            .collect(),
    }))
}
