//! Identified models: versioned rows with provenance. The model itself (the
//! core's document: matrices, parameters, uncertainties) and its validation
//! reports are JSON columns; the metadata columns are what lists and
//! lineages query.

use serde::Serialize;
use sqlx::SqliteConnection;

use super::{Db, Page, Restored, lock_row, new_id, now};

/// A stored model without its (large) document and validation.
#[derive(Debug, Clone, Serialize, sqlx::FromRow, utoipa::ToSchema)]
pub struct ModelSummary {
    /// Id (UUIDv7).
    pub id: String,
    /// The lineage (the id of version 1) this version belongs to.
    pub lineage_id: String,
    /// Version within the lineage, from 1.
    pub version: i64,
    /// The version it was derived from (augmentation, re-identification).
    pub parent_id: Option<String>,
    /// Campaign whose runs it was identified from.
    pub campaign_id: String,
    /// Vessel.
    pub vessel_id: String,
    /// `lpv`, `dp_ship` or `state_space`.
    pub kind: String,
    /// `lambda_kf`, `parallel_ekf`, `n4sid` or `discovery`.
    pub method: String,
    /// Display name.
    pub name: String,
    /// Software version that identified it.
    pub software_version: String,
    /// The job that produced it.
    pub job_id: Option<String>,
    /// Creation time (RFC 3339).
    pub created_at: String,
    /// The engineer's notes.
    pub notes: Option<String>,
    /// When it was deleted (RFC 3339; `null`: not deleted). A deleted version
    /// stays readable by id (provenance) but leaves the lists; `POST
    /// /api/models/{id}/restore` undoes the delete.
    pub deleted_at: Option<String>,
    /// Who deleted it (user name).
    pub deleted_by: Option<String>,
    /// Why it was deleted.
    pub delete_reason: Option<String>,
}

/// A stored model with provenance, document and validation (JSON).
#[derive(Debug, Clone)]
pub struct StoredModel {
    /// Metadata.
    pub summary: ModelSummary,
    /// Method settings as used.
    pub settings: serde_json::Value,
    /// Estimation runs.
    pub run_ids: Vec<String>,
    /// Runs held out for validation.
    pub validation_run_ids: Vec<String>,
    /// The model (core document).
    pub document: serde_json::Value,
    /// Validation reports per held-out run.
    pub validation: serde_json::Value,
}

/// Where a new model goes in the version history.
#[derive(Debug, Clone)]
pub enum Lineage {
    /// Version 1 of a new lineage.
    New,
    /// The next version of the lineage of this model (which becomes the parent).
    After(String),
}

/// A model to store.
#[derive(Debug, Clone)]
pub struct NewModel {
    /// Position in the version history.
    pub lineage: Lineage,
    /// Campaign.
    pub campaign_id: String,
    /// Vessel.
    pub vessel_id: String,
    /// `lpv`, `dp_ship`, `state_space`.
    pub kind: String,
    /// Method name.
    pub method: String,
    /// Display name.
    pub name: String,
    /// Settings as used.
    pub settings: serde_json::Value,
    /// Estimation runs.
    pub run_ids: Vec<String>,
    /// Validation runs.
    pub validation_run_ids: Vec<String>,
    /// The producing job.
    pub job_id: Option<String>,
    /// The model.
    pub document: serde_json::Value,
    /// Validation reports.
    pub validation: serde_json::Value,
}

const SUMMARY: &str = "id, lineage_id, version, parent_id, campaign_id, vessel_id, kind, method, \
                       name, software_version, job_id, created_at, notes, deleted_at, deleted_by, delete_reason";

