//! The demo a newcomer clicks through: the Surveyor ROV on the thesis's grid
//! and Fossen's supply vessel with its three decoupled DP manoeuvres, each
//! with a campaign and a generated plan. The ROV campaign has been "flown":
//! every planned experiment simulated through the ROV truth
//! (`simulation::trials`) and uploaded as a run, so identification can be
//! started at once. Seeded only into an empty database.

use seatrial_core::planning::examples::{
    supply_vessel, supply_vessel_campaign, surveyor_campaign, surveyor_rov,
};
use seatrial_core::planning::{CampaignSpec, ExperimentFamily, generate_plan};

use seatrial_core::simulation::rov::RovTruth;
use seatrial_core::simulation::trials::{TrialSettings, fly_campaign};

use crate::processing::{self, RunMeta};
use crate::storage::blobs::BlobStore;
use crate::storage::runs::{self, NewFile};
use crate::storage::{Db, campaigns, plans, vessels};

/// The ROV demo campaign: the thesis's grid and families.
pub fn rov_campaign() -> CampaignSpec {
    surveyor_campaign(2026)
}

/// The DP demo campaign: the three decoupled manoeuvres, N = 2 each, and a
/// 600 s validation run.
pub fn dp_campaign() -> CampaignSpec {
    let mut c = supply_vessel_campaign(1995);
    c.families.push(ExperimentFamily::Validation);
    c.durations.validation_s = 600.0;
    c
}

/// Seeds the demo if there are no vessels yet. Returns whether it did.
pub async fn seed_if_empty(db: &Db, blobs: &BlobStore) -> anyhow::Result<bool> {
    if !vessels::list(db).await?.is_empty() {
        return Ok(false);
    }
    for (profile, spec) in [
        (surveyor_rov(), rov_campaign()),
        (supply_vessel(), dp_campaign()),
    ] {
        let (p, s) = (profile.clone(), spec.clone());
        let plan = tokio::task::spawn_blocking(move || generate_plan(&p, &s)).await??;
        let v = vessels::insert(db, profile.clone()).await?;
        let c = campaigns::insert(db, &v.id, spec).await?;
        let stored = plans::insert(db, &c.id, &plan).await?;
        if v.profile.kind == seatrial_core::planning::vessel::VesselKind::Rov6 {
            fly_rov_trials(db, blobs, &c.id, &profile, plan, &stored).await?;
        }
    }
    Ok(true)
}

/// Flies the ROV plan through the Surveyor-like truth and uploads each run
/// as the pilots would: stored verbatim, then parsed and scored.
async fn fly_rov_trials(
    db: &Db,
    blobs: &BlobStore,
    campaign_id: &str,
    profile: &seatrial_core::planning::VesselProfile,
    plan: seatrial_core::planning::Plan,
    stored: &plans::StoredPlan,
) -> anyhow::Result<()> {
    let p = profile.clone();
    let flown = tokio::task::spawn_blocking(move || {
        let settings = TrialSettings {
            // Long enough to identify from, short enough to seed in seconds.
            max_duration_s: Some(300.0),
            seed: 2026,
            ..TrialSettings::default()
        };
        fly_campaign(&p, &RovTruth::surveyor_like(), &plan, &settings, |_| true)
    })
    .await??;
    for run in flown {
        let Some(eid) = stored
            .experiments
            .iter()
            .find(|e| e.experiment.code == run.code)
            .map(|e| e.id.clone())
        else {
            continue;
        };
        let mut w = blobs.begin().await?;
        w.write(run.csv.as_bytes()).await?;
        let blob = w.finish().await?;
        let path = blobs.path(&blob.sha256);
        let r = runs::insert(
            db,
            campaign_id,
            Some(&eid),
            &run.code,
            "single",
            &[NewFile {
                role: "file".into(),
                filename: format!("{}.csv", run.code),
                blob,
            }],
        )
        .await?;
        let planned = plans::experiment(db, campaign_id, &eid).await?;
        let prof = profile.clone();
        let done = tokio::task::spawn_blocking(move || {
            processing::process_run(
                &prof,
                &[("file".to_string(), path)],
                &RunMeta::default(),
                planned.as_ref(),
            )
        })
        .await?;
        match done {
            Ok(d) => {
                runs::finish(
                    db,
                    &r.id,
                    "accepted",
                    None,
                    Some(&d.summary),
                    Some(&d.quality_json),
                )
                .await?
            }
            Err(e) => {
                let detail = serde_json::to_value(&e)?;
                runs::finish(db, &r.id, "rejected", Some(&detail), None, None).await?
            }
        }
    }
    Ok(())
}
