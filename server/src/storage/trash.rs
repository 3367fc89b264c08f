//! Soft deletes shared by every kind of stored item: a deleted row keeps who
//! deleted it, when and why; restoring it is refused while a parent (the
//! campaign of a run or model, the vessel of a campaign) is deleted, so an
//! item never comes back under a parent the lists hide.

use serde::Serialize;
use sqlx::SqliteConnection;

use super::{Db, Restored, lock_row, now};

/// Who deleted an item, when and why (all `null`: not deleted).
#[derive(Debug, Clone, Default, Serialize, sqlx::FromRow, utoipa::ToSchema)]
pub struct Deletion {
    /// When it was deleted (RFC 3339; `null`: not deleted). A deleted item
    /// stays readable by id but leaves the lists (`?deleted=true` lists it);
    /// `POST …/{id}/restore` undoes the delete.
    pub deleted_at: Option<String>,
    /// Who deleted it (user name).
    pub deleted_by: Option<String>,
    /// Why it was deleted.
    pub delete_reason: Option<String>,
}

/// The parent table of `table` and the column naming the parent.
fn parent_of(table: &str) -> Option<(&'static str, &'static str)> {
    match table {
        "campaign" => Some(("vessel", "vessel_id")),
        "run" | "model" => Some(("campaign", "campaign_id")),
        _ => None,
    }
}

/// The nearest deleted parent of row `id` of `table`, as `kind 'name' (id)`.
pub async fn deleted_parent(
    conn: &mut SqliteConnection,
    table: &'static str,
    id: &str,
) -> anyhow::Result<Option<String>> {
    let (mut table, mut id) = (table, id.to_string());
    while let Some((parent, column)) = parent_of(table) {
        let sql = format!(
            "SELECT p.id, p.name, p.deleted_at FROM {table} t JOIN {parent} p ON p.id = t.{column} \
             WHERE t.id = $1"
        );
        let row: Option<(String, String, Option<String>)> =
            sqlx::query_as(sqlx::AssertSqlSafe(sql))
                .bind(&id)
                .fetch_optional(&mut *conn)
                .await?;
        let Some((pid, name, deleted_at)) = row else {
            return Ok(None);
        };
        if deleted_at.is_some() {
            return Ok(Some(format!("{parent} '{name}' ({pid})")));
        }
        (table, id) = (parent, pid);
    }
    Ok(None)
}

/// Row `id` of `table` itself if deleted, else its nearest deleted parent,
/// as `kind 'name' (id)`; `None` when neither is (or there is no such row).
pub async fn deleted_self_or_parent(
    db: &Db,
    table: &'static str,
    id: &str,
) -> anyhow::Result<Option<String>> {
    let mut conn = db.acquire().await?;
    let row: Option<(String, Option<String>)> = sqlx::query_as(sqlx::AssertSqlSafe(format!(
        "SELECT name, deleted_at FROM {table} WHERE id = $1"
    )))
    .bind(id)
    .fetch_optional(&mut *conn)
    .await?;
    match row {
        Some((name, Some(_))) => Ok(Some(format!("{table} '{name}' ({id})"))),
        _ => deleted_parent(&mut conn, table, id).await,
    }
}

/// `deleted_at` of row `id` (outer `None`: no such row).
async fn deleted_at(
    conn: &mut SqliteConnection,
    table: &'static str,
    id: &str,
) -> anyhow::Result<Option<Option<String>>> {
    let sql = format!("SELECT deleted_at FROM {table} WHERE id = $1");
    Ok(sqlx::query_scalar(sqlx::AssertSqlSafe(sql))
        .bind(id)
        .fetch_optional(conn)
        .await?)
}

/// Whether row `id` of `table` is deleted (false also when there is none).
pub async fn is_deleted(
    conn: &mut SqliteConnection,
    table: &'static str,
    id: &str,
) -> anyhow::Result<bool> {
    Ok(deleted_at(conn, table, id).await?.flatten().is_some())
}

/// Marks row `id` of `table` deleted, in the caller's transaction (which
/// holds the row's lock); false when it is deleted already.
pub async fn mark(
    conn: &mut SqliteConnection,
    table: &'static str,
    id: &str,
    by: &str,
    reason: Option<&str>,
) -> anyhow::Result<bool> {
    if is_deleted(conn, table, id).await? {
        return Ok(false);
    }
    let sql = format!(
        "UPDATE {table} SET deleted_at = $1, deleted_by = $2, delete_reason = $3 WHERE id = $4"
    );
    sqlx::query(sqlx::AssertSqlSafe(sql))
        .bind(now())
        .bind(by)
        .bind(reason)
        .bind(id)
        .execute(conn)
        .await?;
    Ok(true)
}

/// Soft-deletes row `id` of `table` in one transaction; false when there is
/// no such row or it is deleted already.
pub async fn delete(
    db: &Db,
    table: &'static str,
    id: &str,
    by: &str,
    reason: Option<&str>,
) -> anyhow::Result<bool> {
    let mut tx = db.begin().await?;
    if !lock_row(&mut tx, table, id).await? || !mark(&mut tx, table, id, by, reason).await? {
        return Ok(false);
    }
    tx.commit().await?;
    Ok(true)
}

/// Undoes the soft delete of row `id` of `table`, in one transaction;
/// refused while a parent is deleted.
pub async fn restore(db: &Db, table: &'static str, id: &str) -> anyhow::Result<Restored> {
    let mut tx = db.begin().await?;
    if !lock_row(&mut tx, table, id).await? {
        return Ok(Restored::NotFound);
    }
    if !is_deleted(&mut tx, table, id).await? {
        return Ok(Restored::NotDeleted);
    }
    if let Some(parent) = deleted_parent(&mut tx, table, id).await? {
        return Ok(Restored::ParentDeleted(parent));
    }
    let sql = format!(
        "UPDATE {table} SET deleted_at = NULL, deleted_by = NULL, delete_reason = NULL WHERE id = $1"
    );
    sqlx::query(sqlx::AssertSqlSafe(sql))
        .bind(id)
        .execute(&mut *tx)
        .await?;
    tx.commit().await?;
    Ok(Restored::Done)
}
