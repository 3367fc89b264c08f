//! Plans: generate, read, and export each experiment's schedule.

use axum::Json;
use axum::extract::{Path, State};
use axum::http::{StatusCode, header};
use axum::response::{Html, IntoResponse};
use seatrial_core::planning::analysis::schedule_spectrum;
use serde::Serialize;

use super::{AppState, blocking, export, found};
use crate::error::{ApiError, ApiResult, ErrorBody};
use crate::storage::plans::{self, StoredExperiment, StoredPlan};
use crate::storage::{campaigns, vessels};

/// Generate (or regenerate) the campaign's plan: a new version, stored with
/// every schedule. Deterministic for the campaign's seed.
#[utoipa::path(post, path = "/api/campaigns/{id}/plan", tag = "planning",
    params(("id" = String, Path, description = "Campaign id")),
    responses(
        (status = 201, description = "The new plan", body = StoredPlan),
        (status = 404, description = "No such campaign", body = ErrorBody),
        (status = 422, description = "The campaign cannot be planned", body = ErrorBody)))]
pub async fn generate_plan(
    State(s): State<AppState>,
    Path(id): Path<String>,
) -> ApiResult<(StatusCode, Json<StoredPlan>)> {
    let campaign = found(campaigns::get(&s.db, &id).await?, "campaign", &id)?;
    let vessel = vessels::get(&s.db, &campaign.vessel_id)
        .await?
        .ok_or_else(|| ApiError::Internal(anyhow::anyhow!("campaign {id} has no vessel")))?;
    let spec = campaign.spec;
    let plan =
        blocking(move || seatrial_core::planning::generate_plan(&vessel.profile, &spec)).await??;
    Ok((
        StatusCode::CREATED,
        Json(plans::insert(&s.db, &id, &plan).await?),
    ))
}

/// The campaign's newest plan: experiments in run order with their checks.
#[utoipa::path(get, path = "/api/campaigns/{id}/plan", tag = "planning",
    params(("id" = String, Path, description = "Campaign id")),
    responses(
        (status = 200, description = "The plan", body = StoredPlan),
        (status = 404, description = "No such campaign, or not planned yet", body = ErrorBody)))]
pub async fn get_plan(
    State(s): State<AppState>,
    Path(id): Path<String>,
) -> ApiResult<Json<StoredPlan>> {
    found(campaigns::get(&s.db, &id).await?, "campaign", &id)?;
    let plan = plans::latest(&s.db, &id).await?.ok_or_else(|| {
        ApiError::NotFound(format!(
            "campaign '{id}' has no plan yet: POST /api/campaigns/{id}/plan"
        ))
    })?;
    Ok(Json(plan))
}

/// One column of a schedule.
#[derive(Debug, Serialize, utoipa::ToSchema)]
pub struct ScheduleColumn {
    /// Column name, as in the CSV.
    pub name: String,
    /// SI unit.
    pub unit: String,
    /// Samples at t.
    pub values: Vec<f64>,
}

/// Power spectrum of an excited column (Hann periodogram over the run).
#[derive(Debug, Serialize, utoipa::ToSchema)]
pub struct ColumnSpectrum {
    /// Column name.
    pub name: String,
    /// Frequencies (Hz).
    pub freqs_hz: Vec<f64>,
    /// One-sided PSD (unit²/Hz).
    pub psd: Vec<f64>,
}

/// An experiment with its full schedule: the JSON export.
#[derive(Debug, Serialize, utoipa::ToSchema)]
pub struct ExperimentSchedule {
    /// The experiment.
    pub experiment: StoredExperiment,
    /// Sample rate (Hz).
    pub sample_rate_hz: f64,
    /// Time (s), from 0.
    pub t: Vec<f64>,
    /// Reference columns.
    pub columns: Vec<ScheduleColumn>,
    /// Spectra of the excited columns.
    pub spectra: Vec<ColumnSpectrum>,
}

async fn load(
    s: &AppState,
    id: &str,
    eid: &str,
) -> ApiResult<(StoredExperiment, seatrial_core::planning::Schedule)> {
    found(campaigns::get(&s.db, id).await?, "campaign", id)?;
    found(
        plans::experiment(&s.db, id, eid).await?,
        "experiment in this campaign's plans",
        eid,
    )
}

