//! The demo a newcomer clicks through: the Surveyor ROV on the thesis's grid
//! and Fossen's supply vessel with its three decoupled DP manoeuvres, each
//! with a campaign and a generated plan. Seeded only into an empty database.

use seatrial_core::planning::campaign::{Durations, Excitation};
use seatrial_core::planning::examples::{supply_vessel, surveyor_rov};
use seatrial_core::planning::{
    CampaignSpec, ExperimentFamily, SpeedGrid, SpeedUnit, generate_plan,
};

use crate::storage::{Db, campaigns, plans, vessels};

/// The ROV demo campaign: grid {0.5, …, 3.5} kn (4.0 kn proved unsafe, thesis sec. 1.6).
pub fn rov_campaign() -> CampaignSpec {
    CampaignSpec {
        name: "Surveyor ROV – LPV campaign 0.5–3.5 kn".into(),
        grid: SpeedGrid {
            unit: SpeedUnit::Knots,
            speeds: vec![0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5],
        },
        families: vec![
            ExperimentFamily::Static,
            ExperimentFamily::Dynamic,
            ExperimentFamily::Recursive,
            ExperimentFamily::Validation,
        ],
        repetitions: Some(1),
        excitation: Excitation::default(),
        durations: Durations::default(),
        seed: 2026,
    }
}

/// The DP demo campaign: the three decoupled manoeuvres, N = 2 each.
pub fn dp_campaign() -> CampaignSpec {
    CampaignSpec {
        name: "Supply vessel – decoupled DP manoeuvres SI1→SI2→SI3".into(),
        grid: SpeedGrid {
            unit: SpeedUnit::MetersPerSecond,
            speeds: vec![0.0],
        },
        families: vec![
            ExperimentFamily::DpSurge,
            ExperimentFamily::DpSwayYaw,
            ExperimentFamily::DpAzimuth,
            ExperimentFamily::Validation,
        ],
        repetitions: Some(2),
        excitation: Excitation::default(),
        durations: Durations {
            validation_s: 600.0,
            ..Durations::default()
        },
        seed: 1995,
    }
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
