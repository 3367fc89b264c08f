//! Runs: uploaded logs of one experiment (one file, or control + nav), their
//! processing outcome and quality report, and what they are (the
//! supervisor's description, the matched plan's experiment, the inference).

use seatrial_core::identification::{
    InferredDescription, PlanDescription, RunDescription, RunRole, RunSignal, UserDescription,
    describe_run,
};
use seatrial_core::planning::{Dof, Experiment};
use serde::Serialize;

use super::blobs::StoredBlob;
use sqlx::SqliteConnection;

use super::{Db, Page, Restored, lock_row, new_id, now};

/// One uploaded file of a run.
#[derive(Debug, Clone, Serialize, sqlx::FromRow, utoipa::ToSchema)]
pub struct RunFile {
    /// `file` (single-file run), `control` or `nav`.
    pub role: String,
    /// File name as uploaded.
    pub filename: String,
    /// SHA-256 of the bytes (hex).
    pub sha256: String,
    /// Size in bytes.
    pub size_bytes: i64,
}

/// A run.
#[derive(Debug, Clone, Serialize, utoipa::ToSchema)]
pub struct Run {
    /// Id (UUIDv7).
    pub id: String,
    /// Campaign.
    pub campaign_id: String,
    /// The planned experiment it belongs to, if any.
    pub experiment_id: Option<String>,
    /// Name.
    pub name: String,
    /// `single` or `split` (control + nav from unsynchronized computers).
    pub layout: String,
    /// `stored` (bytes safe, not processed yet), `accepted` or `rejected`.
    pub status: String,
    /// Why the run was rejected: message, file, line, column.
    #[schema(value_type = Option<crate::processing::ProcessError>)]
    pub error: Option<serde_json::Value>,
    /// Processing summary: rows, rates, gaps, warnings, alignment, verdicts.
    #[schema(value_type = Option<crate::processing::RunSummary>)]
    pub summary: Option<serde_json::Value>,
    /// Upload time (RFC 3339).
    pub created_at: String,
    /// The stored files.
    pub files: Vec<RunFile>,
    /// What the run is — role, grid speed, excited DOFs, signal, notes —
    /// each with its source: the supervisor (`user`, wins), the matched
    /// planned experiment (`plan`), or the data (`inferred`, with the reason).
    pub description: RunDescription,
    /// Left out of identification unless a job names it in `run_ids`.
    pub excluded: bool,
    /// Why it is excluded.
    pub excluded_reason: Option<String>,
    /// When it was excluded (RFC 3339).
    pub excluded_at: Option<String>,
    /// When it was deleted (RFC 3339; `null`: not deleted). A deleted run
    /// stays readable by id (the provenance of models built from it) but
    /// leaves the lists and identification; `POST /api/runs/{id}/restore`
    /// undoes the delete.
    pub deleted_at: Option<String>,
    /// Who deleted it (user name).
    pub deleted_by: Option<String>,
    /// Why it was deleted.
    pub delete_reason: Option<String>,
}

#[derive(sqlx::FromRow)]
struct Row {
    id: String,
    campaign_id: String,
    experiment_id: Option<String>,
    name: String,
    layout: String,
    status: String,
    error: Option<String>,
    summary: Option<String>,
    created_at: String,
    role: Option<String>,
    grid_speed_mps: Option<f64>,
    excited_dofs: Option<String>,
    signal: Option<String>,
    notes: Option<String>,
    inferred: Option<String>,
    plan_detail: Option<String>,
    excluded: bool,
    excluded_reason: Option<String>,
    excluded_at: Option<String>,
    deleted_at: Option<String>,
    deleted_by: Option<String>,
    delete_reason: Option<String>,
}

/// The run's columns, and its planned experiment's description (if any).
const FROM: &str = "SELECT r.id, r.campaign_id, r.experiment_id, r.name, r.layout, r.status, r.error, \
     r.summary, r.created_at, r.role, r.grid_speed_mps, r.excited_dofs, r.signal, r.notes, \
     r.inferred, e.detail AS plan_detail, r.excluded, r.excluded_reason, r.excluded_at, \
     r.deleted_at, r.deleted_by, r.delete_reason FROM run r LEFT JOIN experiment e ON e.id = r.experiment_id";

