//! Runs as jobs read them: the stored rows (async, in `load`) become owned
//! descriptions, and those become the core's [`RunInput`]s on the worker
//! thread, where parsing the logs belongs. What a run is (its family, grid
//! speed, excited DOFs) is its effective description: the supervisor's
//! word, else the matched planned experiment, else what was inferred from
//! its data on upload. Two-file runs are merged with the campaign's clock
//! offsets as they are when the job runs (hand-set, own, pooled from every
//! accepted two-file run of the campaign; see [`crate::clock`]), and the
//! job reports which offset each run used.

use std::path::PathBuf;

use seatrial_core::alignment::{OffsetPriors, OffsetSource, offset_words};
use seatrial_core::identification::RunInput;
use seatrial_core::planning::campaign::ExperimentFamily;
use seatrial_core::planning::{Dof, VesselProfile};
use serde::Serialize;

use super::handler::{JobContext, JobFailure};
use crate::clock::CampaignClocks;
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
    /// Clock offsets known apart from its own estimate (two-file runs).
    pub priors: OffsetPriors,
}

/// The clock offset a two-file run was read with, for the job's result.
#[derive(Debug, Clone, Serialize)]
pub struct RunClock {
    /// Run id.
    pub run_id: String,
    /// Run name.
    pub name: String,
    /// Offset used (s, added to navigation stamps).
    pub offset_s: f64,
    /// Its standard deviation (s); `None` when set by hand.
    pub std_s: Option<f64>,
    /// Where it came from.
    pub source: OffsetSource,
    /// The run's own estimate (s), when it has one.
    pub own_offset_s: Option<f64>,
}

impl RunClock {
    /// A note for the model document, in words.
    pub fn note(&self) -> String {
        let source = match self.source {
            OffsetSource::UserRun => "set by hand for the run",
            OffsetSource::UserCampaign => "set by hand for the campaign",
            OffsetSource::Own => "the run's own estimate",
            OffsetSource::Pooled => "the campaign's pooled offset",
            OffsetSource::WeakOwn => "the run's own estimate, NOT informative",
        };
        format!(
            "clock offset of two-file run “{}”: {} ({source})",
            self.name,
            offset_words(self.offset_s, self.std_s)
        )
    }
}

impl StoredRun {
    /// What `run`'s description says it is, with its files under `cx`'s
    /// blobs and its campaign's `clocks` as priors.
    pub fn of(cx: &JobContext, r: Run, clocks: &CampaignClocks) -> StoredRun {
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
            priors: clocks.priors_for(Some(&r.id)),
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

/// Describes `runs` of campaign `campaign_id` by their effective
/// descriptions, with the campaign's clock offsets as they are now.
pub async fn describe(
    cx: &JobContext,
    campaign_id: &str,
    runs: Vec<Run>,
) -> Result<Vec<StoredRun>, JobFailure> {
    let clocks = CampaignClocks::load(&cx.db, campaign_id).await?;
    Ok(runs
        .into_iter()
        .map(|r| StoredRun::of(cx, r, &clocks))
        .collect())
}

/// Reads and resamples the logs (on the worker thread); an unreadable run
/// fails the job naming it. Also returns the clock offset each two-file
/// run was merged with.
pub fn read(
    profile: &VesselProfile,
    stored: &[StoredRun],
) -> Result<(Vec<RunInput>, Vec<RunClock>), JobFailure> {
    let mut inputs = Vec::with_capacity(stored.len());
    let mut clocks = Vec::new();
    for s in stored {
        let mut summary = RunSummary::default();
        let record = processing::load_record(profile, &s.files, &s.meta, &s.priors, &mut summary)
            .map_err(|e| {
            JobFailure::field(
                format!("runs[{}]", s.id),
                format!("run '{}' ({}): {}", s.name, s.id, e.message),
            )
        })?;
        if let Some(a) = summary.alignment {
            clocks.push(RunClock {
                run_id: s.id.clone(),
                name: s.name.clone(),
                offset_s: a.offset_used_s,
                std_s: a.offset_used_std_s,
                source: a.offset_source,
                own_offset_s: a.offset.map(|o| o.offset_s),
            });
        }
        inputs.push(s.input(record));
    }
    Ok((inputs, clocks))
}

/// An identification error's message naming the run its field points at
/// (`runs[<run id>]…`) by name and id, so the engineer finds it.
pub fn naming_run(field: &str, message: String, runs: &[(String, String)]) -> String {
    runs.iter()
        .find(|(id, _)| field.contains(&format!("[{id}]")))
        .filter(|(id, _)| !message.contains(id.as_str()))
        .map_or(message.clone(), |(id, name)| {
            format!("run '{name}' ({id}): {message}")
        })
}
