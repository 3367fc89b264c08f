//! Clock offsets of two-file runs: the campaign's pooled offset and the
//! offsets set by hand, per campaign and per run.
//!
//! Setting a run's offset re-processes that run (its alignment report,
//! summary and quality report are rewritten with the new offset). Setting
//! the campaign's offset stores it: jobs read runs with it from then on,
//! but the runs' stored reports keep the offset they were processed with
//! (`at_upload` against `now` in the views) — nothing is recomputed eagerly.

use axum::Json;
use axum::extract::{Path, State};
use seatrial_core::alignment::{Chosen, OffsetSource, PooledOffset, check_user_offset};
use serde::{Deserialize, Serialize};
use serde_json::Value;

use super::json::ApiJson;
use super::{AppState, found};
use crate::clock::{CampaignClocks, own_estimate};
use crate::error::{ApiError, ApiResult, ErrorBody};
use crate::processing::RunMeta;
use crate::storage::runs::{self, Run};
use crate::storage::{campaigns, clock_offsets};

/// A clock offset to set by hand, or `null` to clear it.
#[derive(Debug, Deserialize, utoipa::ToSchema)]
pub struct ClockOffsetRequest {
    /// Seconds added to navigation time stamps to put them on the control
    /// clock, within ±86 400 s; `null` clears the offset set by hand.
    pub clock_offset_s: Option<f64>,
}

/// An offset a run is (or was) merged with, and where it came from.
#[derive(Debug, Clone, Serialize, utoipa::ToSchema)]
pub struct UsedOffset {
    /// Offset (s).
    pub offset_s: f64,
    /// Its standard deviation (s); `null` when set by hand.
    pub std_s: Option<f64>,
    /// `user_run`, `user_campaign`, `own`, `pooled` or `weak_own`.
    pub source: OffsetSource,
}

impl From<Chosen> for UsedOffset {
    fn from(c: Chosen) -> Self {
        UsedOffset {
            offset_s: c.offset_s,
            std_s: c.std_s,
            source: c.source,
        }
    }
}

/// A run's own estimate, in short.
#[derive(Debug, Clone, Serialize, utoipa::ToSchema)]
pub struct OwnOffset {
    /// Offset estimated from the shared channel (s).
    pub offset_s: f64,
    /// Its calibrated standard deviation (s).
    pub std_s: f64,
    /// Whether it stands on its own (else the pooled offset is used).
    pub informative: bool,
    /// Why, in words.
    pub reason: String,
}

/// The clock offsets of one two-file run.
#[derive(Debug, Clone, Serialize, utoipa::ToSchema)]
pub struct RunClockOffset {
    /// Run id.
    pub run_id: String,
    /// Run name.
    pub name: String,
    /// `accepted` or `rejected`.
    pub status: String,
    /// The offset set by hand for this run (s), if any.
    pub clock_offset_s: Option<f64>,
    /// Its own estimate from the shared channel, when it has one.
    pub own: Option<OwnOffset>,
    /// The offset its stored alignment and quality reports were made with.
    pub at_upload: Option<UsedOffset>,
    /// The offset a job reads it with now (the campaign's offsets may have
    /// changed since it was processed).
    pub now: Option<UsedOffset>,
}

/// A campaign's clock offset: set by hand, pooled, and per two-file run.
#[derive(Debug, Clone, Serialize, utoipa::ToSchema)]
pub struct CampaignClockOffset {
    /// Campaign id.
    pub campaign_id: String,
    /// The campaign's offset set by hand (s), if any: it applies to every
    /// two-file run without its own hand-set offset.
    pub clock_offset_s: Option<f64>,
    /// The offset pooled from the runs' informative estimates
    /// (inverse-variance mean, outliers left out), `null` when no run is
    /// informative. One constant offset per campaign: clock drift across
    /// the campaign is not modelled.
    pub pooled: Option<PooledOffset>,
    /// Every two-file run, oldest first.
    pub runs: Vec<RunClockOffset>,
}

