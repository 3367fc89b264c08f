//! A planned DP campaign flown by a DP ship truth and logged as the vessel's
//! logger would: the counterpart of [`crate::simulation::trials`] for
//! DP (Dp3) profiles.
//!
//! Each planned experiment's input schedule — thruster commands `thr_1 …
//! thr_r` (normalized, u = |p|·p, eq. 5) or forces `tau_X, tau_Y, tau_N`
//! for a vessel that logs τ, through the ship's T — drives the momentum-form ship of [`super::model`] open
//! loop from rest, with a slowly varying bias b_h and position/heading noise
//! ([`super::trial::simulate_trial`], eq. 35–37, 44–45). The ship works in
//! the Bis system of the profile's [`DpPrior`]; the log is SI: `t` (s),
//! the inputs, `u v r` (m/s, rad/s, with a little white noise), `x y` (m) and
//! `psi` (rad, wrapped to (−π, π] like a gyro compass).

use nalgebra::DMatrix;

use super::manoeuvres::Manoeuvre;
use super::model::DpShip;
use super::trial::{DpRun, TrialConfig, simulate_trial};
use crate::logs::schema::{LogRole, input_columns, required_columns};
use crate::planning::vessel::{DpPrior, VesselKind};
use crate::planning::{Experiment, ExperimentFamily, Plan, PlannedExperiment, VesselProfile};
use crate::simulation::trials::{TrialError, run_seed, wrap_pi};

/// Noise and disturbance of a flown DP campaign.
#[derive(Debug, Clone, PartialEq)]
pub struct DpFlightSettings {
    /// Bias (Bis forces) and measurement noise; its `h` is replaced by the
    /// profile's controller interval in Bis time.
    pub trial: TrialConfig,
    /// Standard deviation of the logged surge and sway velocities (m/s).
    pub velocity_noise_mps: f64,
    /// Standard deviation of the logged yaw rate (rad/s).
    pub yaw_rate_noise_rps: f64,
    /// Campaign seed; run `seq` uses [`run_seed`]`(seed, seq)`.
    pub seed: u64,
}

impl DpFlightSettings {
    /// The supply vessel's trials ([`TrialConfig::supply_vessel`]: 1 m
    /// position, 0.2° heading noise, a bias of a few percent of full thrust).
    pub fn supply_vessel(seed: u64) -> Self {
        DpFlightSettings {
            trial: TrialConfig::supply_vessel(),
            velocity_noise_mps: 0.05,
            yaw_rate_noise_rps: 0.001,
            seed,
        }
    }
}

/// One flown DP experiment.
#[derive(Debug, Clone, PartialEq)]
pub struct FlownDpRun {
    /// Position in the run order.
    pub seq: u32,
    /// Experiment code.
    pub code: String,
    /// Family.
    pub family: ExperimentFamily,
    /// The simulated run in Bis units, with the truth.
    pub run: DpRun,
    /// The log as uploaded (SI).
    pub csv: String,
}

/// The manoeuvre (and so the initial heading of the paper's figures) a
/// family flies; the validation run starts like the azimuth test, at 0°.
fn manoeuvre(family: ExperimentFamily) -> Manoeuvre {
    match family {
        ExperimentFamily::DpSurge => Manoeuvre::Surge,
        ExperimentFamily::DpSwayYaw => Manoeuvre::SwayYaw,
        _ => Manoeuvre::Azimuth,
    }
}

fn prior(profile: &VesselProfile) -> Result<&DpPrior, TrialError> {
    profile
        .validate()
        .map_err(|e| TrialError::invalid(format!("profile.{}", e.field), e.to_string()))?;
    if profile.kind != VesselKind::Dp3 {
        return Err(TrialError::invalid(
            "profile.kind",
            "only DP vessels are flown by the DP ship truth",
        ));
    }
    if profile.logger_rate_hz != profile.controller_rate_hz {
        return Err(TrialError::invalid(
            "profile.logger_rate_hz",
            "the DP ship truth logs at the controller rate",
        ));
    }
    profile.dp_prior.as_ref().ok_or_else(|| {
        TrialError::invalid(
            "profile.dp_prior",
            "the Bis length scale L is needed to fly a DP ship",
        )
    })
}

/// Flies one planned DP experiment with `ship` (Bis units) and logs it for
/// `profile`.
pub fn fly_dp_experiment(
    profile: &VesselProfile,
    ship: &DpShip,
    planned: &PlannedExperiment,
    settings: &DpFlightSettings,
    seed: u64,
) -> Result<FlownDpRun, TrialError> {
    let prior = prior(profile)?;
    let ex = &planned.experiment;
    let s = &planned.schedule;
    let n = s.len();
    let inputs = input_columns(profile);
    if inputs.len() != ship.k.len() {
        return Err(TrialError::invalid(
            "profile.inputs",
            format!(
                "the profile has {} input columns and the ship's T has {}",
                inputs.len(),
                ship.k.len()
            ),
        ));
    }
    let mut u = DMatrix::zeros(n, inputs.len());
    for (j, name) in inputs.iter().enumerate() {
        let col = s.columns.iter().position(|c| c == name).ok_or_else(|| {
            TrialError::invalid(
                format!("plan.{}.schedule", ex.code),
                format!("no column '{name}'"),
            )
        })?;
        for k in 0..n {
            u[(k, j)] = s.values[col][k];
        }
    }
    let h_s = 1.0 / s.sample_rate_hz;
    let trial = TrialConfig {
        h: h_s / prior.time_unit_s(),
        ..settings.trial.clone()
    };
    let kind = manoeuvre(ex.family);
    let eta0 = [0.0, 0.0, kind.initial_heading()];
    let run = simulate_trial(ship, kind, &u, eta0, &trial, seed);
    let csv = dp_csv(profile, prior, &run, h_s, settings, seed);
    Ok(FlownDpRun {
        seq: ex.seq,
        code: ex.code.clone(),
        family: ex.family,
        run,
        csv,
    })
}

