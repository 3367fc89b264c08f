//! Runs as jobs read them: the stored rows (async, in `load`) become owned
//! descriptions, and those become the core's [`RunInput`]s on the worker
//! thread, where parsing the logs belongs. Two-file runs are merged with the
//! campaign's clock offsets as they are when the job runs (hand-set, own,
//! pooled from every accepted two-file run of the campaign; see
//! [`crate::clock`]), and the job reports which offset each run used.

use std::path::PathBuf;

use seatrial_core::alignment::{OffsetPriors, OffsetSource, offset_words};
use seatrial_core::identification::RunInput;
use seatrial_core::planning::VesselProfile;
use seatrial_core::planning::campaign::ExperimentFamily;
use serde::Serialize;

use super::handler::{JobContext, JobFailure};
use crate::clock::CampaignClocks;
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

/// Describes `runs` of campaign `campaign_id` with what their plan says.
pub async fn describe(
    cx: &JobContext,
    campaign_id: &str,
    runs: Vec<Run>,
) -> Result<Vec<StoredRun>, JobFailure> {
    let clocks = CampaignClocks::load(&cx.db, campaign_id).await?;
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
            priors: clocks.priors_for(Some(&r.id)),
            id: r.id,
            name: r.name,
        });
    }
    Ok(stored)
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
            .map_err(|e| JobFailure::field(format!("runs[{}]", s.id), e.message))?;
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
        inputs.push(RunInput {
            run_id: s.id.clone(),
            name: s.name.clone(),
            family: s.family,
            grid_speed_mps: s.grid_speed_mps,
            record,
        });
    }
    Ok((inputs, clocks))
}
