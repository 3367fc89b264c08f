//! Runs as jobs read them: the stored rows (async, in `load`) become owned
//! descriptions, and those become the core's [`RunInput`]s on the worker
//! thread, where parsing the logs belongs. What a run is (its family, grid
//! speed, excited DOFs) is its effective description: the supervisor's
//! word, else the matched planned experiment, else what was inferred from
//! its data on upload.

use std::path::PathBuf;

use seatrial_core::identification::RunInput;
use seatrial_core::planning::campaign::ExperimentFamily;
use seatrial_core::planning::{Dof, VesselProfile};

use super::handler::{JobContext, JobFailure};
use crate::processing::{self, RunMeta, RunSummary};
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
    /// The family it counts as (from its role).
    pub family: Option<ExperimentFamily>,
    /// Its grid speed (m/s).
    pub grid_speed_mps: Option<f64>,
    /// The DOFs it excites.
    pub excited_dofs: Vec<Dof>,
}

impl StoredRun {
    /// What `run`'s description says it is, with its files under `cx`'s blobs.
    pub fn of(cx: &JobContext, r: Run) -> StoredRun {
        let d = &r.description;
        StoredRun {
            meta: RunMeta::of_stored(r.summary.as_ref()),
            files: r
                .files
                .iter()
                .map(|f| (f.role.clone(), cx.blobs.path(&f.sha256)))
                .collect(),
            family: d.family,
            grid_speed_mps: d.grid_speed_mps.as_ref().map(|g| g.value),
            excited_dofs: d
                .excited_dofs
                .as_ref()
                .map(|x| x.value.clone())
                .unwrap_or_default(),
            id: r.id,
            name: r.name,
        }
    }

    /// The core's run input over `record`.
    pub fn input(&self, record: seatrial_core::timeseries::UniformRecord) -> RunInput {
        RunInput {
            run_id: self.id.clone(),
            name: self.name.clone(),
            family: self.family,
            grid_speed_mps: self.grid_speed_mps,
            excited_dofs: self.excited_dofs.clone(),
            record,
        }
    }
}

/// Describes `runs` by their effective descriptions.
pub fn describe(cx: &JobContext, runs: Vec<Run>) -> Vec<StoredRun> {
    runs.into_iter().map(|r| StoredRun::of(cx, r)).collect()
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
            Ok(s.input(record))
        })
        .collect()
}
