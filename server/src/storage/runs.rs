//! Runs: uploaded logs of one experiment (one file, or control + nav), their
//! processing outcome and quality report.

use serde::Serialize;

use super::blobs::StoredBlob;
use super::{Db, new_id, now};

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
}

const COLUMNS: &str =
    "id, campaign_id, experiment_id, name, layout, status, error, summary, created_at";

async fn with_files(db: &Db, r: Row) -> anyhow::Result<Run> {
    let files = sqlx::query_as::<_, RunFile>(
        "SELECT role, filename, sha256, size_bytes FROM run_file WHERE run_id = $1 ORDER BY role",
    )
    .bind(&r.id)
    .fetch_all(db)
    .await?;
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

/// Records a run whose files are already stored, in one transaction.
pub async fn insert(
    db: &Db,
    campaign_id: &str,
    experiment_id: Option<&str>,
    name: &str,
    layout: &str,
    files: &[NewFile],
) -> anyhow::Result<Run> {
    let id = new_id();
    let created_at = now();
    let mut tx = db.begin().await?;
    sqlx::query(
        "INSERT INTO run (id, campaign_id, experiment_id, name, layout, status, created_at) \
         VALUES ($1, $2, $3, $4, $5, 'stored', $6)",
    )
    .bind(&id)
    .bind(campaign_id)
    .bind(experiment_id)
    .bind(name)
    .bind(layout)
    .bind(&created_at)
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

/// Records the outcome of processing, with the quality report when accepted.
pub async fn finish(
    db: &Db,
    id: &str,
    status: &str,
    error: Option<&serde_json::Value>,
    summary: Option<&serde_json::Value>,
    quality_json: Option<&str>,
) -> anyhow::Result<()> {
    let mut tx = db.begin().await?;
    sqlx::query("UPDATE run SET status = $1, error = $2, summary = $3 WHERE id = $4")
        .bind(status)
        .bind(error.map(|e| e.to_string()))
        .bind(summary.map(|s| s.to_string()))
        .bind(id)
        .execute(&mut *tx)
        .await?;
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

/// One run.
pub async fn get(db: &Db, id: &str) -> anyhow::Result<Option<Run>> {
    let row = sqlx::query_as::<_, Row>(sqlx::AssertSqlSafe(format!(
        "SELECT {COLUMNS} FROM run WHERE id = $1"
    )))
    .bind(id)
    .fetch_optional(db)
    .await?;
    match row {
        Some(r) => Ok(Some(with_files(db, r).await?)),
        None => Ok(None),
    }
}

/// The runs of a campaign, oldest first.
pub async fn list(db: &Db, campaign_id: &str) -> anyhow::Result<Vec<Run>> {
    let rows = sqlx::query_as::<_, Row>(sqlx::AssertSqlSafe(format!(
        "SELECT {COLUMNS} FROM run WHERE campaign_id = $1 ORDER BY id"
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

/// The stored quality report of a run (JSON text), if any.
pub async fn quality(db: &Db, id: &str) -> anyhow::Result<Option<String>> {
    Ok(
        sqlx::query_scalar("SELECT report FROM run_quality WHERE run_id = $1")
            .bind(id)
            .fetch_optional(db)
            .await?,
    )
}
