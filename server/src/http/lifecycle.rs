//! Soft deletes with undo: `DELETE` a run or a model version marks it
//! deleted (who, when, why) — it leaves the lists and identification but
//! stays readable by id, so every model built from it keeps its provenance —
//! and `POST …/{id}/restore` undoes it. The reason also goes to the audit
//! trail ([`AuditNote`]). Every write is one transaction.

use axum::extract::{Path, State};
use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};
use axum::{Extension, Json};
use serde::{Deserialize, Serialize};

use super::auth::middleware::AuditNote;
use super::auth::{Principal, Role};
use super::lifecycle_parents::{restored, restored_version};
use super::query::ApiQuery;
use super::run_description::MAX_NOTES_CHARS;
use super::{AppState, found};
use crate::error::{ApiError, ApiResult, ErrorBody};
use crate::storage::models::{self, ModelSummary};
use crate::storage::purge::{self, Purged};
use crate::storage::runs::{self, Run};
use seatrial_core::planning::PlanError;

/// Why a run is deleted, and whether for good.
#[derive(Debug, Deserialize, utoipa::IntoParams)]
#[into_params(parameter_in = Query)]
pub struct DeleteRunQuery {
    /// Why (at most 2000 characters); kept with the run and in the audit trail.
    pub reason: Option<String>,
    /// `true` (admin only): remove an already deleted run for good — its
    /// rows and the stored files no other run shares (default false).
    pub purge: Option<bool>,
}

/// Options of a model deletion.
#[derive(Debug, Deserialize, utoipa::IntoParams)]
#[into_params(parameter_in = Query)]
pub struct DeleteModelQuery {
    /// Also delete every live version derived from this one (default false: 409 when there is one).
    pub cascade: Option<bool>,
    /// Why (at most 2000 characters); kept with the model and in the audit trail.
    pub reason: Option<String>,
}

/// A deleted run and what keeps pointing at it.
#[derive(Debug, Serialize, utoipa::ToSchema)]
pub struct DeletedRun {
    /// The run, with `deleted_at`, `deleted_by` and `delete_reason`.
    pub run: Run,
    /// The models and discovery reports built from it (their provenance
    /// still names it), as phrases with their ids.
    pub used_by: Vec<String>,
}

/// What a model deletion marked deleted.
#[derive(Debug, Serialize, utoipa::ToSchema)]
pub struct DeletedModels {
    /// The model and, with `cascade`, the versions derived from it (restore each to undo).
    pub deleted: Vec<String>,
}

/// The trimmed reason, `None` when blank; 422 when too long.
pub(super) fn reason(r: Option<&str>) -> Result<Option<String>, ApiError> {
    let r = r.map(str::trim).filter(|r| !r.is_empty());
    if let Some(r) = r
        && r.chars().count() > MAX_NOTES_CHARS
    {
        return Err(ApiError::Unprocessable(PlanError::over_limit(
            "reason",
            format!("a reason is limited to {MAX_NOTES_CHARS} characters"),
            MAX_NOTES_CHARS as f64,
        )));
    }
    Ok(r.map(String::from))
}

/// The answer with the reason for the audit row.
pub(super) fn noted(resp: impl IntoResponse, note: Option<String>) -> Response {
    let mut resp = resp.into_response();
    if let Some(n) = note {
        resp.extensions_mut().insert(AuditNote(n));
    }
    resp
}

/// The acting user's name (`local` in local mode).
pub(super) fn actor(p: Option<&Extension<Principal>>) -> String {
    p.map_or_else(|| "local".to_string(), |p| p.name().to_string())
}

/// Delete a run (soft): it leaves the campaign's lists, coverage and
/// identification, but stays readable by id with its files, so the
/// provenance of every model built from it stays whole; `POST
/// /api/runs/{id}/restore` undoes it. A rejected upload is removed the same way.
/// `?purge=true` (admin) then removes a deleted run for good, unless a
/// stored model or discovery report (deleted ones too) names it.
#[utoipa::path(delete, path = "/api/runs/{id}", tag = "runs",
    params(("id" = String, Path, description = "Run id"), DeleteRunQuery),
    responses((status = 200, description = "Deleted: the run as it now is, and what was built from it", body = DeletedRun),
              (status = 204, description = "Purged (`purge=true`): the run's rows and its unshared files are gone"),
              (status = 400, description = "Malformed `purge`", body = ErrorBody),
              (status = 404, description = "No such run, or deleted already (without `purge`)", body = ErrorBody),
              (status = 409, description = "`purge` of a run not deleted, or one a stored model's or report's provenance uses (named by name and id)", body = ErrorBody),
              (status = 422, description = "`reason` over 2000 characters", body = ErrorBody)))]
pub async fn delete_run(
    State(s): State<AppState>,
    Path(id): Path<String>,
    who: Option<Extension<Principal>>,
    ApiQuery(q): ApiQuery<DeleteRunQuery>,
) -> ApiResult<Response> {
    let why = reason(q.reason.as_deref())?;
    if q.purge.unwrap_or(false) {
        return purge_run(&s, &id, who.as_ref(), why).await;
    }
    match runs::delete(&s.db, &id, &actor(who.as_ref()), why.as_deref()).await? {
        runs::Deleted::NotFound => Err(ApiError::NotFound(format!(
            "no run with id '{id}' (or it is deleted already)"
        ))),
        runs::Deleted::Gone(used_by) => {
            let run = found(runs::get(&s.db, &id).await?, "run", &id)?;
            Ok(noted(Json(DeletedRun { run, used_by }), why))
        }
    }
}