impl Row {
    fn user(&self) -> anyhow::Result<UserDescription> {
        Ok(UserDescription {
            role: self.role.as_deref().and_then(RunRole::from_name),
            grid_speed_mps: self.grid_speed_mps,
            excited_dofs: self
                .excited_dofs
                .as_deref()
                .map(serde_json::from_str::<Vec<Dof>>)
                .transpose()?,
            signal: self.signal.as_deref().and_then(RunSignal::from_name),
            notes: self.notes.clone(),
        })
    }

    fn description(&self) -> anyhow::Result<RunDescription> {
        let plan = self
            .plan_detail
            .as_deref()
            .map(serde_json::from_str::<Experiment>)
            .transpose()?
            .map(|e| PlanDescription::of_experiment(&e));
        let inferred = self
            .inferred
            .as_deref()
            .map(serde_json::from_str::<InferredDescription>)
            .transpose()?;
        Ok(describe_run(
            &self.user()?,
            plan.as_ref(),
            inferred.as_ref(),
        ))
    }
}

async fn with_files(db: &Db, r: Row) -> anyhow::Result<Run> {
    let files = sqlx::query_as::<_, RunFile>(
        "SELECT role, filename, sha256, size_bytes FROM run_file WHERE run_id = $1 ORDER BY role",
    )
    .bind(&r.id)
    .fetch_all(db)
    .await?;
    let description = r.description()?;
    Ok(Run {
        id: r.id,
        campaign_id: r.campaign_id,
        experiment_id: r.experiment_id,
        name: r.name,
        layout: r.layout,
        status: r.status,
        error: r.error.map(|e| serde_json::from_str(&e)).transpose()?,
        summary: r.summary.map(|e| serde_json::from_str(&e)).transpose()?,
        created_at: r.created_at,
        files,
        description,
        excluded: r.excluded,
        excluded_reason: r.excluded_reason,
        excluded_at: r.excluded_at,
        deleted_at: r.deleted_at,
        deleted_by: r.deleted_by,
        delete_reason: r.delete_reason,
    })
}

/// A file to attach to a new run.
pub struct NewFile {
    /// Role.
    pub role: String,
    /// Name as uploaded.
    pub filename: String,
    /// The stored bytes.
    pub blob: StoredBlob,
}

/// The supervisor's description as column values.
fn user_columns(
    u: &UserDescription,
) -> anyhow::Result<(Option<&'static str>, Option<String>, Option<&'static str>)> {
    Ok((
        u.role.map(RunRole::name),
        u.excited_dofs
            .as_ref()
            .map(serde_json::to_string)
            .transpose()?,
        u.signal.map(RunSignal::name),
    ))
}

/// Records a run whose files are already stored, with what the supervisor
/// said it is and the `meta` it was uploaded with (JSON, for processing),
/// in one transaction.
#[allow(clippy::too_many_arguments)]
pub async fn insert(
    db: &Db,
    campaign_id: &str,
    experiment_id: Option<&str>,
    name: &str,
    layout: &str,
    files: &[NewFile],
    user: &UserDescription,
    upload_meta: &serde_json::Value,
) -> anyhow::Result<Run> {
    let id = new_id();
    let created_at = now();
    let (role, dofs, signal) = user_columns(user)?;
    let mut tx = db.begin().await?;
    sqlx::query(
        "INSERT INTO run (id, campaign_id, experiment_id, name, layout, status, created_at, \
         role, grid_speed_mps, excited_dofs, signal, notes, upload_meta) \
         VALUES ($1, $2, $3, $4, $5, 'stored', $6, $7, $8, $9, $10, $11, $12)",
    )
    .bind(&id)
    .bind(campaign_id)
    .bind(experiment_id)
    .bind(name)
    .bind(layout)
    .bind(&created_at)
    .bind(role)
    .bind(user.grid_speed_mps)
    .bind(dofs)
    .bind(signal)
    .bind(&user.notes)
    .bind(upload_meta.to_string())
    .execute(&mut *tx)
    .await?;
    for f in files {
        sqlx::query(
            "INSERT INTO blob (sha256, size_bytes, created_at) VALUES ($1, $2, $3) ON CONFLICT (sha256) DO NOTHING",
        )
        .bind(&f.blob.sha256)
        .bind(i64::try_from(f.blob.size)?)
        .bind(&created_at)
        .execute(&mut *tx)
        .await?;
        sqlx::query("INSERT INTO run_file (run_id, role, filename, sha256, size_bytes) VALUES ($1, $2, $3, $4, $5)")
            .bind(&id)
            .bind(&f.role)
            .bind(&f.filename)
            .bind(&f.blob.sha256)
            .bind(i64::try_from(f.blob.size)?)
            .execute(&mut *tx)
            .await?;
    }
    tx.commit().await?;
    get(db, &id)
        .await?
        .ok_or_else(|| anyhow::anyhow!("run {id} vanished after insert"))
}