/// Stores a model inside the caller's transaction (so a job's success and its
/// model commit together); versions are assigned here.
pub async fn insert(tx: &mut SqliteConnection, m: NewModel) -> anyhow::Result<ModelSummary> {
    let id = new_id();
    let (lineage_id, version, parent_id) = match &m.lineage {
        Lineage::New => (id.clone(), 1_i64, None),
        Lineage::After(parent) => {
            let lineage: Option<(String,)> =
                sqlx::query_as("SELECT lineage_id FROM model WHERE id = $1")
                    .bind(parent)
                    .fetch_optional(&mut *tx)
                    .await?;
            let Some((lineage_id,)) = lineage else {
                anyhow::bail!("no model with id '{parent}' to version after");
            };
            let (max,): (i64,) =
                sqlx::query_as("SELECT COALESCE(MAX(version), 0) FROM model WHERE lineage_id = $1")
                    .bind(&lineage_id)
                    .fetch_one(&mut *tx)
                    .await?;
            (lineage_id, max + 1, Some(parent.clone()))
        }
    };
    sqlx::query(
        "INSERT INTO model (id, lineage_id, version, parent_id, campaign_id, vessel_id, kind, \
         method, name, settings, run_ids, validation_run_ids, software_version, job_id, \
         document, validation, created_at) \
         VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11, $12, $13, $14, $15, $16, $17)",
    )
    .bind(&id)
    .bind(&lineage_id)
    .bind(version)
    .bind(&parent_id)
    .bind(&m.campaign_id)
    .bind(&m.vessel_id)
    .bind(&m.kind)
    .bind(&m.method)
    .bind(&m.name)
    .bind(m.settings.to_string())
    .bind(serde_json::to_string(&m.run_ids)?)
    .bind(serde_json::to_string(&m.validation_run_ids)?)
    .bind(env!("CARGO_PKG_VERSION"))
    .bind(&m.job_id)
    .bind(m.document.to_string())
    .bind(m.validation.to_string())
    .bind(now())
    .execute(&mut *tx)
    .await?;
    let summary = sqlx::query_as::<_, ModelSummary>(sqlx::AssertSqlSafe(format!(
        "SELECT {SUMMARY} FROM model WHERE id = $1"
    )))
    .bind(&id)
    .fetch_one(&mut *tx)
    .await?;
    Ok(summary)
}

/// The latest version of the lineage identified from `campaign_id` by
/// `method`, if any (re-identification continues it).
pub async fn latest_of_method(
    db: &Db,
    campaign_id: &str,
    method: &str,
) -> anyhow::Result<Option<ModelSummary>> {
    Ok(
        sqlx::query_as::<_, ModelSummary>(sqlx::AssertSqlSafe(format!(
            "SELECT {SUMMARY} FROM model WHERE campaign_id = $1 AND method = $2 \
         AND deleted_at IS NULL ORDER BY created_at DESC, version DESC LIMIT 1"
        )))
        .bind(campaign_id)
        .bind(method)
        .fetch_optional(db)
        .await?,
    )
}

#[derive(sqlx::FromRow)]
struct Heavy {
    settings: String,
    run_ids: String,
    validation_run_ids: String,
    document: String,
    validation: String,
}

/// One model's metadata (name, notes, version, lineage), without its document.
pub async fn summary(db: &Db, id: &str) -> anyhow::Result<Option<ModelSummary>> {
    Ok(
        sqlx::query_as::<_, ModelSummary>(sqlx::AssertSqlSafe(format!(
            "SELECT {SUMMARY} FROM model WHERE id = $1"
        )))
        .bind(id)
        .fetch_optional(db)
        .await?,
    )
}

/// One model with everything.
pub async fn get(db: &Db, id: &str) -> anyhow::Result<Option<StoredModel>> {
    let Some(summary) = summary(db, id).await? else {
        return Ok(None);
    };
    let h = sqlx::query_as::<_, Heavy>(
        "SELECT settings, run_ids, validation_run_ids, document, validation FROM model WHERE id = $1",
    )
    .bind(id)
    .fetch_one(db)
    .await?;
    Ok(Some(StoredModel {
        summary,
        settings: serde_json::from_str(&h.settings)?,
        run_ids: serde_json::from_str(&h.run_ids)?,
        validation_run_ids: serde_json::from_str(&h.validation_run_ids)?,
        document: serde_json::from_str(&h.document)?,
        validation: serde_json::from_str(&h.validation)?,
    }))
}

/// A page of models, newest first, optionally of one campaign or lineage,
/// the live ones or (`deleted`) the deleted ones, and the number that match.
/// Without a campaign, live models of a deleted campaign (or of one on a
/// deleted vessel) are left out, as their campaign is; the campaign's own
/// list still shows them.
pub async fn page(
    db: &Db,
    campaign_id: Option<&str>,
    lineage_id: Option<&str>,
    deleted: bool,
    page: Page,
) -> anyhow::Result<(Vec<ModelSummary>, i64)> {
    let state = if deleted {
        "deleted_at IS NOT NULL".to_string()
    } else {
        format!(
            "deleted_at IS NULL AND ($1 IS NOT NULL OR campaign_id IN \
             (SELECT campaign.id FROM campaign WHERE {}))",
            super::campaigns::LIVE
        )
    };
    let filter = format!(
        "WHERE ($1 IS NULL OR campaign_id = $1) AND ($2 IS NULL OR lineage_id = $2) AND {state}"
    );
    let (total,): (i64,) = sqlx::query_as(sqlx::AssertSqlSafe(format!(
        "SELECT COUNT(*) FROM model {filter}"
    )))
    .bind(campaign_id)
    .bind(lineage_id)
    .fetch_one(db)
    .await?;
    let items = sqlx::query_as::<_, ModelSummary>(sqlx::AssertSqlSafe(format!(
        "SELECT {SUMMARY} FROM model {filter} ORDER BY created_at DESC, version DESC LIMIT $3 OFFSET $4"
    )))
    .bind(campaign_id)
    .bind(lineage_id)
    .bind(page.sql_limit())
    .bind(page.offset)
    .fetch_all(db)
    .await?;
    Ok((items, total))
}

