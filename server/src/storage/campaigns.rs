//! Campaigns.

use seatrial_core::planning::CampaignSpec;
use serde::Serialize;

use super::trash::Deletion;
use super::{Db, lock_row, new_id, now};

/// A stored campaign.
#[derive(Debug, Clone, Serialize, utoipa::ToSchema)]
pub struct Campaign {
    /// Id (UUIDv7).
    pub id: String,
    /// The vessel it is planned for.
    pub vessel_id: String,
    /// Creation time (RFC 3339).
    pub created_at: String,
    /// The grid in m/s (SI), as stored for computation.
    pub grid_speeds_mps: Vec<f64>,
    /// The campaign as entered.
    pub spec: CampaignSpec,
    /// Version of the newest plan; none before the first is generated.
    pub plan_version: Option<i64>,
    /// Who deleted it, when and why (its runs and models stay readable by id).
    #[serde(flatten)]
    pub deletion: Deletion,
}

#[derive(sqlx::FromRow)]
struct Row {
    id: String,
    vessel_id: String,
    spec: String,
    created_at: String,
    plan_version: Option<i64>,
    #[sqlx(flatten)]
    deletion: Deletion,
}

impl TryFrom<Row> for Campaign {
    type Error = anyhow::Error;
    fn try_from(r: Row) -> anyhow::Result<Self> {
        let spec: CampaignSpec = serde_json::from_str(&r.spec)?;
        Ok(Campaign {
            id: r.id,
            vessel_id: r.vessel_id,
            created_at: r.created_at,
            grid_speeds_mps: spec.grid.speeds_si(),
            spec,
            plan_version: r.plan_version,
            deletion: r.deletion,
        })
    }
}

const SELECT: &str = "SELECT id, vessel_id, spec, created_at, deleted_at, deleted_by, delete_reason, \
    (SELECT MAX(p.version) FROM plan p WHERE p.campaign_id = campaign.id) AS plan_version FROM campaign";

/// Campaigns the lists show: not deleted, on a vessel that is not deleted.
pub(crate) const LIVE: &str = "campaign.deleted_at IS NULL AND \
    (SELECT v.deleted_at FROM vessel v WHERE v.id = campaign.vessel_id) IS NULL";

/// Inserts a validated campaign.
pub async fn insert(db: &Db, vessel_id: &str, spec: CampaignSpec) -> anyhow::Result<Campaign> {
    let c = Campaign {
        id: new_id(),
        vessel_id: vessel_id.to_string(),
        created_at: now(),
        grid_speeds_mps: spec.grid.speeds_si(),
        spec,
        plan_version: None,
        deletion: Deletion::default(),
    };
    sqlx::query(
        "INSERT INTO campaign (id, vessel_id, name, spec, created_at) VALUES ($1, $2, $3, $4, $5)",
    )
    .bind(&c.id)
    .bind(&c.vessel_id)
    .bind(&c.spec.name)
    .bind(serde_json::to_string(&c.spec)?)
    .bind(&c.created_at)
    .execute(db)
    .await?;
    Ok(c)
}

/// Campaigns, oldest first, optionally of one vessel: the live ones (not
/// deleted, on a live vessel) or, `deleted`, the deleted ones.
pub async fn list(
    db: &Db,
    vessel_id: Option<&str>,
    deleted: bool,
) -> anyhow::Result<Vec<Campaign>> {
    let which = if deleted {
        "campaign.deleted_at IS NOT NULL"
    } else {
        LIVE
    };
    sqlx::query_as::<_, Row>(sqlx::AssertSqlSafe(format!(
        "{SELECT} WHERE ($1 IS NULL OR vessel_id = $1) AND {which} ORDER BY id"
    )))
    .bind(vessel_id)
    .fetch_all(db)
    .await?
    .into_iter()
    .map(Campaign::try_from)
    .collect()
}

/// One campaign (deleted or not).
pub async fn get(db: &Db, id: &str) -> anyhow::Result<Option<Campaign>> {
    sqlx::query_as::<_, Row>(sqlx::AssertSqlSafe(format!("{SELECT} WHERE id = $1")))
        .bind(id)
        .fetch_optional(db)
        .await?
        .map(Campaign::try_from)
        .transpose()
}

/// Renames a campaign (the `name` column and the stored spec), in one
/// transaction. The renamed campaign, or None when there is no such campaign.
pub async fn rename(db: &Db, id: &str, name: &str) -> anyhow::Result<Option<Campaign>> {
    let mut tx = db.begin().await?;
    if !lock_row(&mut tx, "campaign", id).await? {
        return Ok(None);
    }
    let row = sqlx::query_as::<_, Row>(sqlx::AssertSqlSafe(format!("{SELECT} WHERE id = $1")))
        .bind(id)
        .fetch_one(&mut *tx)
        .await?;
    let mut c = Campaign::try_from(row)?;
    c.spec.name = name.to_string();
    sqlx::query("UPDATE campaign SET name = $1, spec = $2 WHERE id = $3")
        .bind(name)
        .bind(serde_json::to_string(&c.spec)?)
        .bind(id)
        .execute(&mut *tx)
        .await?;
    tx.commit().await?;
    Ok(Some(c))
}