/// What processing found, to record with [`finish`].
#[derive(Default)]
pub struct Outcome<'a> {
    /// Why it was rejected.
    pub error: Option<&'a serde_json::Value>,
    /// The processing summary.
    pub summary: Option<&'a serde_json::Value>,
    /// The quality report (JSON text).
    pub quality_json: Option<&'a str>,
    /// What the data say the run is.
    pub inferred: Option<&'a InferredDescription>,
}

/// Records the outcome of processing, with the quality report and the
/// inferred description when accepted, in one transaction.
pub async fn finish(db: &Db, id: &str, status: &str, out: Outcome<'_>) -> anyhow::Result<()> {
    let mut tx = db.begin().await?;
    sqlx::query(
        "UPDATE run SET status = $1, error = $2, summary = $3, inferred = $4 WHERE id = $5",
    )
    .bind(status)
    .bind(out.error.map(|e| e.to_string()))
    .bind(out.summary.map(|s| s.to_string()))
    .bind(out.inferred.map(serde_json::to_string).transpose()?)
    .bind(id)
    .execute(&mut *tx)
    .await?;
    let quality_json = out.quality_json;
    if let Some(q) = quality_json {
        sqlx::query("DELETE FROM run_quality WHERE run_id = $1")
            .bind(id)
            .execute(&mut *tx)
            .await?;
        sqlx::query("INSERT INTO run_quality (run_id, report, created_at) VALUES ($1, $2, $3)")
            .bind(id)
            .bind(q)
            .bind(now())
            .execute(&mut *tx)
            .await?;
    }
    tx.commit().await?;
    Ok(())
}

/// A field of the supervisor's description (a column of `run`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DescriptionField {
    /// `role`.
    Role,
    /// `grid_speed_mps`.
    GridSpeed,
    /// `excited_dofs`.
    ExcitedDofs,
    /// `signal`.
    Signal,
    /// `notes`.
    Notes,
}

impl DescriptionField {
    fn column(self) -> &'static str {
        match self {
            DescriptionField::Role => "role",
            DescriptionField::GridSpeed => "grid_speed_mps",
            DescriptionField::ExcitedDofs => "excited_dofs",
            DescriptionField::Signal => "signal",
            DescriptionField::Notes => "notes",
        }
    }
}

/// Writes the `fields` of what the supervisor said about a run from `user`,
/// in the caller's transaction (one statement).
async fn set_description(
    conn: &mut SqliteConnection,
    id: &str,
    user: &UserDescription,
    fields: &[DescriptionField],
) -> anyhow::Result<()> {
    if fields.is_empty() {
        return Ok(());
    }
    let (role, dofs, signal) = user_columns(user)?;
    let sets: Vec<String> = fields
        .iter()
        .enumerate()
        .map(|(i, f)| format!("{} = ${}", f.column(), i + 1))
        .collect();
    let sql = format!(
        "UPDATE run SET {} WHERE id = ${}",
        sets.join(", "),
        fields.len() + 1
    );
    let mut q = sqlx::query(sqlx::AssertSqlSafe(sql));
    for f in fields {
        q = match f {
            DescriptionField::Role => q.bind(role),
            DescriptionField::GridSpeed => q.bind(user.grid_speed_mps),
            DescriptionField::ExcitedDofs => q.bind(dofs.clone()),
            DescriptionField::Signal => q.bind(signal),
            DescriptionField::Notes => q.bind(user.notes.clone()),
        };
    }
    q.bind(id).execute(&mut *conn).await?;
    Ok(())
}

