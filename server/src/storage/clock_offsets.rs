//! Clock offsets of two-file runs set by hand, per run and per campaign
//! (seconds added to navigation stamps). `None`: not set by hand.

use std::collections::HashMap;

use super::{Db, now};

/// Where an offset set by hand is kept: the table and its key column.
#[derive(Clone, Copy)]
enum Scope {
    Run,
    Campaign,
}

impl Scope {
    fn table_key(self) -> (&'static str, &'static str) {
        match self {
            Scope::Run => ("run_clock_offset", "run_id"),
            Scope::Campaign => ("campaign_clock_offset", "campaign_id"),
        }
    }
}

async fn get(db: &Db, scope: Scope, id: &str) -> anyhow::Result<Option<f64>> {
    let (table, key) = scope.table_key();
    Ok(sqlx::query_scalar(sqlx::AssertSqlSafe(format!(
        "SELECT clock_offset_s FROM {table} WHERE {key} = $1"
    )))
    .bind(id)
    .fetch_optional(db)
    .await?)
}

async fn set(db: &Db, scope: Scope, id: &str, offset_s: Option<f64>) -> anyhow::Result<()> {
    let (table, key) = scope.table_key();
    let query = match offset_s {
        Some(_) => format!(
            "INSERT INTO {table} ({key}, clock_offset_s, updated_at) VALUES ($1, $2, $3) \
             ON CONFLICT ({key}) DO UPDATE SET clock_offset_s = excluded.clock_offset_s, updated_at = excluded.updated_at"
        ),
        None => format!("DELETE FROM {table} WHERE {key} = $1"),
    };
    let mut q = sqlx::query(sqlx::AssertSqlSafe(query)).bind(id);
    if let Some(v) = offset_s {
        q = q.bind(v).bind(now());
    }
    q.execute(db).await?;
    Ok(())
}

/// The offset set by hand for a run, if any.
pub async fn run_offset(db: &Db, run_id: &str) -> anyhow::Result<Option<f64>> {
    get(db, Scope::Run, run_id).await
}

/// Sets (or with `None` clears) a run's offset.
pub async fn set_run_offset(db: &Db, run_id: &str, offset_s: Option<f64>) -> anyhow::Result<()> {
    set(db, Scope::Run, run_id, offset_s).await
}

/// The offset set by hand for a campaign, if any.
pub async fn campaign_offset(db: &Db, campaign_id: &str) -> anyhow::Result<Option<f64>> {
    get(db, Scope::Campaign, campaign_id).await
}

/// Sets (or with `None` clears) a campaign's offset.
pub async fn set_campaign_offset(
    db: &Db,
    campaign_id: &str,
    offset_s: Option<f64>,
) -> anyhow::Result<()> {
    set(db, Scope::Campaign, campaign_id, offset_s).await
}

/// The offsets set by hand for the runs of a campaign, by run id.
pub async fn run_offsets(db: &Db, campaign_id: &str) -> anyhow::Result<HashMap<String, f64>> {
    let rows: Vec<(String, f64)> = sqlx::query_as(
        "SELECT o.run_id, o.clock_offset_s FROM run_clock_offset o \
         JOIN run r ON r.id = o.run_id WHERE r.campaign_id = $1",
    )
    .bind(campaign_id)
    .fetch_all(db)
    .await?;
    Ok(rows.into_iter().collect())
}
