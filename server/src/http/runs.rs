//! Runs: streamed upload (stored verbatim with SHA-256 before parsing), the
//! bytes back, the quality report, and the campaign's coverage.

use axum::Json;
use axum::body::Body;
use axum::extract::multipart::{Field, MultipartRejection};
use axum::extract::{Multipart, Path, State};
use axum::http::{HeaderMap, StatusCode, header};
use axum::response::{IntoResponse, Response};
use serde::Deserialize;

use super::json::parse_json;
use super::query::{ApiQuery, Paging, with_total};
use super::run_description::{DescriptionChange, from_value};
use super::{AppState, found};
use seatrial_core::alignment::check_user_offset;

use crate::coverage::{self, Coverage};
use crate::error::{ApiError, ApiResult, ErrorBody};
use crate::intake;
use crate::processing::RunMeta;
use crate::storage::blobs::BlobWriter;
use crate::storage::runs::{self, NewFile, Run};
use crate::storage::{campaigns, plans, vessels};

/// The multipart form of an upload (documentation of the parts).
#[derive(Debug, utoipa::ToSchema)]
#[allow(dead_code)]
pub struct UploadForm {
    /// JSON metadata: `{"experiment_id"?, "name"?, "shared_channel"? (default "z"), "rate_hz"?,
    /// "clock_offset_s"? (two-file runs: the offset set by hand, s), "role"?, "grid_speed_mps"?
    /// or "grid_speed_kn"?, "excited_dofs"?, "signal"?, "notes"?}`; what is not said about the
    /// run comes from its planned experiment, else from its data.
    meta: Option<RunMeta>,
    /// A single log with every column the vessel needs.
    #[schema(value_type = Option<String>, format = Binary)]
    file: Option<Vec<u8>>,
    /// The controller log of a two-file run (t, inputs, the shared channel).
    #[schema(value_type = Option<String>, format = Binary)]
    control: Option<Vec<u8>>,
    /// The navigation log of a two-file run (t, velocities, pose, the shared channel).
    #[schema(value_type = Option<String>, format = Binary)]
    nav: Option<Vec<u8>>,
}

const FILE_ROLES: [&str; 3] = ["file", "control", "nav"];
const MAX_META_BYTES: usize = 64 * 1024;

fn too_large(limit: u64) -> ApiError {
    ApiError::too_large(
        "the upload",
        limit,
        " (all files of a run together; server flag --max-upload-mb)",
    )
}

async fn stream_field(
    s: &AppState,
    field: &mut Field<'_>,
    w: &mut BlobWriter,
    total: &mut u64,
) -> ApiResult<()> {
    loop {
        let chunk = field.chunk().await.map_err(|e| {
            if e.status() == StatusCode::PAYLOAD_TOO_LARGE {
                too_large(s.max_upload_bytes)
            } else {
                ApiError::BadRequest {
                    message: format!("the multipart upload broke off: {e}"),
                    field: field.name().map(str::to_string),
                }
            }
        })?;
        let Some(chunk) = chunk else { return Ok(()) };
        *total += chunk.len() as u64;
        if *total > s.max_upload_bytes {
            return Err(too_large(s.max_upload_bytes));
        }
        w.write(&chunk)
            .await
            .map_err(|e| ApiError::Internal(anyhow::anyhow!("writing the upload: {e}")))?;
    }
}

/// A run named after its file: control characters escaped, at most
/// [`seatrial_core::planning::MAX_NAME_LEN`] bytes.
fn run_name_of_file(filename: &str) -> String {
    let mut name = seatrial_core::numbers::escape_controls(filename);
    if name.len() > seatrial_core::planning::MAX_NAME_LEN {
        let mut end = seatrial_core::planning::MAX_NAME_LEN;
        while !name.is_char_boundary(end) {
            end -= 1;
        }
        name.truncate(end);
    }
    name
}

/// Upload a run: `multipart/form-data` with an optional `meta` part (JSON)
/// and either one `file` part or `control` + `nav` parts. Files are streamed
/// to disk and stored verbatim with their SHA-256 before they are parsed; a
/// run that fails validation stays stored (status `rejected`) and the 422
/// names its file, line and column. What the run is (role, grid speed,
/// excited DOFs, signal) is taken from `meta`, else from the planned
/// experiment, else inferred from the data; a `meta` field the service does
/// not accept is a 422 naming it (`meta.role`, …) and nothing is recorded.
#[utoipa::path(post, path = "/api/campaigns/{id}/runs", tag = "runs",
    params(("id" = String, Path, description = "Campaign id")),
    request_body(content = UploadForm, content_type = "multipart/form-data"),
    responses(
        (status = 201, description = "Stored, parsed and scored", body = Run),
        (status = 400, description = "Malformed upload: missing or unknown parts", body = ErrorBody),
        (status = 404, description = "No such campaign or experiment", body = ErrorBody),
        (status = 409, description = "The campaign or its vessel is deleted (named by name and id)", body = ErrorBody),
        (status = 413, description = "Over the upload limit", body = ErrorBody),
        (status = 415, description = "Not multipart/form-data", body = ErrorBody),
        (status = 422, description = "Stored but invalid: `field` is the file, with `line` and `column`; `run_id` names the stored run. Or a `meta` field not accepted (`field` = `meta.…`, no run recorded)", body = ErrorBody)))]
