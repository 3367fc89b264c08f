//! What a parallel-EKF identification needs, checked from what is known
//! about its runs before any log is read — so a job that cannot run is
//! refused when it is submitted, naming what is missing: the vessel
//! profile (L, thruster layout), the pose channels x, y, ψ the EKF measures
//! (eq. 39), the thruster columns of the profile's layout, a held-out run,
//! and a run of every manoeuvre SI1–SI3 (Fossen et al. 1995, sec. 4.2).

use super::ekf_campaign::{EKF_POSE, EkfCampaignSettings, check_ekf_profile};
use super::ekf_layout::is_paper_layout;
use super::ekf_settings::check_settings;
use super::error::IdentifyError;
use super::roles::{held_out, no_validation_run};
use crate::logs::input_columns;
use crate::planning::campaign::ExperimentFamily;
use crate::planning::vessel::VesselProfile;

/// What is known of a run without reading its logs.
#[derive(Debug, Clone, Copy)]
pub struct RunFacts<'a> {
    /// Run id.
    pub run_id: &'a str,
    /// Run name.
    pub name: &'a str,
    /// The family it counts as.
    pub family: Option<ExperimentFamily>,
    /// The channels of its record, when the upload recorded them.
    pub channels: Option<&'a [String]>,
}

/// The stage (0–2: SI1 surge, SI2 sway–yaw, SI3 azimuth) of an estimation
/// run of `family`, or the error naming the run.
pub fn stage_of(run_id: &str, family: Option<ExperimentFamily>) -> Result<usize, IdentifyError> {
    match family {
        Some(ExperimentFamily::DpSurge) => Ok(0),
        Some(ExperimentFamily::DpSwayYaw) => Ok(1),
        Some(ExperimentFamily::DpAzimuth) => Ok(2),
        Some(ExperimentFamily::Static) => Err(IdentifyError::invalid(
            format!("runs[{run_id}]"),
            "a static run has no place in the DP manoeuvres SI1–SI3",
        )),
        _ => Err(IdentifyError::invalid(
            format!("runs[{run_id}]"),
            "the parallel EKF stages runs by their planned DP manoeuvre (dp_surge → SI1, dp_sway_yaw → SI2, dp_azimuth → SI3); this run flew none — hold it out in settings.validation_run_ids or leave it out of run_ids",
        )),
    }
}

/// SI1 and SI2 need a run (they estimate A″_h), SI3 when `need_si3` (the
/// paper's layout, whose azimuth only SI3 drives): `counts` per stage.
pub fn every_stage(counts: &[usize; 3], need_si3: bool) -> Result<(), IdentifyError> {
    let families = ["dp_surge", "dp_sway_yaw", "dp_azimuth"];
    let needed = if need_si3 { 3 } else { 2 };
    match counts[..needed].iter().position(|&c| c == 0) {
        None => Ok(()),
        Some(s) => Err(IdentifyError::invalid(
            "run_ids",
            format!(
                "no {} run for SI{}: every θ″ needs its manoeuvre (Fossen et al. sec. 4.2, N ≥ 2 recommended)",
                families[s],
                s + 1
            ),
        )),
    }
}

/// The channels of `wanted` that `run` lacks.
fn lacking<'a>(run: &RunFacts<'_>, wanted: &'a [String]) -> Vec<&'a str> {
    let Some(have) = run.channels else {
        return Vec::new();
    };
    wanted
        .iter()
        .filter(|w| !have.contains(w))
        .map(String::as_str)
        .collect()
}

