//! HTTP: a thin layer that parses, calls the numerics core (off the async
//! runtime for CPU work), stores and responds. Every `/api` route is
//! declared through utoipa, so `openapi.yaml` is generated from the router
//! itself and a test holds the two together.

pub mod auth;
pub mod campaigns;
pub mod clock_offsets;
pub mod design;
pub mod discrepancies;
pub mod export;
pub mod exposure;
pub mod health;
pub mod jobs;
pub mod json;
pub mod lifecycle;
pub mod lifecycle_parents;
pub mod manage;
pub mod model_cache;
pub mod model_export;
pub mod model_views;
pub mod models;
pub mod next_dive;
pub mod offload;
mod planning_jobs;
pub mod plans;
pub mod precision;
pub mod query;
pub mod run_description;
pub mod run_traces;
pub mod runs;
pub mod vessels;

use std::path::PathBuf;
use std::sync::Arc;

use axum::Router;
use axum::extract::DefaultBodyLimit;
use axum::http::{Method, Uri};
use tower_http::compression::CompressionLayer;
use tower_http::trace::TraceLayer;
use utoipa::OpenApi;
use utoipa_axum::router::OpenApiRouter;
use utoipa_axum::routes;

use crate::error::{ApiError, ErrorBody};
use crate::jobs::{JobContext, JobEvent, JobRegistry, Jobs, JobsConfig};
use crate::storage::Db;
use crate::storage::blobs::BlobStore;
use exposure::Exposure;

/// Bytes of serialised model answers kept in memory.
const MODEL_CACHE_BYTES: usize = 256 << 20;

/// Shared state of the handlers.
#[derive(Clone)]
pub struct AppState {
    /// Database pool.
    pub db: Db,
    /// Uploaded files, content-addressed.
    pub blobs: BlobStore,
    /// Largest upload (all files of a run together), bytes.
    pub max_upload_bytes: u64,
    /// Background jobs: the registered kinds, the running ones, the runner's signals.
    pub jobs: Jobs,
    /// Host allow-list and allowed origins (default: local names only).
    pub exposure: Arc<Exposure>,
    /// Models' GET answers, serialised and compressed once.
    pub model_cache: Arc<model_cache::ModelCache>,
    /// Blocking threads that may answer reads at once ([`offload`]).
    pub read_permits: Arc<tokio::sync::Semaphore>,
    /// Whether credentials are required (default: local mode).
    pub auth: Arc<auth::AuthConfig>,
}

impl AppState {
    /// State over a database whose blobs live in `blob_dir`, with no job
    /// kinds registered.
    pub fn new(db: Db, blob_dir: &std::path::Path, max_upload_bytes: u64) -> std::io::Result<Self> {
        let jobs = Jobs::new(JobRegistry::new(), JobsConfig::default());
        Self::with_jobs(db, blob_dir, max_upload_bytes, jobs)
    }

    /// State with the given job machinery (start its runner with
    /// [`crate::jobs::start`] over [`job_context`](Self::job_context)).
    pub fn with_jobs(
        db: Db,
        blob_dir: &std::path::Path,
        max_upload_bytes: u64,
        jobs: Jobs,
    ) -> std::io::Result<Self> {
        Ok(AppState {
            db,
            blobs: BlobStore::open(blob_dir)?,
            max_upload_bytes,
            jobs,
            exposure: Arc::new(Exposure::default()),
            model_cache: Arc::new(model_cache::ModelCache::new(MODEL_CACHE_BYTES)),
            read_permits: offload::permits(),
            auth: Arc::new(auth::AuthConfig::default()),
        })
    }

    /// What job handlers read.
    pub fn job_context(&self) -> JobContext {
        JobContext {
            db: self.db.clone(),
            blobs: self.blobs.clone(),
        }
    }
}

