mod generic;
mod refine;
mod supply;

use super::DpIdentConfig;
use crate::simulation::dp_ship::{DpRun, DpShip, TrialConfig, paper, simulate_campaign};

/// The supply vessel's truth, its trial settings, the paper's six
/// manoeuvres (N = 2 per stage, 600 samples) flown with seed `seed`, and the
/// EKF configuration a user would pick.
fn supply_campaign(seed: u64) -> (DpShip, TrialConfig, Vec<DpRun>, DpIdentConfig) {
    let truth = DpShip::supply_vessel();
    let trial = TrialConfig::supply_vessel();
    let runs = simulate_campaign(&truth, &trial, paper::SAMPLES_PER_RUN, seed);
    let cfg = DpIdentConfig::supply_vessel(&trial);
    (truth, trial, runs, cfg)
}
