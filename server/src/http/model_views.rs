//! A model's linear responses for the engineer's plots: Bode (over a run's
//! empirical H1 and coherence when asked), pole-zero map, step and impulse
//! responses, Hankel singular values. Thin: load the stored document, put
//! it in state-space form, call `seatrial_core::responses`, answer JSON
//! with names and units. Like every GET they run off the async workers
//! ([`super::offload`]); the numbers are small (milliseconds), so they are
//! computed per request rather than cached.

use axum::Json;
use axum::extract::{Path, State};
use seatrial_core::identification::document::ModelDocument;
use seatrial_core::identification::export_state_space::state_space_export;
use seatrial_core::responses::frequency::{PointResponse, bode, log_grid};
use seatrial_core::responses::hankel::{HankelView, hankel_view};
use seatrial_core::responses::poles::{PoleZeroMap, pole_zero_maps};
use seatrial_core::responses::step::{PointTimeResponse, ResponseKind, time_responses};
use seatrial_core::responses::{LinearModels, linear_models};
use serde::{Deserialize, Serialize};

use super::models::view;
use super::query::ApiQuery;
use super::{AppState, blocking, found};
use crate::error::{ApiError, ApiResult, ErrorBody};
use crate::storage::{models, runs};

/// Most frequencies of a Bode answer.
const MAX_POINTS: usize = 2000;
/// Frequencies kept of a run's Welch grid (log-spaced picks of its bins).
const RUN_GRID_POINTS: usize = 400;

/// The stored model's document and its state-space form (continuous, or
/// ZOH at `h`; an N4SID model at its own h).
async fn load(
    s: &AppState,
    id: &str,
    h: Option<f64>,
) -> ApiResult<(String, ModelDocument, LinearModels)> {
    let m = found(models::get(&s.db, id).await?, "model", id)?;
    let name = m.summary.name.clone();
    let version = m.summary.version;
    let doc = view(m)?.document;
    let e =
        state_space_export(&doc, &name, version, h).map_err(|msg| ApiError::invalid("h", msg))?;
    let lm = linear_models(&e)
        .map_err(|msg| ApiError::Internal(anyhow::anyhow!("model {id}: {msg}")))?;
    Ok((name, doc, lm))
}

/// Options of a Bode answer.
#[derive(Debug, Deserialize, utoipa::IntoParams)]
#[into_params(parameter_in = Query)]
pub struct FrequencyQuery {
    /// A run whose empirical H1 and coherence (from its quality report) come
    /// alongside; the model is then evaluated on the run's frequency grid.
    pub run_id: Option<String>,
    /// Frequencies of the log-spaced grid without `run_id`, 2–2000 (default 200).
    #[param(minimum = 2, maximum = 2000)]
    pub points: Option<usize>,
}

/// A run's empirical transfer-function estimate for one model channel.
#[derive(Debug, Serialize, utoipa::ToSchema)]
pub struct EmpiricalChannel {
    /// Log column of the input (`tau_X` for the model's `gamma_X`).
    pub input: String,
    /// Log column of the output.
    pub output: String,
    /// The model input it is compared with.
    pub model_input: String,
    /// 20·log10 |H1| (dB re 1 output unit per input unit) per frequency.
    pub magnitude_db: Vec<Option<f64>>,
    /// Unwrapped phase of H1 (degrees).
    pub phase_deg: Vec<Option<f64>>,
    /// Magnitude-squared coherence γ² (0–1).
    pub coherence: Vec<Option<f64>>,
}

/// The run the empirical estimates come from.
#[derive(Debug, Serialize, utoipa::ToSchema)]
pub struct EmpiricalRun {
    /// Run id.
    pub run_id: String,
    /// Run name.
    pub run_name: String,
    /// Its grid speed (m/s), when described.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub grid_speed_mps: Option<f64>,
    /// One entry per model channel the run has an estimate for.
    pub channels: Vec<EmpiricalChannel>,
}

