//! Runs as jobs read them: the stored rows (async, in `load`) become owned
//! descriptions, and those become the core's [`RunInput`]s on the worker
//! thread, where parsing the logs belongs.

use std::path::PathBuf;

use seatrial_core::identification::RunInput;
use seatrial_core::planning::VesselProfile;
use seatrial_core::planning::campaign::ExperimentFamily;

use super::handler::{JobContext, JobFailure};
use crate::processing::{self, RunMeta, RunSummary};
use crate::storage::plans;
use crate::storage::runs::Run;

/// A run as stored, ready to be re-read on the worker.
pub struct StoredRun {
    /// Run id.
    pub id: String,
    /// Run name.
    pub name: String,
    /// (role, blob path) of its files.
    pub files: Vec<(String, PathBuf)>,
    /// How it was uploaded (rate, shared channel).
    pub meta: RunMeta,
    /// The planned experiment's family.
    pub family: Option<ExperimentFamily>,
    /// The planned experiment's grid speed (m/s).
    pub grid_speed_mps: Option<f64>,
}

/// Describes `runs` of campaign `campaign_id` with what their plan says.
pub async fn describe(
    cx: &JobContext,
    campaign_id: &str,
    runs: Vec<Run>,
) -> Result<Vec<StoredRun>, JobFailure> {
    let mut stored = Vec::new();
    for r in runs {
        let planned = match &r.experiment_id {
            Some(eid) => plans::experiment(&cx.db, campaign_id, eid)
                .await?
                .map(|(e, _)| e.experiment),
            None => None,
        };
        stored.push(StoredRun {
            meta: RunMeta::of_stored(r.summary.as_ref()),
            files: r
                .files
                .iter()
                .map(|f| (f.role.clone(), cx.blobs.path(&f.sha256)))
                .collect(),
            family: planned.as_ref().map(|e| e.family),
            grid_speed_mps: planned.as_ref().and_then(|e| e.grid_speed_mps),
            id: r.id,
            name: r.name,
        });
    }
    Ok(stored)
}

/// Reads and resamples the logs (on the worker thread); an unreadable run
/// fails the job naming it.
pub fn read(profile: &VesselProfile, stored: &[StoredRun]) -> Result<Vec<RunInput>, JobFailure> {
    stored
        .iter()
        .map(|s| {
            let mut summary = RunSummary::default();
            let record = processing::load_record(profile, &s.files, &s.meta, &mut summary)
                .map_err(|e| JobFailure::field(format!("runs[{}]", s.id), e.message))?;
            Ok(RunInput {
                run_id: s.id.clone(),
                name: s.name.clone(),
                family: s.family,
                grid_speed_mps: s.grid_speed_mps,
                record,
            })
        })
        .collect()
}