pub async fn upload_run(
    State(s): State<AppState>,
    Path(id): Path<String>,
    headers: HeaderMap,
    multipart: Result<Multipart, MultipartRejection>,
) -> ApiResult<(StatusCode, Json<Run>)> {
    let campaign = found(campaigns::get(&s.db, &id).await?, "campaign", &id)?;
    super::lifecycle_parents::refuse_deleted(&s.db, "campaign", &id).await?;
    let vessel = found(
        vessels::get(&s.db, &campaign.vessel_id).await?,
        "vessel",
        &campaign.vessel_id,
    )?;
    if let Some(len) = headers
        .get(header::CONTENT_LENGTH)
        .and_then(|v| v.to_str().ok())
        .and_then(|v| v.parse::<u64>().ok())
        && len > s.max_upload_bytes
    {
        return Err(too_large(s.max_upload_bytes));
    }
    let mut multipart = multipart.map_err(|e| {
        ApiError::UnsupportedMediaType(format!(
            "upload the run as multipart/form-data with a 'file' part (or 'control' and 'nav'): {e}"
        ))
    })?;
    let mut meta = RunMeta::default();
    let mut user = Default::default();
    let mut files: Vec<NewFile> = Vec::new();
    let mut total = 0u64;
    loop {
        let next = multipart
            .next_field()
            .await
            .map_err(|e| ApiError::BadRequest {
                message: format!("malformed multipart body: {e}"),
                field: None,
            })?;
        let Some(mut field) = next else { break };
        let name = field.name().unwrap_or("").to_string();
        if name == "meta" {
            let bytes = field
                .bytes()
                .await
                .map_err(|e| ApiError::bad_field("meta", format!("unreadable: {e}")))?;
            if bytes.len() > MAX_META_BYTES {
                return Err(ApiError::bad_field("meta", "metadata is limited to 64 KB"));
            }
            let v: serde_json::Value = parse_json(&bytes).map_err(|e| match e {
                ApiError::BadRequest { message, field } => ApiError::BadRequest {
                    message,
                    field: Some(field.map_or("meta".into(), |f| format!("meta.{f}"))),
                },
                other => other,
            })?;
            meta = from_value(v, "meta.")?;
            if let Some(n) = &meta.name {
                seatrial_core::planning::check_name("meta.name", n)?;
            }
            if let Some(r) = meta.rate_hz {
                seatrial_core::logs::check_rate_hz(r)
                    .map_err(|m| ApiError::invalid("meta.rate_hz", m))?;
            }
            // Checked at once: a `meta` sent before the files refuses the
            // upload before any byte is stored.
            DescriptionChange::of_meta(&meta).apply(&mut user, &vessel.profile, "meta.")?;
            if let Some(v) = meta.clock_offset_s {
                check_user_offset("meta.clock_offset_s", v)
                    .map_err(|e| ApiError::invalid("meta.clock_offset_s", e.message()))?;
            }
            continue;
        }
        if !FILE_ROLES.contains(&name.as_str()) {
            return Err(ApiError::bad_field(
                name.clone(),
                format!("unknown part '{name}'; expected meta, and file or control + nav"),
            ));
        }
        if files.iter().any(|f| f.role == name) {
            return Err(ApiError::bad_field(
                name.clone(),
                format!("the part '{name}' appears twice"),
            ));
        }
        let filename = field.file_name().unwrap_or(&name).to_string();
        let mut w = s
            .blobs
            .begin()
            .await
            .map_err(|e| ApiError::Internal(anyhow::anyhow!("creating a blob: {e}")))?;
        if let Err(e) = stream_field(&s, &mut field, &mut w, &mut total).await {
            w.abort().await;
            return Err(e);
        }
        if w.size() == 0 {
            w.abort().await;
            return Err(ApiError::bad_field(name, "the file is empty"));
        }
        let blob = w
            .finish()
            .await
            .map_err(|e| ApiError::Internal(anyhow::anyhow!("storing the upload: {e}")))?;
        files.push(NewFile {
            role: name,
            filename,
            blob,
        });
    }
    let roles: Vec<&str> = files.iter().map(|f| f.role.as_str()).collect();
    let layout = match roles.as_slice() {
        ["file"] => "single",
        r if r.len() == 2 && r.contains(&"control") && r.contains(&"nav") => "split",
        [] => {
            return Err(ApiError::bad_field(
                "file",
                "no file uploaded: send a 'file' part, or 'control' and 'nav'",
            ));
        }
        _ => {
            return Err(ApiError::bad_field(
                "file",
                format!(
                    "send either one 'file' part or both 'control' and 'nav' (got {})",
                    roles.join(", ")
                ),
            ));
        }
    };
    if meta.clock_offset_s.is_some() && layout == "single" {
        return Err(ApiError::invalid(
            "meta.clock_offset_s",
            "a single-file run has one clock: a clock offset applies to two-file runs (control + nav)",
        ));
    }
    let planned = match &meta.experiment_id {
        Some(eid) => Some(
            plans::experiment(&s.db, &campaign.id, eid)
                .await?
                .ok_or_else(|| {
                    ApiError::NotFound(format!(
                        "no experiment '{eid}' in this campaign's plans (field meta.experiment_id)"
                    ))
                })?,
        ),
        None => None,
    };
    let name = meta
        .name
        .clone()
        .or_else(|| planned.as_ref().map(|(e, _)| e.experiment.code.clone()))
        .unwrap_or_else(|| run_name_of_file(&files[0].filename));
    let upload_meta = serde_json::to_value(&meta).map_err(anyhow::Error::from)?;
    let run = runs::insert(
        &s.db,
        &campaign.id,
        meta.experiment_id.as_deref(),
        &name,
        layout,
        &files,
        &user,
        &upload_meta,
    )
    .await?;
    match intake::process_stored(&s.db, &s.blobs, &run.id).await? {
        Ok(run) => Ok((StatusCode::CREATED, Json(run))),
        Err(e) => Err(ApiError::InvalidUpload {
            message: e.message,
            field: e.file,
            line: e.line,
            column: e.column,
            run_id: run.id,
        }),
    }
}