/// Bode data of a model.
#[derive(Debug, Serialize, utoipa::ToSchema)]
pub struct FrequencyResponseView {
    /// Model id.
    pub model_id: String,
    /// Model name.
    pub model_name: String,
    /// Frequencies (Hz).
    pub freqs_hz: Vec<f64>,
    /// Sample time (s) of a discrete model (its Nyquist limits the grid); 0 for continuous.
    pub sample_time_s: f64,
    /// One entry per operating point (LPV grid speed).
    pub points: Vec<PointResponse>,
    /// The run's empirical H1 and coherence (with `run_id`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub run: Option<EmpiricalRun>,
}

/// The log column a model input is estimated from: γ = τ − g(η) is
/// compared with the logged τ.
fn logged_input(model_input: &str) -> String {
    match model_input
        .strip_prefix("gamma_")
        .or_else(|| model_input.strip_prefix("γ_"))
    {
        Some(s) => format!("tau_{s}"),
        None => model_input.to_string(),
    }
}

/// Indices of about `target` log-spaced bins of an ascending grid (f > 0, ≤ `f_max`).
fn log_picks(freqs: &[f64], f_max: f64, target: usize) -> Vec<usize> {
    let ok: Vec<usize> = (0..freqs.len())
        .filter(|&i| freqs[i] > 0.0 && freqs[i] <= f_max)
        .collect();
    if ok.len() <= target {
        return ok;
    }
    let (l0, l1) = (freqs[ok[0]].ln(), freqs[*ok.last().unwrap_or(&ok[0])].ln());
    let mut out: Vec<usize> = Vec::with_capacity(target);
    let mut j = 0;
    for k in 0..target {
        let want = l0 + (l1 - l0) * k as f64 / (target - 1) as f64;
        while j + 1 < ok.len() && freqs[ok[j + 1]].ln() <= want {
            j += 1;
        }
        if out.last() != Some(&ok[j]) {
            out.push(ok[j]);
        }
    }
    out
}

fn numbers(v: &serde_json::Value, picks: &[usize], scale: f64) -> Vec<Option<f64>> {
    let a = v.as_array();
    picks
        .iter()
        .map(|&i| {
            a.and_then(|a| a.get(i))
                .and_then(|x| x.as_f64())
                .map(|x| x * scale)
                .filter(|x| x.is_finite())
        })
        .collect()
}

/// Frequency response of every channel at every operating point; with
/// `run_id`, on the run's Welch grid together with its empirical H1 and
/// coherence (the comparison that shows where the model holds).
#[utoipa::path(get, path = "/api/models/{id}/frequency-response", tag = "models",
    params(("id" = String, Path, description = "Model id"), FrequencyQuery),
    responses((status = 200, description = "Magnitude (dB) and phase (°) per channel", body = FrequencyResponseView),
              (status = 400, description = "Malformed query parameter", body = ErrorBody),
              (status = 404, description = "No such model or run", body = ErrorBody),
              (status = 422, description = "`points` outside 2–2000, or the run has no quality report", body = ErrorBody)))]
