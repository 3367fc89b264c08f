//! The demo a newcomer clicks through: the Surveyor ROV on the thesis's grid
//! and Fossen's supply vessel with its three decoupled DP manoeuvres, each
//! with a campaign and a generated plan. Seeded only into an empty database.

use seatrial_core::planning::examples::{
    supply_vessel, supply_vessel_campaign, surveyor_campaign, surveyor_rov,
};
use seatrial_core::planning::{CampaignSpec, ExperimentFamily, generate_plan};

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
pub async fn seed_if_empty(db: &Db) -> anyhow::Result<bool> {
    if !vessels::list(db).await?.is_empty() {
        return Ok(false);
    }
    for (profile, spec) in [
        (surveyor_rov(), rov_campaign()),
        (supply_vessel(), dp_campaign()),
    ] {
        let (p, s) = (profile.clone(), spec.clone());
        let plan = tokio::task::spawn_blocking(move || generate_plan(&p, &s)).await??;
        let v = vessels::insert(db, profile).await?;
        let c = campaigns::insert(db, &v.id, spec).await?;
        plans::insert(db, &c.id, &plan).await?;
    }
    Ok(true)
}