/// One run.
pub async fn get(db: &Db, id: &str) -> anyhow::Result<Option<Run>> {
    let row = sqlx::query_as::<_, Row>(sqlx::AssertSqlSafe(format!("{FROM} WHERE r.id = $1")))
        .bind(id)
        .fetch_optional(db)
        .await?;
    match row {
        Some(r) => Ok(Some(with_files(db, r).await?)),
        None => Ok(None),
    }
}

/// The runs of a campaign that are not deleted, oldest first.
pub async fn list(db: &Db, campaign_id: &str) -> anyhow::Result<Vec<Run>> {
    let rows = sqlx::query_as::<_, Row>(sqlx::AssertSqlSafe(format!(
        "{FROM} WHERE r.campaign_id = $1 AND r.deleted_at IS NULL ORDER BY r.id"
    )))
    .bind(campaign_id)
    .fetch_all(db)
    .await?;
    let mut out = Vec::with_capacity(rows.len());
    for r in rows {
        out.push(with_files(db, r).await?);
    }
    Ok(out)
}

/// The `meta` a run was uploaded with (JSON text), if recorded.
pub async fn upload_meta(db: &Db, id: &str) -> anyhow::Result<Option<String>> {
    let m: Option<Option<String>> = sqlx::query_scalar("SELECT upload_meta FROM run WHERE id = $1")
        .bind(id)
        .fetch_optional(db)
        .await?;
    Ok(m.flatten())
}

/// Runs still `stored` (never processed), oldest first.
pub async fn stored_ids(db: &Db) -> anyhow::Result<Vec<String>> {
    Ok(
        sqlx::query_scalar("SELECT id FROM run WHERE status = 'stored' ORDER BY created_at, id")
            .fetch_all(db)
            .await?,
    )
}

/// The stored quality report of a run (JSON text), if any.
pub async fn quality(db: &Db, id: &str) -> anyhow::Result<Option<String>> {
    Ok(
        sqlx::query_scalar("SELECT report FROM run_quality WHERE run_id = $1")
            .bind(id)
            .fetch_optional(db)
            .await?,
    )
}

/// A page of a campaign's runs, oldest first, optionally of one status, the
/// live ones or (`deleted`) the deleted ones, and the number of runs that match.
pub async fn page(
    db: &Db,
    campaign_id: &str,
    status: Option<&str>,
    deleted: bool,
    page: Page,
) -> anyhow::Result<(Vec<Run>, i64)> {
    let gone = if deleted { "NOT NULL" } else { "NULL" };
    let (total,): (i64,) = sqlx::query_as(sqlx::AssertSqlSafe(format!(
        "SELECT COUNT(*) FROM run WHERE campaign_id = $1 AND ($2 IS NULL OR status = $2) \
         AND deleted_at IS {gone}"
    )))
    .bind(campaign_id)
    .bind(status)
    .fetch_one(db)
    .await?;
    let rows = sqlx::query_as::<_, Row>(sqlx::AssertSqlSafe(format!(
        "{FROM} WHERE r.campaign_id = $1 AND ($2 IS NULL OR r.status = $2) \
         AND r.deleted_at IS {gone} ORDER BY r.id LIMIT $3 OFFSET $4"
    )))
    .bind(campaign_id)
    .bind(status)
    .bind(page.sql_limit())
    .bind(page.offset)
    .fetch_all(db)
    .await?;
    let mut out = Vec::with_capacity(rows.len());
    for r in rows {
        out.push(with_files(db, r).await?);
    }
    Ok((out, total))
}

/// A change to a run's name or exclusion, beside its description.
#[derive(Debug, Default, Clone)]
pub struct RunUpdate {
    /// New name.
    pub name: Option<String>,
    /// `Some(Some(reason))`: exclude from identification; `Some(None)`: include again.
    pub exclusion: Option<Option<String>>,
}

