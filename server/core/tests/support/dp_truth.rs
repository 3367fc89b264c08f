//! The parallel EKF campaign graded on the independent DP ship of
//! `seatrial-truth` (`dp_ship`: the supply vessel of Fossen et al. 1995 in
//! its own code), logged position-only at 1 Hz (t, thr_1 … thr_6, x, y, ψ)
//! and parsed like an upload. Nothing here is shared with the estimator but
//! the CSV parser.

#![allow(dead_code)]

use seatrial_core::estimation::NoProgress;
use seatrial_core::identification::outcome::Identified;
use seatrial_core::identification::{
    EkfCampaignSettings, ModelDocument, RunInput, identify_ekf_campaign,
};
use seatrial_core::logs::{LogRole, ParseOptions, parse_log, to_uniform};
use seatrial_core::planning::VesselProfile;
use seatrial_core::planning::campaign::ExperimentFamily;
use seatrial_truth::dp_ship::{self, DpManoeuvre, DpTrial, fly_dp_campaign};

fn family(m: DpManoeuvre) -> ExperimentFamily {
    match m {
        DpManoeuvre::Surge => ExperimentFamily::DpSurge,
        DpManoeuvre::SwayYaw => ExperimentFamily::DpSwayYaw,
        DpManoeuvre::Azimuth => ExperimentFamily::DpAzimuth,
        DpManoeuvre::Validation => ExperimentFamily::Validation,
    }
}

/// The campaign of `trial` and `seed`, flown by the truth and parsed as
/// uploads for `profile`.
pub fn runs(profile: &VesselProfile, trial: &DpTrial, seed: u64) -> Vec<RunInput> {
    parsed(profile, fly_dp_campaign(trial, seed))
}

/// The truth's logs parsed as uploads for `profile`.
pub fn parsed(profile: &VesselProfile, logs: Vec<dp_ship::DpLog>) -> Vec<RunInput> {
    logs.into_iter()
        .map(|log| {
            let parsed = parse_log(
                log.csv.as_bytes(),
                &ParseOptions::for_vessel(profile, LogRole::Single, None),
            )
            .expect("a position-only DP log is accepted");
            let (mut record, _) = to_uniform(&parsed.table, None).unwrap();
            // As the service loads a run: logged shaft speeds → commands.
            let reading = seatrial_core::logs::read_thruster_commands(profile, &mut record);
            assert!(reading.warnings.is_empty(), "{:?}", reading.warnings);
            RunInput {
                run_id: log.name.clone(),
                name: log.name,
                family: Some(family(log.manoeuvre)),
                grid_speed_mps: Some(0.0),
                excited_dofs: vec![],
                record,
            }
        })
        .collect()
}

/// The campaign identified with `settings`, with its held-out validation.
pub fn identify_validated(
    profile: &VesselProfile,
    runs: &[RunInput],
    settings: &EkfCampaignSettings,
) -> Identified {
    identify_ekf_campaign(
        profile,
        &seatrial_core::logs::commanded_columns(profile),
        runs,
        settings,
        &mut NoProgress,
    )
    .unwrap()
}

/// The model document of the campaign identified with `settings`.
pub fn identify(
    profile: &VesselProfile,
    runs: &[RunInput],
    settings: &EkfCampaignSettings,
) -> ModelDocument {
    identify_validated(profile, runs, settings).document
}

/// The truth's θ″ (eq. 48–49): A″_h entries, then K″1, K″3, K″5, K″6.
pub fn truth() -> [f64; 9] {
    let (a, k) = (dp_ship::A_H, dp_ship::K);
    [
        a[0][0], a[1][1], a[1][2], a[2][1], a[2][2], k[0], k[2], k[4], k[5],
    ]
}
