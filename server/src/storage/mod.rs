//! Storage: SQLite through sqlx, migrations embedded from `migrations/`.
//! Queries use `$N` placeholders and portable SQL so that the same code can
//! later run on PostgreSQL (see the migration's header for the conventions).

pub mod accounts;
pub mod audit;
pub mod blobs;
pub mod campaigns;
pub mod clock_offsets;
pub mod discrepancies;
pub mod jobs;
pub mod models;
pub mod plan_revision;
pub mod plans;
pub mod purge;
pub mod runs;
pub mod trash;
pub mod vessels;

use std::path::Path;
use std::str::FromStr;
use std::time::Duration;

use sqlx::sqlite::{SqliteConnectOptions, SqliteJournalMode, SqlitePoolOptions, SqliteSynchronous};

/// The pool type used throughout.
pub type Db = sqlx::SqlitePool;

/// Opens (creating if needed) the database file, in WAL mode with foreign
/// keys on, and applies pending migrations.
pub async fn open(path: &Path) -> anyhow::Result<Db> {
    if let Some(dir) = path.parent()
        && !dir.as_os_str().is_empty()
    {
        std::fs::create_dir_all(dir)?;
    }
    let opts = SqliteConnectOptions::from_str(&format!("sqlite://{}", path.display()))?
        .create_if_missing(true)
        .journal_mode(SqliteJournalMode::Wal)
        .synchronous(SqliteSynchronous::Normal)
        .foreign_keys(true)
        .busy_timeout(Duration::from_secs(10));
    let pool = SqlitePoolOptions::new()
        .max_connections(8)
        .connect_with(opts)
        .await?;
    sqlx::migrate!("./migrations").run(&pool).await?;
    Ok(pool)
}

/// A page of a list: at most `limit` items after skipping `offset`.
#[derive(Debug, Clone, Copy, Default)]
pub struct Page {
    /// Most items (None: all).
    pub limit: Option<i64>,
    /// Items skipped.
    pub offset: i64,
}

impl Page {
    /// The `LIMIT` to bind (every row when no limit is set).
    pub fn sql_limit(self) -> i64 {
        self.limit.unwrap_or(i64::MAX)
    }
}

/// Takes the database's write lock for the caller's transaction by a no-op
/// write to row `id` of `table` (so what it reads next cannot change before
/// it commits); false when there is no such row.
pub(crate) async fn lock_row(
    conn: &mut sqlx::SqliteConnection,
    table: &'static str,
    id: &str,
) -> anyhow::Result<bool> {
    let sql = format!("UPDATE {table} SET id = id WHERE id = $1");
    Ok(sqlx::query(sqlx::AssertSqlSafe(sql))
        .bind(id)
        .execute(conn)
        .await?
        .rows_affected()
        > 0)
}

/// What restoring a deleted item did.
#[derive(Debug, PartialEq, Eq)]
pub enum Restored {
    /// No such item.
    NotFound,
    /// It was not deleted; nothing changed.
    NotDeleted,
    /// A parent (`kind 'name' (id)`) is deleted: restore it first.
    ParentDeleted(String),
    /// Restored.
    Done,
}

/// A new time-ordered id.
pub fn new_id() -> String {
    uuid::Uuid::now_v7().to_string()
}

/// Now, RFC 3339 in UTC.
pub fn now() -> String {
    time::OffsetDateTime::now_utc()
        .format(&time::format_description::well_known::Rfc3339)
        .unwrap_or_default()
}
