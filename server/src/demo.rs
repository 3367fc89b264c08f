//! The demo a newcomer clicks through: the Surveyor ROV on the thesis's grid
//! and Fossen's supply vessel with its three decoupled DP manoeuvres, each
//! with a campaign and a generated plan. Both campaigns have been "flown":
//! every planned experiment simulated through its truth (the ROV through
//! `simulation::trials`, the supply vessel through `simulation::dp_ship`)
//! and uploaded as a run, so identification can be started at once. Seeded
//! only into an empty database.

use seatrial_core::identification::UserDescription;
use seatrial_core::planning::examples::{
    supply_vessel, supply_vessel_trial_campaign, surveyor_campaign, surveyor_rov,
};
use seatrial_core::planning::vessel::VesselKind;
use seatrial_core::planning::{CampaignSpec, Plan, VesselProfile, generate_plan};
use seatrial_core::simulation::dp_ship::{DpFlightSettings, DpShip, fly_dp_campaign};

use seatrial_core::simulation::rov::RovTruth;
use seatrial_core::simulation::trials::{TrialSettings, fly_campaign};

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
    supply_vessel_trial_campaign(1995)
}

/// Seeds the demo if there are no vessels yet. Returns whether it did.
pub async fn seed_if_empty(db: &Db, blobs: &BlobStore) -> anyhow::Result<bool> {
    if vessels::any(db).await? {
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
        let stored = crate::storage::plan_revision::insert(db, &c.id, &plan).await?;
        match v.profile.kind {
            VesselKind::Rov6 => fly_rov_trials(db, blobs, &c.id, &profile, plan, &stored).await?,
            VesselKind::Dp3 => fly_dp_trials(db, blobs, &c.id, &profile, plan, &stored).await?,
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
    profile: &VesselProfile,
    plan: Plan,
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
    let logs = flown.into_iter().map(|r| (r.code, r.csv)).collect();
    upload_all(db, blobs, campaign_id, stored, logs).await
}

/// Flies the DP plan through Fossen's supply vessel (the paper's M″, T″,
/// A″_h, K″; 1 m position and 0.2° heading noise, a slowly varying bias)
/// and uploads each run, so `parallel_ekf` can be run at once.
async fn fly_dp_trials(
    db: &Db,
    blobs: &BlobStore,
    campaign_id: &str,
    profile: &VesselProfile,
    plan: Plan,
    stored: &plans::StoredPlan,
) -> anyhow::Result<()> {
    let p = profile.clone();
    let flown = tokio::task::spawn_blocking(move || {
        fly_dp_campaign(
            &p,
            &DpShip::supply_vessel(),
            &plan,
            &DpFlightSettings::supply_vessel(1995),
            |_| true,
        )
    })
    .await??;
    let logs = flown.into_iter().map(|r| (r.code, r.csv)).collect();
    upload_all(db, blobs, campaign_id, stored, logs).await
}

/// Uploads `(experiment code, csv)` logs as runs of their planned
/// experiments: stored verbatim, then parsed and scored.
pub async fn upload_all(
    db: &Db,
    blobs: &BlobStore,
    campaign_id: &str,
    stored: &plans::StoredPlan,
    logs: Vec<(String, String)>,
) -> anyhow::Result<()> {
    for (code, csv) in logs {
        let Some(eid) = stored
            .experiments
            .iter()
            .find(|e| e.experiment.code == code)
            .map(|e| e.id.clone())
        else {
            continue;
        };
        let mut w = blobs.begin().await?;
        w.write(csv.as_bytes()).await?;
        let blob = w.finish().await?;
        let r = runs::insert(
            db,
            campaign_id,
            Some(&eid),
            &code,
            "single",
            &[NewFile {
                role: "file".into(),
                filename: format!("{code}.csv"),
                blob,
            }],
            &UserDescription::default(),
            &serde_json::json!({}),
        )
        .await?;
        // A demo log that does not process stays, rejected with its reason.
        let _ = crate::intake::process_stored(db, blobs, &r.id).await?;
    }
    Ok(())
}