/// Which runs of a campaign to list.
#[derive(Debug, Deserialize, utoipa::IntoParams)]
#[into_params(parameter_in = Query)]
pub struct RunFilter {
    /// Only runs with this status: `accepted`, `rejected` (uploads that failed
    /// validation, listed apart) or `stored`.
    pub status: Option<String>,
    /// `true`: the deleted runs instead of the live ones (default false).
    pub deleted: Option<bool>,
}

const RUN_STATUSES: [&str; 3] = ["stored", "accepted", "rejected"];

/// Runs of a campaign, oldest first, without the deleted ones
/// (`?deleted=true` lists those), each with `excluded` (left out of
/// identification) and its reason; `limit`/`offset` page the list and the
/// `X-Total-Count` header gives how many match.
#[utoipa::path(get, path = "/api/campaigns/{id}/runs", tag = "runs",
    params(("id" = String, Path, description = "Campaign id"), RunFilter, Paging),
    responses((status = 200, description = "Runs, oldest first", body = [Run],
                headers(("x-total-count" = i64, description = "Runs that match the filter (all pages)"))),
              (status = 400, description = "Malformed query parameter", body = ErrorBody),
              (status = 404, description = "No such campaign", body = ErrorBody),
              (status = 422, description = "`limit` outside 1–1000 or an unknown `status`", body = ErrorBody)))]
pub async fn list_runs(
    State(s): State<AppState>,
    Path(id): Path<String>,
    ApiQuery(f): ApiQuery<RunFilter>,
    ApiQuery(p): ApiQuery<Paging>,
) -> ApiResult<Response> {
    let page = p.page()?;
    if let Some(st) = &f.status
        && !RUN_STATUSES.contains(&st.as_str())
    {
        return Err(ApiError::invalid(
            "status",
            format!("unknown status '{st}'; one of {}", RUN_STATUSES.join(", ")),
        ));
    }
    found(campaigns::get(&s.db, &id).await?, "campaign", &id)?;
    let (items, total) = runs::page(
        &s.db,
        &id,
        f.status.as_deref(),
        f.deleted.unwrap_or(false),
        page,
    )
    .await?;
    Ok(with_total(items, total))
}

/// One run: files, status, summary (rates, gaps, warnings, alignment,
/// verdicts) and what it is (role, grid speed, excited DOFs, signal, notes,
/// each with its source: `user`, `plan` or `inferred` with the reason).
#[utoipa::path(get, path = "/api/runs/{id}", tag = "runs",
    params(("id" = String, Path, description = "Run id")),
    responses((status = 200, description = "The run", body = Run),
              (status = 404, description = "No such run", body = ErrorBody)))]