fn view_of(run: &Run, clocks: &CampaignClocks) -> RunClockOffset {
    let alignment = run.summary.as_ref().and_then(|s| s.get("alignment"));
    let at_upload = alignment.and_then(|a| {
        Some(UsedOffset {
            offset_s: a.get("offset_used_s")?.as_f64()?,
            std_s: a.get("offset_used_std_s").and_then(Value::as_f64),
            source: serde_json::from_value(a.get("offset_source")?.clone()).ok()?,
        })
    });
    RunClockOffset {
        run_id: run.id.clone(),
        name: run.name.clone(),
        status: run.status.clone(),
        clock_offset_s: clocks.user_runs.get(&run.id).copied(),
        own: own_estimate(run).map(|e| OwnOffset {
            offset_s: e.offset_s,
            std_s: e.std_error_s,
            informative: e.informative,
            reason: e.reason,
        }),
        at_upload,
        now: clocks.decide(run).map(UsedOffset::from),
    }
}

async fn campaign_view(s: &AppState, campaign_id: &str) -> ApiResult<CampaignClockOffset> {
    let clocks = CampaignClocks::load(&s.db, campaign_id).await?;
    let runs = runs::list(&s.db, campaign_id).await?;
    Ok(CampaignClockOffset {
        campaign_id: campaign_id.to_string(),
        clock_offset_s: clocks.user_campaign_s,
        pooled: clocks.pooled.clone(),
        runs: runs
            .iter()
            .filter(|r| r.layout == "split" && r.status != "stored")
            .map(|r| view_of(r, &clocks))
            .collect(),
    })
}

/// A 422 naming `field` unless `run` has two files.
fn two_file(run: &Run, field: &str) -> ApiResult<()> {
    if run.layout == "split" {
        return Ok(());
    }
    Err(ApiError::invalid(
        field,
        "a single-file run has one clock: clock offsets apply to two-file runs (control + nav)",
    ))
}

/// Reads `{"clock_offset_s": seconds | null}`: 422 naming the field for a
/// value that is not a finite number of seconds within a day.
fn requested_offset(body: &Value) -> ApiResult<Option<f64>> {
    const FIELD: &str = "clock_offset_s";
    let obj = body.as_object().ok_or_else(|| {
        ApiError::bad_field(
            FIELD,
            "expected a JSON object {\"clock_offset_s\": seconds or null}",
        )
    })?;
    if let Some(k) = obj.keys().find(|k| k.as_str() != FIELD) {
        return Err(ApiError::bad_field(
            k.clone(),
            format!("unknown field '{k}'; the body is {{\"clock_offset_s\": seconds or null}}"),
        ));
    }
    let value = match obj.get(FIELD) {
        None => {
            return Err(ApiError::bad_field(
                FIELD,
                "missing field: give the offset in seconds, or null to clear it",
            ));
        }
        Some(Value::Null) => return Ok(None),
        Some(Value::Number(n)) => n.as_f64().unwrap_or(f64::NAN),
        Some(Value::String(t)) => {
            return Err(ApiError::invalid(
                FIELD,
                format!(
                    "must be a finite number of seconds within ±86400 s (or null), got the string \"{t}\""
                ),
            ));
        }
        Some(other) => {
            return Err(ApiError::bad_field(
                FIELD,
                format!("must be a number of seconds or null, got {other}"),
            ));
        }
    };
    check_user_offset(FIELD, value).map_err(|e| ApiError::invalid(FIELD, e.message()))?;
    Ok(Some(value))
}

/// The campaign's clock offset: set by hand, pooled from its two-file runs
/// (with the runs used, left out as inconsistent, or uninformative), and
/// per two-file run the offset its reports used and the one a job uses now.
#[utoipa::path(get, path = "/api/campaigns/{id}/clock-offset", tag = "runs",
    params(("id" = String, Path, description = "Campaign id")),
    responses((status = 200, description = "The campaign's clock offsets", body = CampaignClockOffset),
              (status = 404, description = "No such campaign", body = ErrorBody)))]
pub async fn get_campaign_clock_offset(
    State(s): State<AppState>,
    Path(id): Path<String>,
) -> ApiResult<Json<CampaignClockOffset>> {
    found(campaigns::get(&s.db, &id).await?, "campaign", &id)?;
    Ok(Json(campaign_view(&s, &id).await?))
}