/// Flies every experiment of `plan` that `filter` accepts, in run order.
pub fn fly_dp_campaign(
    profile: &VesselProfile,
    ship: &DpShip,
    plan: &Plan,
    settings: &DpFlightSettings,
    filter: impl Fn(&Experiment) -> bool,
) -> Result<Vec<FlownDpRun>, TrialError> {
    plan.experiments
        .iter()
        .filter(|p| filter(&p.experiment))
        .map(|p| {
            fly_dp_experiment(
                profile,
                ship,
                p,
                settings,
                run_seed(settings.seed, p.experiment.seq),
            )
        })
        .collect()
}

/// The SI log of a run in the profile's single-file columns.
fn dp_csv(
    profile: &VesselProfile,
    prior: &DpPrior,
    run: &DpRun,
    h_s: f64,
    settings: &DpFlightSettings,
    seed: u64,
) -> String {
    let (l, v, t) = (
        prior.length_m,
        prior.velocity_unit_mps(),
        prior.time_unit_s(),
    );
    let mut rng = crate::rng::SplitMix64::new(crate::rng::mix(seed ^ 0x5eed));
    let cols = required_columns(profile, LogRole::Single, None);
    let inputs = input_columns(profile);
    // A turning azimuth is held at the angle of its column of T″ (the one
    // it is flown with), logged in its declared unit.
    let held_angles: Vec<(String, f64)> = planned_azimuth_angles(profile);
    let mut out = cols.join(",");
    out.push('\n');
    for k in 0..run.t.len() {
        let mut row = Vec::with_capacity(cols.len());
        for c in &cols {
            let val = match c.as_str() {
                "t" => k as f64 * h_s,
                "u" => run.nu[(k, 0)] * v + settings.velocity_noise_mps * rng.normal(),
                "v" => run.nu[(k, 1)] * v + settings.velocity_noise_mps * rng.normal(),
                "r" => run.nu[(k, 2)] / t + settings.yaw_rate_noise_rps * rng.normal(),
                "x" => run.eta[(k, 0)] * l,
                "y" => run.eta[(k, 1)] * l,
                "psi" => wrap_pi(run.eta[(k, 2)]),
                input => match held_angles.iter().find(|(c, _)| c == input) {
                    Some(&(_, alpha)) => alpha,
                    None => inputs
                        .iter()
                        .position(|c| c == input)
                        .map_or(0.0, |j| run.u[(k, j)]),
                },
            };
            row.push(val.to_string());
        }
        out.push_str(&row.join(","));
        out.push('\n');
    }
    out
}

/// Column `azi_j` and the angle (in its declared unit) of each azimuth that
/// logs its angle, at the angle of its column of T″: atan2(T″_2j, T″_1j).
fn planned_azimuth_angles(profile: &VesselProfile) -> Vec<(String, f64)> {
    let crate::planning::vessel::InputChannels::Thrusters {
        thrusters,
        configuration,
    } = &profile.inputs
    else {
        return Vec::new();
    };
    thrusters
        .iter()
        .enumerate()
        .filter_map(|(j, th)| {
            let a = th.logged_angle?;
            let alpha = configuration[1][j].atan2(configuration[0][j]);
            let alpha = alpha / a.unit.radians();
            Some((crate::logs::schema::azimuth_angle_column(j + 1), alpha))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::planning::examples::{supply_vessel, supply_vessel_campaign};
    use crate::planning::generate_plan;

    #[test]
    fn planned_manoeuvres_fly_to_si_logs() {
        let profile = supply_vessel();
        let plan = generate_plan(&profile, &supply_vessel_campaign(7)).unwrap();
        let ship = DpShip::supply_vessel();
        let runs = fly_dp_campaign(
            &profile,
            &ship,
            &plan,
            &DpFlightSettings::supply_vessel(3),
            |_| true,
        )
        .unwrap();
        assert_eq!(runs.len(), plan.experiments.len());
        let surge = runs
            .iter()
            .find(|r| r.family == ExperimentFamily::DpSurge)
            .unwrap();
        let mut lines = surge.csv.lines();
        assert_eq!(
            lines.next().unwrap(),
            "t,thr_1,thr_2,thr_3,thr_4,thr_5,thr_6,u,v,r,x,y,psi"
        );
        // Surge moves the ship by tens to hundreds of metres.
        let last: Vec<f64> = surge
            .csv
            .lines()
            .last()
            .unwrap()
            .split(',')
            .map(|v| v.parse().unwrap())
            .collect();
        assert_eq!(last[0], (surge.run.t.len() - 1) as f64);
        let travelled = (last[10].powi(2) + last[11].powi(2)).sqrt();
        assert!(travelled > 50.0, "{travelled} m");
        assert!(
            last[12].abs() <= std::f64::consts::PI,
            "ψ wrapped like a compass"
        );
        // Same seed, same log; the other profile kind is refused.
        let again = fly_dp_experiment(
            &profile,
            &ship,
            &plan.experiments[0],
            &DpFlightSettings::supply_vessel(3),
            run_seed(3, plan.experiments[0].experiment.seq),
        )
        .unwrap();
        assert_eq!(again.csv, runs[0].csv);
        let rov = crate::planning::examples::surveyor_rov();
        let e = fly_dp_experiment(
            &rov,
            &ship,
            &plan.experiments[0],
            &DpFlightSettings::supply_vessel(3),
            1,
        )
        .unwrap_err();
        assert_eq!(e.field(), "profile.kind");
    }
}