pub async fn frequency_response(
    State(s): State<AppState>,
    Path(id): Path<String>,
    ApiQuery(q): ApiQuery<FrequencyQuery>,
) -> ApiResult<Json<FrequencyResponseView>> {
    let points = q.points.unwrap_or(200);
    if !(2..=MAX_POINTS).contains(&points) {
        return Err(ApiError::invalid(
            "points",
            format!("must be 2–{MAX_POINTS}, got {points}"),
        ));
    }
    let (name, _, lm) = load(&s, &id, None).await?;
    let sample_time_s = lm.points.first().map_or(0.0, |(_, m)| m.sample_time_s);
    let run = match &q.run_id {
        None => None,
        Some(rid) => {
            let run = runs::get(&s.db, rid)
                .await?
                .ok_or_else(|| ApiError::missing("run_id", format!("no run with id '{rid}'")))?;
            let report = runs::quality(&s.db, rid).await?.ok_or_else(|| {
                ApiError::invalid(
                    "run_id",
                    format!(
                        "run '{}' ({rid}) has no quality report (status {})",
                        run.name, run.status
                    ),
                )
            })?;
            Some((run, report))
        }
    };
    let view = blocking(move || -> ApiResult<FrequencyResponseView> {
        let Some((run, report)) = run else {
            let freqs = log_grid(&lm, points);
            return Ok(FrequencyResponseView {
                model_id: id,
                model_name: name,
                points: bode(&lm, &freqs),
                freqs_hz: freqs,
                sample_time_s,
                run: None,
            });
        };
        let q: serde_json::Value = serde_json::from_str(&report).map_err(|e| {
            ApiError::Internal(anyhow::anyhow!("stored quality report unreadable: {e}"))
        })?;
        let all: Vec<f64> = q["freqs_hz"]
            .as_array()
            .map(|a| a.iter().filter_map(|v| v.as_f64()).collect())
            .unwrap_or_default();
        let f_max = if sample_time_s > 0.0 {
            0.5 / sample_time_s
        } else {
            f64::INFINITY
        };
        let picks = log_picks(&all, f_max, RUN_GRID_POINTS);
        if picks.is_empty() {
            return Err(ApiError::invalid(
                "run_id",
                format!(
                    "run '{}' has no frequencies below the model's Nyquist frequency",
                    run.name
                ),
            ));
        }
        let freqs: Vec<f64> = picks.iter().map(|&i| all[i]).collect();
        let pairs = q["pairs"].as_array().cloned().unwrap_or_default();
        let mut channels = Vec::new();
        for input in &lm.inputs {
            let logged = logged_input(&input.name);
            for output in &lm.outputs {
                let Some(p) = pairs.iter().find(|p| {
                    p["output"] == output.name.as_str()
                        && (p["input"] == input.name.as_str() || p["input"] == logged.as_str())
                }) else {
                    continue;
                };
                channels.push(EmpiricalChannel {
                    input: p["input"].as_str().unwrap_or_default().to_string(),
                    output: output.name.clone(),
                    model_input: input.name.clone(),
                    magnitude_db: numbers(&p["h1_magnitude_db"], &picks, 1.0),
                    phase_deg: numbers(
                        &p["h1_phase_unwrapped_rad"],
                        &picks,
                        180.0 / std::f64::consts::PI,
                    ),
                    coherence: numbers(&p["coherence"], &picks, 1.0),
                });
            }
        }
        Ok(FrequencyResponseView {
            model_id: id,
            model_name: name,
            points: bode(&lm, &freqs),
            freqs_hz: freqs,
            sample_time_s,
            run: Some(EmpiricalRun {
                run_id: run.id.clone(),
                run_name: run.name.clone(),
                grid_speed_mps: run.description.grid_speed_mps.as_ref().map(|g| g.value),
                channels,
            }),
        })
    })
    .await??;
    Ok(Json(view))
}

/// A model's poles and zeros.
#[derive(Debug, Serialize, utoipa::ToSchema)]
pub struct PoleZeroView {
    /// Model id.
    pub model_id: String,
    /// What the zeros are.
    pub zeros_are: String,
    /// One map per operating point.
    pub points: Vec<PoleZeroMap>,
}

/// Poles (eigenvalues of A) and per-channel SISO zeros at every operating
/// point: the s plane (rad/s) for an LPV or DP model, the z plane for an
/// N4SID model; with natural frequency, damping and time constant.
#[utoipa::path(get, path = "/api/models/{id}/poles", tag = "models",
    params(("id" = String, Path, description = "Model id")),
    responses((status = 200, description = "Poles and zeros", body = PoleZeroView),
              (status = 404, description = "No such model", body = ErrorBody)))]
pub async fn poles(
    State(s): State<AppState>,
    Path(id): Path<String>,
) -> ApiResult<Json<PoleZeroView>> {
    let (_, _, lm) = load(&s, &id, None).await?;
    let points = blocking(move || pole_zero_maps(&lm)).await?;
    Ok(Json(PoleZeroView {
        model_id: id,
        zeros_are: "per-channel SISO zeros of each input → output transfer function (not MIMO transmission zeros)".into(),
        points,
    }))
}

