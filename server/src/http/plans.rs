//! Plans: generate and re-plan (versioned), read, and export each
//! experiment's schedule.

use axum::Json;
use axum::extract::{Path, State};
use axum::http::{StatusCode, header};
use axum::response::{Html, IntoResponse};
use seatrial_core::planning::analysis::schedule_spectrum;
use seatrial_core::planning::campaign::{Durations, Excitation};
use seatrial_core::planning::{CampaignSpec, ExperimentFamily, SpeedGrid};
use serde::{Deserialize, Serialize};

use super::json::OptionalApiJson;
use super::{AppState, blocking, export, found};
use crate::error::{ApiError, ApiResult, ErrorBody};
use crate::storage::plan_revision::{self, Fingerprinted};
use crate::storage::plans::{self, StoredExperiment, StoredPlan};
use crate::storage::{campaigns, vessels};

/// Changes to the campaign for a re-plan; absent fields are kept. An empty
/// body re-plans the campaign as it is.
#[derive(Debug, Deserialize, utoipa::ToSchema)]
#[serde(deny_unknown_fields)]
pub struct CampaignRevision {
    /// Forward-speed grid, in kn or m/s.
    #[serde(default)]
    pub grid: Option<SpeedGrid>,
    /// Families to fly (at least one, each once).
    #[serde(default)]
    #[schema(min_items = 1)]
    pub families: Option<Vec<ExperimentFamily>>,
    /// Repetitions.
    #[serde(default)]
    pub repetitions: Option<u32>,
    /// Excitation settings (replaced as a whole: its absent fields take their defaults).
    #[serde(default)]
    pub excitation: Option<Excitation>,
    /// Durations (replaced as a whole: its absent fields take their defaults).
    #[serde(default)]
    pub durations: Option<Durations>,
    /// Seed of every pseudo-random sequence (0 … 2⁵³−1).
    #[serde(default)]
    pub seed: Option<u64>,
    /// Deciding experiments (replaced as a whole; `[]` removes them): the
    /// `experiment` of a discovery report's ambiguity, as given, planned
    /// after the plan's runs, one run `DEC{k}-{dof}-{heading}` per heading
    /// (6-DOF ROVs only: a DP ship's plan is thruster schedules).
    #[serde(default)]
    #[schema(max_items = 8)]
    pub deciding: Option<Vec<seatrial_core::discrepancy::experiment::ExperimentProposal>>,
}

impl CampaignRevision {
    fn apply(self, spec: &CampaignSpec) -> CampaignSpec {
        let mut s = spec.clone();
        if let Some(g) = self.grid {
            s.grid = g;
        }
        if let Some(f) = self.families {
            s.families = f;
        }
        if let Some(r) = self.repetitions {
            s.repetitions = Some(r);
        }
        if let Some(e) = self.excitation {
            s.excitation = e;
        }
        if let Some(d) = self.durations {
            s.durations = d;
        }
        if let Some(seed) = self.seed {
            s.seed = seed;
        }
        if let Some(d) = self.deciding {
            s.deciding = d;
        }
        s
    }
}

/// A plan as (re-)planning returns it.
#[derive(Debug, Serialize, utoipa::ToSchema)]
pub struct PlanRevision {
    /// The campaign's newest plan.
    #[serde(flatten)]
    pub plan: StoredPlan,
    /// True when this call stored a new version; false when the plan came
    /// out identical to the newest version, which is returned unchanged.
    pub created: bool,
}

/// Plan or re-plan the campaign, optionally with changed settings (which
/// then become the campaign's). Deterministic for the campaign's seed. A
/// new version keeps the id of every experiment whose identity (family,
/// grid speed, DOFs, static sign, repetition) and content (description and
/// schedule) are unchanged, so uploaded runs stay matched; `changes` lists
/// what was added, removed and changed, and the runs flown for removed or
/// changed experiments. A plan identical to the newest version is not
/// stored again: that version is returned with 200.
#[utoipa::path(post, path = "/api/campaigns/{id}/plan", tag = "planning",
    params(("id" = String, Path, description = "Campaign id")),
    request_body(content = Option<CampaignRevision>, description = "Optional changes to the campaign", content_type = "application/json"),
    responses(
        (status = 200, description = "Identical to the newest version: nothing stored", body = PlanRevision),
        (status = 201, description = "A new version", body = PlanRevision),
        (status = 400, description = "Malformed JSON; `field` names the JSON path", body = ErrorBody),
        (status = 404, description = "No such campaign", body = ErrorBody),
        (status = 409, description = "The campaign or its vessel is deleted (named by name and id)", body = ErrorBody),
        (status = 413, description = "Body too large", body = ErrorBody),
        (status = 415, description = "A body that is not JSON", body = ErrorBody),
        (status = 422, description = "The campaign cannot be planned: `field` and `limit` name what and why", body = ErrorBody)))]
pub async fn generate_plan(
    State(s): State<AppState>,
    Path(id): Path<String>,
    OptionalApiJson(change): OptionalApiJson<CampaignRevision>,
) -> ApiResult<(StatusCode, Json<PlanRevision>)> {
    let campaign = found(campaigns::get(&s.db, &id).await?, "campaign", &id)?;
    super::lifecycle_parents::refuse_deleted(&s.db, "campaign", &id).await?;
    let vessel = vessels::get(&s.db, &campaign.vessel_id)
        .await?
        .ok_or_else(|| ApiError::Internal(anyhow::anyhow!("campaign {id} has no vessel")))?;
    let spec = change.map(|c| c.apply(&campaign.spec));
    let planned = spec.clone().unwrap_or(campaign.spec);
    let new = blocking(move || -> ApiResult<Fingerprinted> {
        let plan = seatrial_core::planning::generate_plan(&vessel.profile, &planned)?;
        Ok(Fingerprinted::new(plan)?)
    })
    .await??;
    let stored = found(
        plan_revision::store(&s.db, &id, &new, spec.as_ref()).await?,
        "campaign",
        &id,
    )?;
    let status = if stored.created {
        StatusCode::CREATED
    } else {
        StatusCode::OK
    };
    Ok((
        status,
        Json(PlanRevision {
            plan: stored.plan,
            created: stored.created,
        }),
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
