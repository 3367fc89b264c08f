//! Missing-physics discovery reports: one row per `discover` job, linked to
//! the model examined and the augmented model stored as its next version.

use serde::Serialize;
use sqlx::SqliteConnection;

use super::{Db, new_id, now};

/// A stored report without its (large) body.
#[derive(Debug, Clone, Serialize, utoipa::ToSchema)]
pub struct DiscrepancySummary {
    /// Id (UUIDv7).
    pub id: String,
    /// The model examined.
    pub model_id: String,
    /// The augmented model stored as the next version (none when nothing
    /// was named).
    pub augmented_model_id: Option<String>,
    /// Campaign.
    pub campaign_id: String,
    /// The producing job.
    pub job_id: Option<String>,
    /// The story in sentences.
    pub summary: Vec<String>,
    /// Software version.
    pub software_version: String,
    /// Creation time (RFC 3339).
    pub created_at: String,
}

/// A stored report with everything.
#[derive(Debug, Clone)]
pub struct StoredDiscrepancy {
    /// Metadata.
    pub summary: DiscrepancySummary,
    /// Settings as used.
    pub settings: serde_json::Value,
    /// Runs the augmentation was fitted on.
    pub run_ids: Vec<String>,
    /// Runs held out.
    pub validation_run_ids: Vec<String>,
    /// The report (JSON of the core's `DiscrepancyReport`).
    pub report: serde_json::Value,
}

/// A report to store.
#[derive(Debug, Clone)]
pub struct NewDiscrepancy {
    /// The model examined.
    pub model_id: String,
    /// The augmented model, when stored.
    pub augmented_model_id: Option<String>,
    /// Campaign.
    pub campaign_id: String,
    /// The job.
    pub job_id: Option<String>,
    /// Settings as used.
    pub settings: serde_json::Value,
    /// Estimation runs.
    pub run_ids: Vec<String>,
    /// Held-out runs.
    pub validation_run_ids: Vec<String>,
    /// Sentences.
    pub summary: Vec<String>,
    /// The report.
    pub report: serde_json::Value,
}

#[derive(sqlx::FromRow)]
struct Row {
    id: String,
    model_id: String,
    augmented_model_id: Option<String>,
    campaign_id: String,
    job_id: Option<String>,
    summary: String,
    software_version: String,
    created_at: String,
}

impl Row {
    fn into_summary(self) -> anyhow::Result<DiscrepancySummary> {
        Ok(DiscrepancySummary {
            summary: serde_json::from_str(&self.summary)?,
            id: self.id,
            model_id: self.model_id,
            augmented_model_id: self.augmented_model_id,
            campaign_id: self.campaign_id,
            job_id: self.job_id,
            software_version: self.software_version,
            created_at: self.created_at,
        })
    }
}

const SUMMARY: &str =
    "id, model_id, augmented_model_id, campaign_id, job_id, summary, software_version, created_at";

/// Stores a report inside the caller's transaction (with the job's success).
pub async fn insert(tx: &mut SqliteConnection, d: NewDiscrepancy) -> anyhow::Result<String> {
    let id = new_id();
    sqlx::query(
        "INSERT INTO discrepancy (id, model_id, augmented_model_id, campaign_id, job_id, \
         settings, run_ids, validation_run_ids, summary, report, software_version, created_at) \
         VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11, $12)",
    )
    .bind(&id)
    .bind(&d.model_id)
    .bind(&d.augmented_model_id)
    .bind(&d.campaign_id)
    .bind(&d.job_id)
    .bind(d.settings.to_string())
    .bind(serde_json::to_string(&d.run_ids)?)
    .bind(serde_json::to_string(&d.validation_run_ids)?)
    .bind(serde_json::to_string(&d.summary)?)
    .bind(d.report.to_string())
    .bind(env!("CARGO_PKG_VERSION"))
    .bind(now())
    .execute(&mut *tx)
    .await?;
    Ok(id)
}

/// Reports on `model_id`, newest first.
pub async fn list_for_model(db: &Db, model_id: &str) -> anyhow::Result<Vec<DiscrepancySummary>> {
    sqlx::query_as::<_, Row>(sqlx::AssertSqlSafe(format!(
        "SELECT {SUMMARY} FROM discrepancy WHERE model_id = $1 ORDER BY created_at DESC, id DESC"
    )))
    .bind(model_id)
    .fetch_all(db)
    .await?
    .into_iter()
    .map(Row::into_summary)
    .collect()
}

#[derive(sqlx::FromRow)]
struct Heavy {
    settings: String,
    run_ids: String,
    validation_run_ids: String,
    report: String,
}

/// One report with everything.
pub async fn get(db: &Db, id: &str) -> anyhow::Result<Option<StoredDiscrepancy>> {
    let Some(row) = sqlx::query_as::<_, Row>(sqlx::AssertSqlSafe(format!(
        "SELECT {SUMMARY} FROM discrepancy WHERE id = $1"
    )))
    .bind(id)
    .fetch_optional(db)
    .await?
    else {
        return Ok(None);
    };
    let h = sqlx::query_as::<_, Heavy>(
        "SELECT settings, run_ids, validation_run_ids, report FROM discrepancy WHERE id = $1",
    )
    .bind(id)
    .fetch_one(db)
    .await?;
    Ok(Some(StoredDiscrepancy {
        summary: row.into_summary()?,
        settings: serde_json::from_str(&h.settings)?,
        run_ids: serde_json::from_str(&h.run_ids)?,
        validation_run_ids: serde_json::from_str(&h.validation_run_ids)?,
        report: serde_json::from_str(&h.report)?,
    }))
}
