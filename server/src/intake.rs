//! From a stored run to an accepted or rejected one, and what a crashed
//! server left behind. An upload is stored first (files in the blob store,
//! the run `stored` with the options it was uploaded with), then processed
//! by [`process_stored`] — the same call at upload, when the demo is
//! seeded, and at start for runs a killed server left `stored`
//! ([`recover`]), so none stays `stored` forever.

use seatrial_core::alignment::OffsetPriors;

use crate::clock::CampaignClocks;
use crate::processing::{self, ProcessError, Processed, RunMeta};
use crate::storage::Db;
use crate::storage::blobs::BlobStore;
use crate::storage::runs::{self, Outcome, Run};
use crate::storage::{campaigns, clock_offsets, plans, vessels};

/// Processes `run`'s stored files with `meta` and `priors` off the async
/// runtime (its campaign's vessel, grid and planned experiment loaded
/// here), recording nothing.
pub async fn process(
    db: &Db,
    blobs: &BlobStore,
    run: &Run,
    meta: RunMeta,
    priors: OffsetPriors,
) -> anyhow::Result<Result<Processed, ProcessError>> {
    let campaign = campaigns::get(db, &run.campaign_id)
        .await?
        .ok_or_else(|| anyhow::anyhow!("campaign of run {} vanished", run.id))?;
    let vessel = vessels::get(db, &campaign.vessel_id)
        .await?
        .ok_or_else(|| anyhow::anyhow!("vessel of run {} vanished", run.id))?;
    let planned = match &run.experiment_id {
        Some(eid) => plans::experiment(db, &campaign.id, eid).await?,
        None => None,
    };
    let files: Vec<_> = run
        .files
        .iter()
        .map(|f| (f.role.clone(), blobs.path(&f.sha256)))
        .collect();
    let grid = campaign.grid_speeds_mps;
    Ok(tokio::task::spawn_blocking(move || {
        processing::process_run(
            &vessel.profile,
            &files,
            &meta,
            &priors,
            planned.as_ref(),
            &grid,
        )
    })
    .await?)
}

/// Processes stored run `run_id` with the options it was uploaded with and
/// records the outcome: `Ok(run)` accepted, `Err(why)` rejected (the run
/// stays, with the reason). The outer error is a storage failure.
pub async fn process_stored(
    db: &Db,
    blobs: &BlobStore,
    run_id: &str,
) -> anyhow::Result<Result<Run, ProcessError>> {
    let run = runs::get(db, run_id)
        .await?
        .ok_or_else(|| anyhow::anyhow!("run {run_id} vanished before processing"))?;
    let meta: RunMeta = match runs::upload_meta(db, run_id).await? {
        Some(m) => serde_json::from_str(&m)?,
        None => RunMeta::default(),
    };
    let priors = OffsetPriors {
        user_run_s: meta.clock_offset_s,
        ..CampaignClocks::load(db, &run.campaign_id)
            .await?
            .priors_for(None)
    };
    let user_offset = meta.clock_offset_s;
    match process(db, blobs, &run, meta, priors).await? {
        Ok(done) => {
            if user_offset.is_some() {
                clock_offsets::set_run_offset(db, run_id, user_offset).await?;
            }
            runs::finish(db, run_id, "accepted", done.outcome()).await?;
            let run = runs::get(db, run_id)
                .await?
                .ok_or_else(|| anyhow::anyhow!("run {run_id} vanished after processing"))?;
            Ok(Ok(run))
        }
        Err(e) => {
            let detail = serde_json::to_value(&e)?;
            let out = Outcome {
                error: Some(&detail),
                ..Outcome::default()
            };
            runs::finish(db, run_id, "rejected", out).await?;
            Ok(Err(e))
        }
    }
}

/// What a crashed server left: partial uploads, runs never processed.
#[derive(Debug, Default)]
pub struct Debris {
    /// Partial uploads removed from the blob store's `tmp/`.
    pub partial_uploads: usize,
    /// Blob files no row names (a crash after a purge's commit, or between
    /// an upload's file and its row), removed.
    pub orphan_blobs: usize,
    /// Runs left `stored`, to process with [`Debris::reprocess`].
    pub stored_runs: Vec<String>,
}

/// Sweeps the partial uploads and orphan blob files and lists the runs left `stored`. Call it
/// before serving, so that a run being uploaded now is not in the list.
pub async fn sweep(db: &Db, blobs: &BlobStore) -> anyhow::Result<Debris> {
    let partial_uploads = blobs.sweep_tmp()?;
    if partial_uploads > 0 {
        tracing::warn!(
            files = partial_uploads,
            "removed partial uploads a stopped server left in the blob store's tmp/"
        );
    }
    let orphans = crate::storage::purge::orphan_blobs(db, blobs).await?;
    for sha in &orphans {
        blobs.remove(sha).await?;
    }
    if !orphans.is_empty() {
        tracing::warn!(
            files = orphans.len(),
            "removed blob files no run names (a purge or upload cut short)"
        );
    }
    let stored_runs = runs::stored_ids(db).await?;
    Ok(Debris {
        partial_uploads,
        orphan_blobs: orphans.len(),
        stored_runs,
    })
}

impl Debris {
    /// Processes the runs left `stored` (accepted or rejected, logged);
    /// how many were processed. A run that fails to process for a storage
    /// reason is logged and left for the next start.
    pub async fn reprocess(&self, db: &Db, blobs: &BlobStore) -> usize {
        let mut done = 0;
        for id in &self.stored_runs {
            match process_stored(db, blobs, id).await {
                Ok(Ok(_)) => {
                    done += 1;
                    tracing::info!(run = %id, "run left stored by a stopped server: accepted");
                }
                Ok(Err(e)) => {
                    done += 1;
                    tracing::info!(run = %id, reason = %e.message, "run left stored by a stopped server: rejected");
                }
                Err(e) => {
                    tracing::error!(run = %id, error = %e, "run left stored could not be processed")
                }
            }
        }
        done
    }
}

/// Sweeps and re-processes at once (tests, and a start that can wait).
pub async fn recover(db: &Db, blobs: &BlobStore) -> anyhow::Result<Debris> {
    let debris = sweep(db, blobs).await?;
    debris.reprocess(db, blobs).await;
    Ok(debris)
}