pub async fn get_run(State(s): State<AppState>, Path(id): Path<String>) -> ApiResult<Json<Run>> {
    Ok(Json(found(runs::get(&s.db, &id).await?, "run", &id)?))
}

/// Which file of a run.
#[derive(Debug, Deserialize, utoipa::IntoParams)]
#[into_params(parameter_in = Query)]
pub struct RawQuery {
    /// `file` (single-file run, the default), `control` or `nav`.
    pub file: Option<String>,
}

/// The uploaded bytes, exactly as received (SHA-256 in `X-Content-SHA256` and the ETag).
#[utoipa::path(get, path = "/api/runs/{id}/raw", tag = "runs",
    params(("id" = String, Path, description = "Run id"), RawQuery),
    responses((status = 200, description = "The uploaded file", content_type = "text/csv", body = String),
              (status = 400, description = "A two-file run needs ?file=control or ?file=nav", body = ErrorBody),
              (status = 404, description = "No such run or file", body = ErrorBody)))]
pub async fn raw_run(
    State(s): State<AppState>,
    Path(id): Path<String>,
    ApiQuery(q): ApiQuery<RawQuery>,
) -> ApiResult<Response> {
    let run = found(runs::get(&s.db, &id).await?, "run", &id)?;
    let role = match (q.file.as_deref(), run.layout.as_str()) {
        (Some(r), _) => r.to_string(),
        (None, "single") => "file".to_string(),
        (None, _) => {
            return Err(ApiError::bad_field(
                "file",
                "this run has two files: ask for ?file=control or ?file=nav",
            ));
        }
    };
    let f = run
        .files
        .iter()
        .find(|f| f.role == role)
        .ok_or_else(|| ApiError::NotFound(format!("run '{id}' has no file '{role}'")))?;
    let file = tokio::fs::File::open(s.blobs.path(&f.sha256))
        .await
        .map_err(|e| ApiError::Internal(anyhow::anyhow!("blob {} unreadable: {e}", f.sha256)))?;
    let body = Body::from_stream(tokio_util::io::ReaderStream::new(file));
    let disposition = super::exposure::attachment(&f.filename);
    Ok((
        [
            (header::CONTENT_TYPE, "text/csv".to_string()),
            (header::CONTENT_LENGTH, f.size_bytes.to_string()),
            (header::CONTENT_DISPOSITION, disposition),
            (header::ETAG, format!("\"{}\"", f.sha256)),
            (
                header::HeaderName::from_static("x-content-sha256"),
                f.sha256.clone(),
            ),
        ],
        body,
    )
        .into_response())
}

/// The run's data-quality report: spectra, coherence, H1, regressor singular
/// values, PE per input, plan adherence and a verdict per DOF.
#[utoipa::path(get, path = "/api/runs/{id}/quality", tag = "runs",
    params(("id" = String, Path, description = "Run id")),
    responses((status = 200, description = "The report", body = seatrial_core::quality::QualityReport),
              (status = 404, description = "No such run, or it was rejected", body = ErrorBody)))]
pub async fn run_quality(State(s): State<AppState>, Path(id): Path<String>) -> ApiResult<Response> {
    let run = found(runs::get(&s.db, &id).await?, "run", &id)?;
    let report = runs::quality(&s.db, &id).await?.ok_or_else(|| {
        ApiError::NotFound(format!(
            "run '{id}' has no quality report (status {}): {}",
            run.status,
            run.error
                .as_ref()
                .and_then(|e| e["message"].as_str())
                .unwrap_or("not processed")
        ))
    })?;
    Ok(([(header::CONTENT_TYPE, "application/json")], report).into_response())
}

/// The campaign's coverage: for each planned experiment, its runs and whether
/// it is covered by a good run, weak, must be repeated, or missing.
#[utoipa::path(get, path = "/api/campaigns/{id}/coverage", tag = "runs",
    params(("id" = String, Path, description = "Campaign id")),
    responses((status = 200, description = "Coverage of the newest plan", body = Coverage),
              (status = 404, description = "No such campaign, or not planned yet", body = ErrorBody)))]
pub async fn coverage(
    State(s): State<AppState>,
    Path(id): Path<String>,
) -> ApiResult<Json<Coverage>> {
    found(campaigns::get(&s.db, &id).await?, "campaign", &id)?;
    let plan = plans::latest(&s.db, &id)
        .await?
        .ok_or_else(|| ApiError::NotFound(format!("campaign '{id}' has no plan yet")))?;
    let runs = runs::list(&s.db, &id).await?;
    Ok(Json(coverage::coverage(&plan, &runs)))
}