/// One experiment with its schedule and spectra (JSON export).
#[utoipa::path(get, path = "/api/campaigns/{id}/plan/experiments/{eid}", tag = "planning",
    params(("id" = String, Path, description = "Campaign id"), ("eid" = String, Path, description = "Experiment id")),
    responses(
        (status = 200, description = "Schedule and spectra", body = ExperimentSchedule),
        (status = 404, description = "No such campaign or experiment", body = ErrorBody)))]
pub async fn get_experiment(
    State(s): State<AppState>,
    Path((id, eid)): Path<(String, String)>,
) -> ApiResult<Json<ExperimentSchedule>> {
    let (experiment, schedule) = load(&s, &id, &eid).await?;
    let out = blocking(move || {
        let fs = schedule.sample_rate_hz;
        let t = export::times(schedule.len(), fs);
        let mut spectra = Vec::new();
        for (ch, x) in experiment.experiment.channels.iter().zip(&schedule.values) {
            if ch.excited
                && x.len() >= 8
                && let Ok(sp) = schedule_spectrum(x, fs)
            {
                spectra.push(ColumnSpectrum {
                    name: ch.column.clone(),
                    freqs_hz: sp.freqs,
                    psd: sp.values,
                });
            }
        }
        let columns = experiment
            .experiment
            .channels
            .iter()
            .zip(schedule.values)
            .map(|(ch, values)| ScheduleColumn {
                name: ch.column.clone(),
                unit: ch.unit.clone(),
                values,
            })
            .collect();
        ExperimentSchedule {
            experiment,
            sample_rate_hz: fs,
            t,
            columns,
            spectra,
        }
    })
    .await?;
    Ok(Json(out))
}

/// The schedule as CSV: `t` plus one reference column per channel.
#[utoipa::path(get, path = "/api/campaigns/{id}/plan/experiments/{eid}/schedule.csv", tag = "planning",
    params(("id" = String, Path, description = "Campaign id"), ("eid" = String, Path, description = "Experiment id")),
    responses(
        (status = 200, description = "CSV with header `t,<columns>`", content_type = "text/csv", body = String),
        (status = 404, description = "No such campaign or experiment", body = ErrorBody)))]
pub async fn schedule_csv(
    State(s): State<AppState>,
    Path((id, eid)): Path<(String, String)>,
) -> ApiResult<impl IntoResponse> {
    let (experiment, schedule) = load(&s, &id, &eid).await?;
    let filename = format!(
        "{:03}_{}.csv",
        experiment.experiment.seq, experiment.experiment.code
    )
    .replace(['/', '\\', '"'], "_");
    let body = blocking(move || export::schedule_csv(&schedule)).await?;
    Ok((
        [
            (header::CONTENT_TYPE, "text/csv; charset=utf-8".to_string()),
            (
                header::CONTENT_DISPOSITION,
                super::exposure::attachment(&filename),
            ),
        ],
        body,
    ))
}

/// The whole plan as a printable run sheet (HTML, print to paper or PDF).
#[utoipa::path(get, path = "/api/campaigns/{id}/plan/runsheet", tag = "planning",
    params(("id" = String, Path, description = "Campaign id")),
    responses(
        (status = 200, description = "Printable HTML run sheet", content_type = "text/html", body = String),
        (status = 404, description = "No such campaign, or not planned yet", body = ErrorBody)))]
pub async fn run_sheet(
    State(s): State<AppState>,
    Path(id): Path<String>,
) -> ApiResult<Html<String>> {
    let campaign = found(campaigns::get(&s.db, &id).await?, "campaign", &id)?;
    let vessel = found(
        vessels::get(&s.db, &campaign.vessel_id).await?,
        "vessel",
        &campaign.vessel_id,
    )?;
    let plan = plans::latest(&s.db, &id)
        .await?
        .ok_or_else(|| ApiError::NotFound(format!("campaign '{id}' has no plan yet")))?;
    Ok(Html(export::run_sheet(&vessel, &campaign, &plan)))
}
