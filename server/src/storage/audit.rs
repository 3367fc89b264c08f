//! The audit trail: who wrote what, when, and how it was answered.

use serde::Serialize;

use super::{Db, Page, new_id, now};

/// One write request (or sign-in attempt).
#[derive(Debug, Clone, Serialize, sqlx::FromRow, utoipa::ToSchema)]
pub struct AuditEntry {
    /// Id (UUIDv7, ordered by time).
    pub id: String,
    /// When it was answered (RFC 3339).
    pub at: String,
    /// The acting user (`null`: the local admin of local mode, or a failed sign-in).
    pub user_id: Option<String>,
    /// The acting user's name (`local` in local mode; the name tried for a failed sign-in).
    pub user_name: String,
    /// How the request was authenticated: `session`, `token`, `local` or `login`.
    pub via: String,
    /// HTTP method.
    pub method: String,
    /// The route template (`/api/runs/{id}`).
    pub route: String,
    /// The path as requested.
    pub path: String,
    /// The route's `{id}`, or the id of what was created.
    pub target_id: Option<String>,
    /// The response's status code.
    pub status: i64,
    /// The reason given with the write (e.g. why something was deleted), if any.
    pub note: Option<String>,
}

/// What a new entry says (its id and time are set on insert).
#[derive(Debug, Clone)]
pub struct NewAudit {
    /// Acting user id.
    pub user_id: Option<String>,
    /// Acting user name.
    pub user_name: String,
    /// `session`, `token`, `local` or `login`.
    pub via: &'static str,
    /// HTTP method.
    pub method: String,
    /// Route template.
    pub route: String,
    /// Path as requested.
    pub path: String,
    /// Target id.
    pub target_id: Option<String>,
    /// Status code.
    pub status: u16,
    /// The reason given with the write.
    pub note: Option<String>,
}

/// Appends an entry.
pub async fn insert(db: &Db, e: NewAudit) -> anyhow::Result<()> {
    sqlx::query(
        "INSERT INTO audit (id, at, user_id, user_name, via, method, route, path, target_id, status, note) \
         VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11)",
    )
    .bind(new_id())
    .bind(now())
    .bind(&e.user_id)
    .bind(&e.user_name)
    .bind(e.via)
    .bind(&e.method)
    .bind(&e.route)
    .bind(&e.path)
    .bind(&e.target_id)
    .bind(i64::from(e.status))
    .bind(&e.note)
    .execute(db)
    .await?;
    Ok(())
}

/// Entries, newest first (of one user when given), one page, with the total.
pub async fn page(
    db: &Db,
    user_id: Option<&str>,
    page: Page,
) -> anyhow::Result<(Vec<AuditEntry>, i64)> {
    let items = sqlx::query_as(
        "SELECT id, at, user_id, user_name, via, method, route, path, target_id, status, note \
         FROM audit WHERE ($1 IS NULL OR user_id = $1) ORDER BY id DESC LIMIT $2 OFFSET $3",
    )
    .bind(user_id)
    .bind(page.sql_limit())
    .bind(page.offset)
    .fetch_all(db)
    .await?;
    let total = sqlx::query_scalar("SELECT COUNT(*) FROM audit WHERE ($1 IS NULL OR user_id = $1)")
        .bind(user_id)
        .fetch_one(db)
        .await?;
    Ok((items, total))
}