/// Options of a step or impulse response.
#[derive(Debug, Deserialize, utoipa::IntoParams)]
#[into_params(parameter_in = Query)]
pub struct StepQuery {
    /// `step` (default) or `impulse`.
    pub kind: Option<ResponseKind>,
    /// Time shown (s), 0 < t ≤ 86400 (default: six time constants of the slowest stable pole).
    pub t_end_s: Option<f64>,
}

/// Step or impulse responses of a model.
#[derive(Debug, Serialize, utoipa::ToSchema)]
pub struct StepResponseView {
    /// Model id.
    pub model_id: String,
    /// Which response.
    pub kind: ResponseKind,
    /// One entry per operating point.
    pub points: Vec<PointTimeResponse>,
}

/// Step or impulse response of every input → output channel from rest at
/// every operating point; an unstable response stops where it diverges
/// (`diverged_at_s`).
#[utoipa::path(get, path = "/api/models/{id}/step-response", tag = "models",
    params(("id" = String, Path, description = "Model id"), StepQuery),
    responses((status = 200, description = "Responses per channel", body = StepResponseView),
              (status = 400, description = "Malformed query parameter (`kind` not step or impulse)", body = ErrorBody),
              (status = 404, description = "No such model", body = ErrorBody),
              (status = 422, description = "`t_end_s` not in (0, 86400]", body = ErrorBody)))]
pub async fn step_response(
    State(s): State<AppState>,
    Path(id): Path<String>,
    ApiQuery(q): ApiQuery<StepQuery>,
) -> ApiResult<Json<StepResponseView>> {
    if let Some(t) = q.t_end_s
        && !(t.is_finite() && t > 0.0 && t <= 86_400.0)
    {
        return Err(ApiError::invalid(
            "t_end_s",
            format!("must be a number of seconds in (0, 86400], got {t}"),
        ));
    }
    let kind = q.kind.unwrap_or(ResponseKind::Step);
    let (_, _, lm) = load(&s, &id, None).await?;
    let points = blocking(move || time_responses(&lm, kind, q.t_end_s))
        .await?
        .map_err(|msg| ApiError::invalid("t_end_s", msg))?;
    Ok(Json(StepResponseView {
        model_id: id,
        kind,
        points,
    }))
}

/// Options of the Hankel singular values.
#[derive(Debug, Deserialize, utoipa::IntoParams)]
#[into_params(parameter_in = Query)]
pub struct HankelQuery {
    /// Sample time (s) at which an LPV or DP model is ZOH-discretized first
    /// (default: its continuous form); an N4SID model only at its own h.
    pub h: Option<f64>,
}

/// A model's Hankel singular values.
#[derive(Debug, Serialize, utoipa::ToSchema)]
pub struct HankelSingularValues {
    /// Model id.
    pub model_id: String,
    /// Values per operating point, and an N4SID model's subspace singular values.
    #[serde(flatten)]
    pub view: HankelView,
}

/// Hankel singular values at every operating point (how many states carry
/// the input → output energy), and for an N4SID model the singular values
/// of its subspace step that chose the order.
#[utoipa::path(get, path = "/api/models/{id}/hankel", tag = "models",
    params(("id" = String, Path, description = "Model id"), HankelQuery),
    responses((status = 200, description = "Singular values", body = HankelSingularValues),
              (status = 400, description = "Malformed query parameter", body = ErrorBody),
              (status = 404, description = "No such model", body = ErrorBody),
              (status = 422, description = "`h` unusable (not positive; an N4SID model's own h differs)", body = ErrorBody)))]
pub async fn hankel(
    State(s): State<AppState>,
    Path(id): Path<String>,
    ApiQuery(q): ApiQuery<HankelQuery>,
) -> ApiResult<Json<HankelSingularValues>> {
    let (_, doc, lm) = load(&s, &id, q.h).await?;
    let view = blocking(move || hankel_view(&doc, &lm)).await?;
    Ok(Json(HankelSingularValues { model_id: id, view }))
}
