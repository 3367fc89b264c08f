//! Plans and their experiments; schedules stored as little-endian f64
//! blobs, column after column.

use seatrial_core::planning::{Experiment, Plan, PlanTotals, Schedule};
use serde::Serialize;

use super::{Db, new_id, now};

/// A stored plan without its experiments' samples.
#[derive(Debug, Clone, Serialize, utoipa::ToSchema)]
pub struct StoredPlan {
    /// Id (UUIDv7).
    pub id: String,
    /// Campaign.
    pub campaign_id: String,
    /// Generation number, from 1; the newest is the campaign's plan.
    pub version: i64,
    /// Creation time (RFC 3339).
    pub created_at: String,
    /// Totals: count, run time, set-up time, total trial time.
    pub totals: PlanTotals,
    /// Experiments in run order.
    pub experiments: Vec<StoredExperiment>,
}

/// A stored experiment (description and checks; samples separately).
#[derive(Debug, Clone, Serialize, utoipa::ToSchema)]
pub struct StoredExperiment {
    /// Id (UUIDv7): the `{eid}` of the schedule routes.
    pub id: String,
    /// Description, channels, analysis, warnings.
    #[serde(flatten)]
    pub experiment: Experiment,
}

#[derive(sqlx::FromRow)]
struct PlanRow {
    id: String,
    campaign_id: String,
    version: i64,
    totals: String,
    created_at: String,
}

#[derive(sqlx::FromRow)]
struct ExperimentRow {
    id: String,
    detail: String,
}

#[derive(sqlx::FromRow)]
struct ScheduleRow {
    sample_rate_hz: f64,
    n_samples: i64,
    columns: String,
    samples: Vec<u8>,
}

fn encode(s: &Schedule) -> Vec<u8> {
    let mut out = Vec::with_capacity(s.values.len() * s.len() * 8);
    for col in &s.values {
        for v in col {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    out
}

fn decode(r: ScheduleRow) -> anyhow::Result<Schedule> {
    let columns: Vec<String> = serde_json::from_str(&r.columns)?;
    let n = usize::try_from(r.n_samples)?;
    anyhow::ensure!(
        r.samples.len() == columns.len() * n * 8,
        "schedule blob has the wrong size"
    );
    let values = r
        .samples
        .chunks_exact(n.max(1) * 8)
        .take(columns.len())
        .map(|c| {
            c.chunks_exact(8)
                .map(|b| f64::from_le_bytes(b.try_into().unwrap_or([0; 8])))
                .collect()
        })
        .collect();
    Ok(Schedule {
        sample_rate_hz: r.sample_rate_hz,
        columns,
        values,
    })
}

/// Stores a new plan version with all its experiments in one transaction.
pub async fn insert(db: &Db, campaign_id: &str, plan: &Plan) -> anyhow::Result<StoredPlan> {
    let mut tx = db.begin().await?;
    let version: i64 =
        sqlx::query_scalar("SELECT COALESCE(MAX(version), 0) + 1 FROM plan WHERE campaign_id = $1")
            .bind(campaign_id)
            .fetch_one(&mut *tx)
            .await?;
    let stored = StoredPlan {
        id: new_id(),
        campaign_id: campaign_id.to_string(),
        version,
        created_at: now(),
        totals: plan.totals.clone(),
        experiments: plan
            .experiments
            .iter()
            .map(|p| StoredExperiment {
                id: new_id(),
                experiment: p.experiment.clone(),
            })
            .collect(),
    };
    sqlx::query("INSERT INTO plan (id, campaign_id, version, totals, created_at) VALUES ($1, $2, $3, $4, $5)")
        .bind(&stored.id)
        .bind(campaign_id)
        .bind(version)
        .bind(serde_json::to_string(&stored.totals)?)
        .bind(&stored.created_at)
        .execute(&mut *tx)
        .await?;
    for (s, p) in stored.experiments.iter().zip(&plan.experiments) {
        let e = &s.experiment;
        sqlx::query(
            "INSERT INTO experiment (id, plan_id, seq, code, family, detail, sample_rate_hz, n_samples, columns, samples) \
             VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10)",
        )
        .bind(&s.id)
        .bind(&stored.id)
        .bind(i64::from(e.seq))
        .bind(&e.code)
        .bind(e.family.name())
        .bind(serde_json::to_string(e)?)
        .bind(p.schedule.sample_rate_hz)
        .bind(i64::try_from(p.schedule.len())?)
        .bind(serde_json::to_string(&p.schedule.columns)?)
        .bind(encode(&p.schedule))
        .execute(&mut *tx)
        .await?;
    }
    tx.commit().await?;
    Ok(stored)
}

/// The newest plan of a campaign.
pub async fn latest(db: &Db, campaign_id: &str) -> anyhow::Result<Option<StoredPlan>> {
    let Some(p) = sqlx::query_as::<_, PlanRow>(
        "SELECT id, campaign_id, version, totals, created_at FROM plan WHERE campaign_id = $1 ORDER BY version DESC LIMIT 1",
    )
    .bind(campaign_id)
    .fetch_optional(db)
    .await?
    else {
        return Ok(None);
    };
    let rows = sqlx::query_as::<_, ExperimentRow>(
        "SELECT id, detail FROM experiment WHERE plan_id = $1 ORDER BY seq",
    )
    .bind(&p.id)
    .fetch_all(db)
    .await?;
    let experiments = rows
        .into_iter()
        .map(|r| {
            Ok(StoredExperiment {
                id: r.id,
                experiment: serde_json::from_str(&r.detail)?,
            })
        })
        .collect::<anyhow::Result<_>>()?;
    Ok(Some(StoredPlan {
        id: p.id,
        campaign_id: p.campaign_id,
        version: p.version,
        created_at: p.created_at,
        totals: serde_json::from_str(&p.totals)?,
        experiments,
    }))
}

/// One experiment of a campaign's newest plan, with its schedule.
pub async fn experiment(
    db: &Db,
    campaign_id: &str,
    eid: &str,
) -> anyhow::Result<Option<(StoredExperiment, Schedule)>> {
    #[derive(sqlx::FromRow)]
    struct Row {
        id: String,
        detail: String,
        sample_rate_hz: f64,
        n_samples: i64,
        columns: String,
        samples: Vec<u8>,
    }
    let row = sqlx::query_as::<_, Row>(
        "SELECT e.id, e.detail, e.sample_rate_hz, e.n_samples, e.columns, e.samples \
         FROM experiment e JOIN plan p ON p.id = e.plan_id \
         WHERE e.id = $1 AND p.campaign_id = $2",
    )
    .bind(eid)
    .bind(campaign_id)
    .fetch_optional(db)
    .await?;
    let Some(r) = row else { return Ok(None) };
    let schedule = decode(ScheduleRow {
        sample_rate_hz: r.sample_rate_hz,
        n_samples: r.n_samples,
        columns: r.columns,
        samples: r.samples,
    })?;
    Ok(Some((
        StoredExperiment {
            id: r.id,
            experiment: serde_json::from_str(&r.detail)?,
        },
        schedule,
    )))
}