/// Checks a parallel-EKF job on `runs` of `profile` with `settings`, in the
/// order profile, settings, held-out runs named, channels, roles.
pub fn check_ekf_job(
    profile: &VesselProfile,
    runs: &[RunFacts<'_>],
    settings: &EkfCampaignSettings,
) -> Result<(), IdentifyError> {
    check_ekf_profile(profile)?;
    check_settings(settings)?;
    let ids = settings.validation_run_ids.as_deref();
    for (i, id) in ids.unwrap_or_default().iter().enumerate() {
        if !runs.iter().any(|r| r.run_id == id) {
            return Err(IdentifyError::invalid(
                format!("settings.validation_run_ids[{i}]"),
                format!("run '{id}' is not among the job's runs"),
            ));
        }
    }
    let pose = EKF_POSE.map(String::from);
    let mut inputs = input_columns(profile);
    inputs.extend(crate::logs::schema::azimuth_angle_columns(profile));
    let mut counts = [0usize; 3];
    let mut validation = 0;
    for r in runs {
        let missing = lacking(r, &pose);
        if !missing.is_empty() {
            return Err(IdentifyError::invalid(
                format!("runs[{}]", r.run_id),
                format!(
                    "run '{}' ({}) has no {}: the parallel EKF measures the pose x, y, ψ (Fossen et al. 1995, eq. 39); a velocity-only log is identified by n4sid",
                    r.name,
                    r.run_id,
                    missing.join(", ")
                ),
            ));
        }
        let missing = lacking(r, &inputs);
        if !missing.is_empty() {
            let logged: Vec<&str> = r
                .channels
                .unwrap_or_default()
                .iter()
                .filter(|c| c.starts_with("thr_") || c.starts_with("tau_"))
                .map(String::as_str)
                .collect();
            return Err(IdentifyError::invalid(
                "vessel.inputs.thrusters",
                format!(
                    "the profile's thruster layout does not match run '{}' ({}): it needs {} and the log has no {} (logged inputs: {})",
                    r.name,
                    r.run_id,
                    inputs.join(", "),
                    missing.join(", "),
                    if logged.is_empty() {
                        "none".to_string()
                    } else {
                        logged.join(", ")
                    }
                ),
            ));
        }
        if held_out(r.run_id, r.family, ids) {
            validation += 1;
        } else {
            counts[stage_of(r.run_id, r.family)?] += 1;
        }
    }
    if validation == 0 {
        return Err(no_validation_run());
    }
    every_stage(&counts, is_paper_layout(profile))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::planning::examples::supply_vessel;
    use ExperimentFamily::*;

    fn facts<'a>(channels: &'a [String]) -> Vec<RunFacts<'a>> {
        [
            ("a", DpSurge),
            ("b", DpSwayYaw),
            ("c", DpAzimuth),
            ("v", Validation),
        ]
        .map(|(id, family)| RunFacts {
            run_id: id,
            name: id,
            family: Some(family),
            channels: Some(channels),
        })
        .to_vec()
    }

    fn columns(names: &str) -> Vec<String> {
        names.split(',').map(String::from).collect()
    }

    #[test]
    fn a_job_that_cannot_run_names_what_is_missing() {
        let p = supply_vessel();
        let s = EkfCampaignSettings::default();
        let full = columns("thr_1,thr_2,thr_3,thr_4,thr_5,thr_6,x,y,psi");
        assert!(check_ekf_job(&p, &facts(&full), &s).is_ok());
        let e = check_ekf_job(&p, &facts(&full)[..3], &s).unwrap_err();
        assert_eq!(e.field(), "settings.validation_run_ids");
        let e = check_ekf_job(&p, &facts(&full)[1..], &s).unwrap_err();
        assert_eq!(e.field(), "run_ids");
        assert!(e.to_string().contains("no dp_surge run for SI1"), "{e}");
        let velocities = columns("thr_1,thr_2,thr_3,thr_4,thr_5,thr_6,u,v,r");
        let e = check_ekf_job(&p, &facts(&velocities), &s).unwrap_err();
        assert_eq!(e.field(), "runs[a]");
        assert!(e.to_string().contains("has no x, y, psi"), "{e}");
        let four = columns("thr_1,thr_2,thr_3,thr_4,x,y,psi");
        let e = check_ekf_job(&p, &facts(&four), &s).unwrap_err();
        assert_eq!(e.field(), "vessel.inputs.thrusters");
        assert!(e.to_string().contains("no thr_5, thr_6"), "{e}");
        let mut bare = supply_vessel();
        bare.dp_prior = None;
        let e = check_ekf_job(&bare, &facts(&full), &s).unwrap_err();
        assert_eq!(e.field(), "vessel.dp_prior.length_m");
        let named = EkfCampaignSettings {
            validation_run_ids: Some(vec!["zz".into()]),
            ..Default::default()
        };
        let e = check_ekf_job(&p, &facts(&full), &named).unwrap_err();
        assert_eq!(e.field(), "settings.validation_run_ids[0]");
    }
}