#[derive(OpenApi)]
#[openapi(
    info(
        title = "seatrial",
        description = "Sea-trial system identification of ROVs and dynamically positioned ships: plan trial campaigns, score runs, identify and validate models.",
        license(name = "MIT")
    ),
    components(schemas(ErrorBody, JobEvent, model_export::ExportFormat, crate::storage::jobs::JobKind, crate::storage::jobs::IdentifyMethod, crate::jobs::precision::PrecisionSettings, crate::jobs::precision::PriorChoice, crate::jobs::design::DesignSettings, crate::jobs::next_dive::NextDiveSettings)),
    tags(
        (name = "service", description = "Service health"),
        (name = "accounts", description = "Sign-in, personal API tokens, users and roles, the audit trail"),
        (name = "planning", description = "Vessels, campaigns, excitation plans and their exports"),
        (name = "runs", description = "Uploaded logs, their alignment and data-quality reports"),
        (name = "jobs", description = "Background jobs (identification, discovery, predicted precision, experiment design): submit, follow by polling or Server-Sent Events, cancel, retry"),
        (name = "models", description = "Identified models: versions with provenance, matrices and parameters with uncertainties, validation, exports"),
        (name = "discovery", description = "Missing-physics discovery: where a model and the recordings part, the physics left out, the augmented model and the before/after proof")
    )
)]
struct ApiDoc;

/// The `/api` routes with their OpenAPI description.
pub fn api() -> OpenApiRouter<AppState> {
    OpenApiRouter::with_openapi(ApiDoc::openapi())
        .routes(routes!(health::health))
        .routes(routes!(auth::session::login))
        .routes(routes!(auth::session::logout))
        .routes(routes!(auth::session::me))
        .routes(routes!(auth::session::change_password))
        .routes(routes!(
            auth::tokens::create_token,
            auth::tokens::list_tokens
        ))
        .routes(routes!(auth::tokens::revoke_token))
        .routes(routes!(auth::users::create_user, auth::users::list_users))
        .routes(routes!(auth::users::patch_user))
        .routes(routes!(auth::users::list_audit))
        .routes(routes!(vessels::create_vessel, vessels::list_vessels))
        .routes(routes!(
            vessels::get_vessel,
            vessels::patch_vessel,
            lifecycle_parents::delete_vessel
        ))
        .routes(routes!(lifecycle_parents::restore_vessel))
        .routes(routes!(
            campaigns::create_campaign,
            campaigns::list_campaigns
        ))
        .routes(routes!(
            campaigns::get_campaign,
            manage::patch_campaign,
            lifecycle_parents::delete_campaign
        ))
        .routes(routes!(lifecycle_parents::restore_campaign))
        .routes(routes!(plans::generate_plan, plans::get_plan))
        .routes(routes!(plans::get_experiment))
        .routes(routes!(plans::schedule_csv))
        .routes(routes!(plans::run_sheet))
        .routes(routes!(runs::list_runs))
        .routes(routes!(
            runs::get_run,
            run_description::describe_run,
            lifecycle::delete_run
        ))
        .routes(routes!(lifecycle::restore_run))
        .routes(routes!(runs::raw_run))
        .routes(routes!(runs::run_quality))
        .routes(routes!(run_traces::run_traces))
        .routes(routes!(runs::coverage))
        .routes(routes!(precision::get_precision))
        .routes(routes!(design::get_design))
        .routes(routes!(next_dive::get_next_dive))
        .routes(routes!(next_dive::next_dive_run_sheet))
        .routes(routes!(
            clock_offsets::get_campaign_clock_offset,
            clock_offsets::put_campaign_clock_offset
        ))
        .routes(routes!(
            clock_offsets::get_run_clock_offset,
            clock_offsets::put_run_clock_offset
        ))
        .routes(routes!(jobs::submit_job, jobs::list_jobs))
        .routes(routes!(jobs::get_job))
        .routes(routes!(jobs::cancel_job))
        .routes(routes!(jobs::retry_job))
        .routes(routes!(jobs::job_events))
        .routes(routes!(models::list_models))
        .routes(routes!(models::compare_models))
        .routes(routes!(
            models::get_model,
            manage::patch_model,
            lifecycle::delete_model
        ))
        .routes(routes!(lifecycle::restore_model))
        .routes(routes!(model_export::export_model))
        .routes(routes!(model_views::frequency_response))
        .routes(routes!(model_views::poles))
        .routes(routes!(model_views::step_response))
        .routes(routes!(model_views::hankel))
        .routes(routes!(discrepancies::list_model_discrepancies))
        .routes(routes!(discrepancies::get_discrepancy))
        // Uploads stream to disk under their own limit (counted in the handler).
        .merge(
            OpenApiRouter::new()
                .routes(routes!(runs::upload_run))
                .layer(DefaultBodyLimit::disable()),
        )
}