/// `DELETE /api/runs/{id}?purge=true`: admins only (the route itself needs
/// a supervisor); the audit row's note says it was purged.
async fn purge_run(
    s: &AppState,
    id: &str,
    who: Option<&Extension<Principal>>,
    why: Option<String>,
) -> ApiResult<Response> {
    if who.is_some_and(|p| p.role < Role::Admin) {
        return Err(ApiError::forbidden(
            "role",
            "purging a run for good needs the admin role",
        ));
    }
    match purge::run(&s.db, &s.blobs, id).await? {
        Purged::NotFound => Err(ApiError::NotFound(format!("no run with id '{id}'"))),
        Purged::NotDeleted(name) => Err(ApiError::Conflict(format!(
            "run '{name}' ({id}) is not deleted: delete it first, then purge it"
        ))),
        Purged::InUse(name, users) => Err(ApiError::Conflict(format!(
            "run '{name}' ({id}) is kept: the provenance of {} uses it",
            users.join(", ")
        ))),
        Purged::Done(name, files) => {
            let note = format!(
                "purged run '{name}' ({id}), {} file(s) removed{}",
                files.len(),
                why.map(|w| format!(": {w}")).unwrap_or_default()
            );
            Ok(noted(StatusCode::NO_CONTENT, Some(note)))
        }
    }
}

/// Undo the delete of a run.
#[utoipa::path(post, path = "/api/runs/{id}/restore", tag = "runs",
    params(("id" = String, Path, description = "Run id")),
    responses((status = 200, description = "Restored: the run", body = Run),
              (status = 404, description = "No such run", body = ErrorBody),
              (status = 409, description = "The run is not deleted, or its campaign or vessel is (named by name and id)", body = ErrorBody)))]
pub async fn restore_run(
    State(s): State<AppState>,
    Path(id): Path<String>,
) -> ApiResult<Json<Run>> {
    let r = runs::restore(&s.db, &id).await?;
    let run = runs::get(&s.db, &id).await?;
    restored(r, "run", &id, run.as_ref().map_or("", |r| r.name.as_str()))?;
    Ok(Json(found(run, "run", &id)?))
}

/// Delete a model version (soft), with the versions derived from it when
/// asked. A version a live one was derived from (an augmented model, a
/// re-identification) is kept with a 409 naming them, unless
/// `?cascade=true` deletes those too; so is a model a queued or running job
/// works on. A deleted version leaves the lists but stays readable by id
/// (with its discovery reports); `POST /api/models/{id}/restore` undoes it.
#[utoipa::path(delete, path = "/api/models/{id}", tag = "models",
    params(("id" = String, Path, description = "Model id"), DeleteModelQuery),
    responses(
        (status = 200, description = "Deleted: the ids marked deleted", body = DeletedModels),
        (status = 400, description = "Malformed `cascade`", body = ErrorBody),
        (status = 404, description = "No such model, or deleted already", body = ErrorBody),
        (status = 409, description = "Versions were derived from it (without `cascade`), or a job works on it; the message names them", body = ErrorBody),
        (status = 422, description = "`reason` over 2000 characters", body = ErrorBody)))]
pub async fn delete_model(
    State(s): State<AppState>,
    Path(id): Path<String>,
    who: Option<Extension<Principal>>,
    ApiQuery(q): ApiQuery<DeleteModelQuery>,
) -> ApiResult<Response> {
    let why = reason(q.reason.as_deref())?;
    let by = actor(who.as_ref());
    match models::delete(&s.db, &id, q.cascade.unwrap_or(false), &by, why.as_deref()).await? {
        models::Deleted::NotFound => Err(ApiError::NotFound(format!(
            "no model with id '{id}' (or it is deleted already)"
        ))),
        models::Deleted::InUse(why) => Err(ApiError::Conflict(format!(
            "model {} is kept: {}{}",
            named_model(&s, &id).await?,
            why.join("; "),
            if why.iter().any(|w| w.contains("derived")) {
                " (delete with ?cascade=true to remove those versions too)"
            } else {
                ""
            }
        ))),
        models::Deleted::Gone(deleted) => {
            for gone in &deleted {
                s.model_cache.forget(gone);
            }
            Ok(noted(Json(DeletedModels { deleted }), why))
        }
    }
}

/// `'name' v3 (id)` of a model.
async fn named_model(s: &AppState, id: &str) -> ApiResult<String> {
    let m = found(models::summary(&s.db, id).await?, "model", id)?;
    Ok(format!("'{}' v{} ({id})", m.name, m.version))
}

/// Undo the delete of a model version (one version: after a cascade,
/// restore each id the delete answered).
#[utoipa::path(post, path = "/api/models/{id}/restore", tag = "models",
    params(("id" = String, Path, description = "Model id")),
    responses((status = 200, description = "Restored: the model's metadata", body = ModelSummary),
              (status = 404, description = "No such model", body = ErrorBody),
              (status = 409, description = "The model is not deleted, or its campaign or vessel is (named by name and id)", body = ErrorBody)))]
pub async fn restore_model(
    State(s): State<AppState>,
    Path(id): Path<String>,
) -> ApiResult<Json<ModelSummary>> {
    let r = models::restore(&s.db, &id).await?;
    let m = models::summary(&s.db, &id).await?;
    let (name, version) = m
        .as_ref()
        .map_or(("", None), |m| (m.name.as_str(), Some(m.version)));
    restored_version(r, "model", &id, name, version)?;
    s.model_cache.forget(&id);
    Ok(Json(found(m, "model", &id)?))
}