/// Renames a model and/or sets its notes (`Some(None)` clears them), in one
/// transaction. False when there is no such model.
pub async fn update(
    db: &Db,
    id: &str,
    name: Option<&str>,
    notes: Option<Option<&str>>,
) -> anyhow::Result<bool> {
    let mut tx = db.begin().await?;
    let found = sqlx::query(
        "UPDATE model SET name = COALESCE($1, name), \
         notes = CASE WHEN $2 THEN $3 ELSE notes END WHERE id = $4",
    )
    .bind(name)
    .bind(notes.is_some())
    .bind(notes.flatten())
    .bind(id)
    .execute(&mut *tx)
    .await?
    .rows_affected()
        > 0;
    tx.commit().await?;
    Ok(found)
}

/// What deleting a model did.
#[derive(Debug)]
pub enum Deleted {
    /// No such model (or it is deleted already).
    NotFound,
    /// Live versions derived from it (without `cascade`), or jobs waiting on
    /// it, as phrases naming them; nothing changed.
    InUse(Vec<String>),
    /// The ids deleted: the model, then (with `cascade`) what was derived from it.
    Gone(Vec<String>),
}

/// Soft-deletes a model version, in one transaction: it keeps its row (so
/// the provenance of what was derived from it stays readable) and its
/// discovery reports, with who deleted it, when and why. A version a live
/// one was derived from (`parent_id`) is refused unless `cascade`, which
/// deletes the derived versions too; so is a model a queued or running job
/// works on.
pub async fn delete(
    db: &Db,
    id: &str,
    cascade: bool,
    by: &str,
    reason: Option<&str>,
) -> anyhow::Result<Deleted> {
    let mut tx = db.begin().await?;
    if !lock_row(&mut tx, "model", id).await?
        || super::trash::is_deleted(&mut tx, "model", id).await?
    {
        return Ok(Deleted::NotFound);
    }
    // The model and everything live derived from it, parents before children.
    let mut ids = vec![id.to_string()];
    let mut i = 0;
    while i < ids.len() {
        let children: Vec<(String, String, i64)> = sqlx::query_as(
            "SELECT id, name, version FROM model WHERE parent_id = $1 AND deleted_at IS NULL \
             ORDER BY version",
        )
        .bind(&ids[i])
        .fetch_all(&mut *tx)
        .await?;
        if !cascade && !children.is_empty() {
            return Ok(Deleted::InUse(
                children
                    .into_iter()
                    .map(|(id, name, v)| format!("model '{name}' v{v} ({id}) was derived from it"))
                    .collect(),
            ));
        }
        ids.extend(children.into_iter().map(|c| c.0));
        i += 1;
    }
    let mut busy = Vec::new();
    for m in &ids {
        let jobs: Vec<(String, String)> = sqlx::query_as(
            "SELECT id, kind FROM job WHERE state IN ('queued', 'running') AND request LIKE $1",
        )
        .bind(format!("%\"model_id\":\"{m}\"%"))
        .fetch_all(&mut *tx)
        .await?;
        if jobs.is_empty() {
            continue;
        }
        let (name, v): (String, i64) =
            sqlx::query_as("SELECT name, version FROM model WHERE id = $1")
                .bind(m)
                .fetch_one(&mut *tx)
                .await?;
        busy.extend(
            jobs.into_iter()
                .map(|(j, kind)| format!("{kind} job {j} works on model '{name}' v{v} ({m})")),
        );
    }
    if !busy.is_empty() {
        return Ok(Deleted::InUse(busy));
    }
    let at = now();
    for m in &ids {
        sqlx::query(
            "UPDATE model SET deleted_at = $1, deleted_by = $2, delete_reason = $3 WHERE id = $4",
        )
        .bind(&at)
        .bind(by)
        .bind(reason)
        .bind(m)
        .execute(&mut *tx)
        .await?;
    }
    tx.commit().await?;
    Ok(Deleted::Gone(ids))
}

/// Undoes the soft delete of one model version, in one transaction
/// (refused while its campaign or vessel is deleted).
pub async fn restore(db: &Db, id: &str) -> anyhow::Result<Restored> {
    super::trash::restore(db, "model", id).await
}
