//! Vessel profiles.

use seatrial_core::planning::VesselProfile;
use serde::Serialize;

use super::trash::Deletion;
use super::{Db, lock_row, new_id, now};

/// A stored vessel.
#[derive(Debug, Clone, Serialize, utoipa::ToSchema)]
pub struct Vessel {
    /// Id (UUIDv7).
    pub id: String,
    /// Creation time (RFC 3339).
    pub created_at: String,
    /// The profile.
    pub profile: VesselProfile,
    /// Who deleted it, when and why (a deleted vessel's campaigns leave the lists too).
    #[serde(flatten)]
    pub deletion: Deletion,
}

#[derive(sqlx::FromRow)]
struct Row {
    id: String,
    profile: String,
    created_at: String,
    #[sqlx(flatten)]
    deletion: Deletion,
}

const SELECT: &str =
    "SELECT id, profile, created_at, deleted_at, deleted_by, delete_reason FROM vessel";

impl TryFrom<Row> for Vessel {
    type Error = anyhow::Error;
    fn try_from(r: Row) -> anyhow::Result<Self> {
        Ok(Vessel {
            id: r.id,
            created_at: r.created_at,
            profile: serde_json::from_str(&r.profile)?,
            deletion: r.deletion,
        })
    }
}

/// Inserts a validated profile.
pub async fn insert(db: &Db, profile: VesselProfile) -> anyhow::Result<Vessel> {
    let v = Vessel {
        id: new_id(),
        created_at: now(),
        profile,
        deletion: Deletion::default(),
    };
    sqlx::query(
        "INSERT INTO vessel (id, name, kind, profile, created_at) VALUES ($1, $2, $3, $4, $5)",
    )
    .bind(&v.id)
    .bind(&v.profile.name)
    .bind(
        serde_json::to_value(v.profile.kind)?
            .as_str()
            .unwrap_or_default()
            .to_string(),
    )
    .bind(serde_json::to_string(&v.profile)?)
    .bind(&v.created_at)
    .execute(db)
    .await?;
    Ok(v)
}

/// The live vessels (or, `deleted`, the deleted ones), oldest first.
pub async fn list(db: &Db, deleted: bool) -> anyhow::Result<Vec<Vessel>> {
    let gone = if deleted { "NOT NULL" } else { "NULL" };
    sqlx::query_as::<_, Row>(sqlx::AssertSqlSafe(format!(
        "{SELECT} WHERE deleted_at IS {gone} ORDER BY id"
    )))
    .fetch_all(db)
    .await?
    .into_iter()
    .map(Vessel::try_from)
    .collect()
}

/// Whether any vessel is stored, deleted ones included.
pub async fn any(db: &Db) -> anyhow::Result<bool> {
    Ok(sqlx::query_scalar::<_, i64>("SELECT COUNT(*) FROM vessel")
        .fetch_one(db)
        .await?
        > 0)
}

/// One vessel (deleted or not).
pub async fn get(db: &Db, id: &str) -> anyhow::Result<Option<Vessel>> {
    sqlx::query_as::<_, Row>(sqlx::AssertSqlSafe(format!("{SELECT} WHERE id = $1")))
        .bind(id)
        .fetch_optional(db)
        .await?
        .map(Vessel::try_from)
        .transpose()
}

/// Renames a vessel (its profile's name and the name column), in one
/// transaction; `None` when there is no such vessel.
pub async fn rename(db: &Db, id: &str, name: &str) -> anyhow::Result<Option<Vessel>> {
    let mut tx = db.begin().await?;
    if !lock_row(&mut tx, "vessel", id).await? {
        return Ok(None);
    }
    let row = sqlx::query_as::<_, Row>(sqlx::AssertSqlSafe(format!("{SELECT} WHERE id = $1")))
        .bind(id)
        .fetch_one(&mut *tx)
        .await?;
    let mut v = Vessel::try_from(row)?;
    v.profile.name = name.to_string();
    sqlx::query("UPDATE vessel SET name = $1, profile = $2 WHERE id = $3")
        .bind(name)
        .bind(serde_json::to_string(&v.profile)?)
        .bind(id)
        .execute(&mut *tx)
        .await?;
    tx.commit().await?;
    Ok(Some(v))
}