/// Sets (a number of seconds) or clears (`null`) the campaign's clock
/// offset by hand. It overrides the runs' own and pooled estimates for every
/// two-file run without a hand-set offset of its own, in jobs from now on;
/// stored run reports are not recomputed.
#[utoipa::path(put, path = "/api/campaigns/{id}/clock-offset", tag = "runs",
    params(("id" = String, Path, description = "Campaign id")),
    request_body = ClockOffsetRequest,
    responses((status = 200, description = "Stored; the campaign's clock offsets", body = CampaignClockOffset),
              (status = 400, description = "Malformed body", body = ErrorBody),
              (status = 404, description = "No such campaign", body = ErrorBody),
              (status = 415, description = "Not application/json", body = ErrorBody),
              (status = 422, description = "Not a finite offset within a day (field `clock_offset_s`)", body = ErrorBody)))]
pub async fn put_campaign_clock_offset(
    State(s): State<AppState>,
    Path(id): Path<String>,
    ApiJson(body): ApiJson<Value>,
) -> ApiResult<Json<CampaignClockOffset>> {
    found(campaigns::get(&s.db, &id).await?, "campaign", &id)?;
    let offset = requested_offset(&body)?;
    clock_offsets::set_campaign_offset(&s.db, &id, offset).await?;
    Ok(Json(campaign_view(&s, &id).await?))
}

/// A two-file run's clock offsets: set by hand, its own estimate, the one
/// its reports used and the one a job uses now.
#[utoipa::path(get, path = "/api/runs/{id}/clock-offset", tag = "runs",
    params(("id" = String, Path, description = "Run id")),
    responses((status = 200, description = "The run's clock offsets", body = RunClockOffset),
              (status = 404, description = "No such run", body = ErrorBody),
              (status = 422, description = "A single-file run has one clock (field `id`)", body = ErrorBody)))]
pub async fn get_run_clock_offset(
    State(s): State<AppState>,
    Path(id): Path<String>,
) -> ApiResult<Json<RunClockOffset>> {
    let run = found(runs::get(&s.db, &id).await?, "run", &id)?;
    two_file(&run, "id")?;
    let clocks = CampaignClocks::load(&s.db, &run.campaign_id).await?;
    Ok(Json(view_of(&run, &clocks)))
}

/// Sets (a number of seconds) or clears (`null`) a two-file run's clock
/// offset by hand, and re-processes the run with it: its alignment report
/// (`offset_source: user_run`), summary and quality report are rewritten. A
/// run rejected at upload (e.g. a shared channel that never changes) is
/// accepted if it now processes. Nothing is stored when it fails.
#[utoipa::path(put, path = "/api/runs/{id}/clock-offset", tag = "runs",
    params(("id" = String, Path, description = "Run id")),
    request_body = ClockOffsetRequest,
    responses((status = 200, description = "Stored and re-processed; the run", body = Run),
              (status = 400, description = "Malformed body", body = ErrorBody),
              (status = 404, description = "No such run", body = ErrorBody),
              (status = 415, description = "Not application/json", body = ErrorBody),
              (status = 422, description = "Not a finite offset within a day, a single-file run, or the run does not process with it (field `clock_offset_s`, or the file)", body = ErrorBody)))]
pub async fn put_run_clock_offset(
    State(s): State<AppState>,
    Path(id): Path<String>,
    ApiJson(body): ApiJson<Value>,
) -> ApiResult<Json<Run>> {
    let run = found(runs::get(&s.db, &id).await?, "run", &id)?;
    let offset = requested_offset(&body)?;
    two_file(&run, "clock_offset_s")?;
    let mut clocks = CampaignClocks::load(&s.db, &run.campaign_id).await?;
    match offset {
        Some(v) => clocks.user_runs.insert(run.id.clone(), v),
        None => clocks.user_runs.remove(&run.id),
    };
    let priors = clocks.priors_for(Some(&run.id));
    let meta = RunMeta::of_stored(run.summary.as_ref());
    let outcome = crate::intake::process(&s.db, &s.blobs, &run, meta, priors).await?;
    let done = outcome.map_err(|e| {
        let field = match e.file.as_str() {
            "meta.clock_offset_s" => "clock_offset_s".to_string(),
            other => other.to_string(),
        };
        ApiError::invalid(field, e.message)
    })?;
    clock_offsets::set_run_offset(&s.db, &run.id, offset).await?;
    runs::finish(&s.db, &run.id, "accepted", done.outcome()).await?;
    Ok(Json(found(runs::get(&s.db, &id).await?, "run", &id)?))
}