/// Writes the `fields` of what the supervisor said about a run from `user`
/// and the name and exclusion of `update`, in one transaction (fields not
/// named keep their value, so two edits of different fields never undo each
/// other). False when there is no such run.
pub async fn update(
    db: &Db,
    id: &str,
    user: &UserDescription,
    fields: &[DescriptionField],
    update: &RunUpdate,
) -> anyhow::Result<bool> {
    let mut tx = db.begin().await?;
    if !lock_row(&mut tx, "run", id).await? {
        return Ok(false);
    }
    if let Some(name) = &update.name {
        sqlx::query("UPDATE run SET name = $1 WHERE id = $2")
            .bind(name)
            .bind(id)
            .execute(&mut *tx)
            .await?;
    }
    if let Some(exclusion) = &update.exclusion {
        sqlx::query(
            "UPDATE run SET excluded = $1, excluded_reason = $2, \
             excluded_at = CASE WHEN $1 THEN COALESCE(CASE WHEN excluded THEN excluded_at END, $3) END \
             WHERE id = $4",
        )
        .bind(exclusion.is_some())
        .bind(exclusion)
        .bind(now())
        .bind(id)
        .execute(&mut *tx)
        .await?;
    }
    set_description(&mut tx, id, user, fields).await?;
    tx.commit().await?;
    Ok(true)
}

/// What is built from a run: the models (estimation or validation; only
/// the live ones unless `deleted_too`) and the discovery reports that used
/// it, as `kind 'name' v<version> (id)` phrases.
pub async fn users(
    conn: &mut SqliteConnection,
    id: &str,
    deleted_too: bool,
) -> anyhow::Result<Vec<String>> {
    // Ids are UUIDs: a quoted id matches exactly one element of a JSON list.
    let quoted = format!("%\"{id}\"%");
    let models: Vec<(String, String, i64)> = sqlx::query_as(
        "SELECT id, name, version FROM model WHERE (run_ids LIKE $1 OR validation_run_ids LIKE $1) \
         AND ($2 OR deleted_at IS NULL) ORDER BY created_at",
    )
    .bind(&quoted)
    .bind(deleted_too)
    .fetch_all(&mut *conn)
    .await?;
    let reports: Vec<(String,)> = sqlx::query_as(
        "SELECT id FROM discrepancy WHERE run_ids LIKE $1 OR validation_run_ids LIKE $1 \
         ORDER BY created_at",
    )
    .bind(&quoted)
    .fetch_all(&mut *conn)
    .await?;
    Ok(models
        .into_iter()
        .map(|(id, name, v)| format!("model '{name}' v{v} ({id})"))
        .chain(
            reports
                .into_iter()
                .map(|(id,)| format!("discovery report {id}")),
        )
        .collect())
}

/// What deleting a run did.
#[derive(Debug)]
pub enum Deleted {
    /// No such run (or it is deleted already).
    NotFound,
    /// Deleted; the models and reports built from it (phrases naming them)
    /// keep their provenance.
    Gone(Vec<String>),
}

/// Soft-deletes a run, in one transaction: it keeps its row, files and
/// quality report (so every model built from it keeps a readable
/// provenance), with who deleted it, when and why.
pub async fn delete(db: &Db, id: &str, by: &str, reason: Option<&str>) -> anyhow::Result<Deleted> {
    let mut tx = db.begin().await?;
    if !lock_row(&mut tx, "run", id).await? || super::trash::is_deleted(&mut tx, "run", id).await? {
        return Ok(Deleted::NotFound);
    }
    let users = users(&mut tx, id, false).await?;
    super::trash::mark(&mut tx, "run", id, by, reason).await?;
    tx.commit().await?;
    Ok(Deleted::Gone(users))
}

/// Undoes the soft delete of a run, in one transaction (refused while its
/// campaign or vessel is deleted).
pub async fn restore(db: &Db, id: &str) -> anyhow::Result<Restored> {
    super::trash::restore(db, "run", id).await
}