/// The OpenAPI document of the service, with the role each route needs
/// and the security schemes ([`auth::document`]).
pub fn openapi() -> utoipa::openapi::OpenApi {
    let mut doc = api().split_for_parts().1;
    auth::document(&mut doc);
    doc
}

async fn api_not_found(uri: Uri) -> ApiError {
    ApiError::NotFound(format!("no API route {}", uri.path()))
}

async fn method_not_allowed(method: Method, uri: Uri) -> ApiError {
    ApiError::MethodNotAllowed(format!(
        "{method} is not allowed on {}; see openapi.yaml for the methods of each route",
        uri.path()
    ))
}

/// The whole application: `/api`, and the web UI's files from `web_dir`
/// (uPlot from `web_dir/node_modules`, installed by `npm ci`), behind the
/// Host allow-list, the Origin rule on writes and the security headers
/// ([`exposure`]); every `/api` route behind the accounts guard
/// ([`auth::middleware`]).
pub fn app(state: AppState, web_dir: PathBuf) -> Router {
    let (api, _) = api().split_for_parts();
    let accounts = axum::middleware::from_fn_with_state(state.clone(), auth::middleware::guard);
    let api = api
        .route_layer(accounts)
        .route("/api/{*rest}", axum::routing::any(api_not_found))
        .method_not_allowed_fallback(method_not_allowed)
        .layer(DefaultBodyLimit::max(json::MAX_JSON_BODY));
    let guard = axum::middleware::from_fn_with_state(state.exposure.clone(), exposure::guard);
    let offload =
        axum::middleware::from_fn_with_state(state.read_permits.clone(), offload::offload);
    api.layer(offload)
        .fallback(move |uri: Uri, req: axum::extract::Request| {
            exposure::web_asset(web_dir.clone(), uri, req)
        })
        // Quality reports run to megabytes of JSON; ships share satellite links.
        .layer(CompressionLayer::new())
        .layer(guard)
        .layer(TraceLayer::new_for_http())
        .with_state(state)
}

/// Maps a missing row to a 404 naming what was looked for.
pub(crate) fn found<T>(v: Option<T>, what: &str, id: &str) -> Result<T, ApiError> {
    v.ok_or_else(|| ApiError::NotFound(format!("no {what} with id '{id}'")))
}

/// The campaign and the vessel stored run `run` belongs to; a 404 names
/// the one that is gone.
pub(crate) async fn campaign_and_vessel(
    db: &Db,
    run: &crate::storage::runs::Run,
) -> Result<
    (
        crate::storage::campaigns::Campaign,
        crate::storage::vessels::Vessel,
    ),
    ApiError,
> {
    let campaign = found(
        crate::storage::campaigns::get(db, &run.campaign_id).await?,
        "campaign",
        &run.campaign_id,
    )?;
    let vessel = found(
        crate::storage::vessels::get(db, &campaign.vessel_id).await?,
        "vessel",
        &campaign.vessel_id,
    )?;
    Ok((campaign, vessel))
}

/// Runs CPU-bound work off the async runtime.
pub(crate) async fn blocking<T: Send + 'static>(
    f: impl FnOnce() -> T + Send + 'static,
) -> Result<T, ApiError> {
    tokio::task::spawn_blocking(f)
        .await
        .map_err(|e| ApiError::Internal(anyhow::anyhow!("worker task failed: {e}")))
}
