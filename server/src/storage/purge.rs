//! Purging a soft-deleted run for good (admin): its rows go in one
//! transaction, then the files of its blobs no other run shares. The order
//! is crash-safe: a crash before the commit leaves everything as it was; a
//! crash after it leaves at worst a blob file no row names, which
//! [`orphan_blobs`] finds and the next start removes (`intake::sweep`)
//! before serving. A row never names a missing file.

use std::collections::HashSet;

use super::blobs::BlobStore;
use super::{Db, lock_row};

/// What purging a run did.
#[derive(Debug)]
pub enum Purged {
    /// No such run.
    NotFound,
    /// The run is not deleted (delete it first); its name.
    NotDeleted(String),
    /// Kept: the run's name and the models and discovery reports whose
    /// provenance uses it (`kind 'name' (id)` phrases).
    InUse(String, Vec<String>),
    /// Gone; the run's name and the blob files removed.
    Done(String, Vec<String>),
}

/// Removes soft-deleted run `id` for good: its rows (files, quality report,
/// clock offset, the run) and the blob rows no other run shares in one
/// transaction, then those blob files.
pub async fn run(db: &Db, blobs: &BlobStore, id: &str) -> anyhow::Result<Purged> {
    let mut tx = db.begin().await?;
    if !lock_row(&mut tx, "run", id).await? {
        return Ok(Purged::NotFound);
    }
    let (name, deleted_at): (String, Option<String>) =
        sqlx::query_as("SELECT name, deleted_at FROM run WHERE id = $1")
            .bind(id)
            .fetch_one(&mut *tx)
            .await?;
    if deleted_at.is_none() {
        return Ok(Purged::NotDeleted(name));
    }
    // Everything stored that names it, deleted models included.
    let users = super::runs::users(&mut tx, id, true).await?;
    if !users.is_empty() {
        return Ok(Purged::InUse(name, users));
    }
    let shas: Vec<String> = sqlx::query_scalar("SELECT sha256 FROM run_file WHERE run_id = $1")
        .bind(id)
        .fetch_all(&mut *tx)
        .await?;
    for sql in [
        "DELETE FROM run_file WHERE run_id = $1",
        "DELETE FROM run_quality WHERE run_id = $1",
        "DELETE FROM run_clock_offset WHERE run_id = $1",
        "DELETE FROM run WHERE id = $1",
    ] {
        sqlx::query(sql).bind(id).execute(&mut *tx).await?;
    }
    let mut gone = Vec::new();
    for sha in shas {
        let shared: i64 = sqlx::query_scalar("SELECT COUNT(*) FROM run_file WHERE sha256 = $1")
            .bind(&sha)
            .fetch_one(&mut *tx)
            .await?;
        if shared == 0 {
            sqlx::query("DELETE FROM blob WHERE sha256 = $1")
                .bind(&sha)
                .execute(&mut *tx)
                .await?;
            gone.push(sha);
        }
    }
    tx.commit().await?;
    // Files after the commit: a crash here leaves only orphans, swept at start.
    let mut removed = Vec::new();
    for sha in gone {
        // Stored again meanwhile (the same bytes uploaded): keep the file.
        let back: Option<i64> = sqlx::query_scalar("SELECT 1 FROM blob WHERE sha256 = $1")
            .bind(&sha)
            .fetch_optional(db)
            .await?;
        if back.is_none() {
            blobs.remove(&sha).await?;
            removed.push(sha);
        }
    }
    Ok(Purged::Done(name, removed))
}

/// The blob files no `blob` row names: what a crash after a purge's commit
/// (or between an upload's file and its row) left. Only safe to remove
/// before serving, when no upload is under way.
pub async fn orphan_blobs(db: &Db, blobs: &BlobStore) -> anyhow::Result<Vec<String>> {
    let known: HashSet<String> = sqlx::query_scalar("SELECT sha256 FROM blob")
        .fetch_all(db)
        .await?
        .into_iter()
        .collect();
    Ok(blobs
        .files()?
        .into_iter()
        .filter(|f| !known.contains(f))
        .collect())
}
