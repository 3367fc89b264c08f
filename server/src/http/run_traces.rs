//! The time plot of a run: every logged channel over a window, decimated
//! to the envelope when long, with the window's statistics (what an
//! engineer reads off a selected stretch of a trial). The log is read
//! again from its stored files, as identification reads it.

use axum::Json;
use axum::extract::{Path, State};
use seatrial_core::traces::{TracePlot, trace_plot};
use serde::{Deserialize, Serialize};

use super::query::ApiQuery;
use super::{AppState, blocking, campaign_and_vessel, found};
use crate::clock::CampaignClocks;
use crate::error::{ApiError, ApiResult, ErrorBody};
use crate::jobs::run_inputs::StoredRun;
use crate::processing::{self, RunSummary};
use crate::storage::runs;

/// Most points per channel.
const MAX_POINTS: usize = 20_000;

/// Which window of the run.
#[derive(Debug, Deserialize, utoipa::IntoParams)]
#[into_params(parameter_in = Query)]
pub struct TraceQuery {
    /// Window start (s, log time; default: the first sample).
    pub from_s: Option<f64>,
    /// Window end (s; default: the last sample).
    pub to_s: Option<f64>,
    /// Points per channel, 10–20000 (default 2000): longer windows are
    /// shown as each bucket's minimum and maximum.
    #[param(minimum = 10, maximum = 20000)]
    pub points: Option<usize>,
}

/// A run's time plot.
#[derive(Debug, Serialize, utoipa::ToSchema)]
pub struct RunTraces {
    /// Run id.
    pub run_id: String,
    /// Run name.
    pub run_name: String,
    /// The channels over the window.
    #[serde(flatten)]
    pub plot: TracePlot,
}

/// Every channel of an accepted run over a time window (the whole run by
/// default) with units, decimated to about `points` per channel, and the
/// statistics (mean, std, RMS, min, max) of each channel over the window.
#[utoipa::path(get, path = "/api/runs/{id}/traces", tag = "runs",
    params(("id" = String, Path, description = "Run id"), TraceQuery),
    responses((status = 200, description = "The channels over the window", body = RunTraces),
              (status = 400, description = "Malformed query parameter", body = ErrorBody),
              (status = 404, description = "No such run", body = ErrorBody),
              (status = 422, description = "The run is not accepted, or the window is empty or outside the log, or `points` outside 10–20000", body = ErrorBody)))]
pub async fn run_traces(
    State(s): State<AppState>,
    Path(id): Path<String>,
    ApiQuery(q): ApiQuery<TraceQuery>,
) -> ApiResult<Json<RunTraces>> {
    let points = q.points.unwrap_or(2000);
    if !(10..=MAX_POINTS).contains(&points) {
        return Err(ApiError::invalid(
            "points",
            format!("must be 10–{MAX_POINTS}, got {points}"),
        ));
    }
    let run = found(runs::get(&s.db, &id).await?, "run", &id)?;
    if run.status != "accepted" {
        return Err(ApiError::invalid(
            "id",
            format!(
                "run '{}' ({id}) was {}: no samples to plot",
                run.name, run.status
            ),
        ));
    }
    let (_, vessel) = campaign_and_vessel(&s.db, &run).await?;
    let clocks = CampaignClocks::load(&s.db, &run.campaign_id).await?;
    let stored = StoredRun::of(&s.job_context(), run.clone(), &clocks);
    let profile = vessel.profile.clone();
    let plot = blocking(move || -> ApiResult<TracePlot> {
        let mut summary = RunSummary::default();
        let record = processing::load_record(
            &profile,
            &stored.files,
            &stored.meta,
            &stored.priors,
            &mut summary,
        )
        .map_err(|e| ApiError::invalid("id", e.message))?;
        trace_plot(&record, q.from_s, q.to_s, points)
            .map_err(|(field, msg)| ApiError::invalid(field, msg))
    })
    .await??;
    Ok(Json(RunTraces {
        run_id: run.id,
        run_name: run.name,
        plot,
    }))
}
