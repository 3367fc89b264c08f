//! A simulated sea-trial campaign: every planned experiment of a
//! [`Plan`](crate::planning::Plan) flown by the ROV truth ([`RovTruth`]) and
//! logged the way the vessel's logger would, so the demo and the end-to-end
//! tests can upload realistic logs.
//!
//! # How a run is flown
//!
//! The schedule holds references at the controller rate f_c. Per modeled DOF:
//!
//! - `u_ref … r_ref`: a velocity reference ν_ref,i flown by the vessel's
//!   controller, a PI per DOF ([`VelocityPi`]) at f_c producing the
//!   commanded τ_i, slew-limited to the profile's `max_force_rate` and
//!   clipped to `max_force`;
//! - `phi_ref`, `theta_ref`: a roll or pitch attitude held by an attitude
//!   loop that feeds the velocity PI its rate reference ([`AttitudeLoop`]);
//! - `tau_X … tau_N`: an open-loop force, applied as scheduled (clipped to
//!   `max_force`).
//!
//! DOFs the profile does not model get τ = 0 (left passive) and are not
//! logged. Thruster-actuated (DP) profiles are flown by
//! [`super::dp_ship::fly`].
//!
//! The controller feeds back ν over ground as the navigation filter would
//! estimate it: noise-free by default ([`Feedback::True`]), or with the
//! sensors' white noise drawn at every controller sample
//! ([`Feedback::Measured`]); the logger records τ commanded, ν and η at the
//! logger rate f_l = f_c / D (D a whole number) with seeded white
//! measurement noise (with measured feedback: what the controller read). Before t = 0 the vessel flies a lead-in holding the
//! first references, so a run starts trimmed at its operating point, as after
//! the set-up time between runs.
//!
//! The plant is integrated exactly as [`RovTruth::simulate`] does (RK4,
//! τ held over each controller interval, the same actuators and current); a
//! test replays the commanded τ through `simulate` and finds the same
//! trajectory.

use nalgebra::{DMatrix, Vector3, Vector6};

use super::integrate::rk4_step;
use super::rov::current::CurrentProcess;
use super::rov::kinematics::rotation;
use super::rov::{RovRecord, RovTruth, SimError};
use crate::logs::schema::{LogRole, TIME_COLUMN, pose_column, required_columns};
use crate::planning::statics::{attitude_column, holds_attitude};
use crate::planning::vessel::{InputChannels, VesselKind};
use crate::planning::{Dof, Experiment, ExperimentFamily, Plan, PlannedExperiment, VesselProfile};
use crate::rng::{SplitMix64, mix};

mod control;
mod settings;
pub use control::{
    ATTITUDE_TIME_CONSTANTS, AttitudeLoop, BANDWIDTH_PER_TIME_CONSTANT, DeclaredAutopilot,
    Setpoint, VelocityPi,
};
pub use settings::{Feedback, MeasurementNoise, TrialError, TrialSettings};

/// Default lead-in in units of the largest modeled time constant T̂ (≈ 99 %
/// settled).
pub const LEAD_IN_TIME_CONSTANTS: f64 = 5.0;
/// Smallest |cos θ| before the Euler-angle kinematics counts as singular
/// (as in [`RovTruth::simulate`]).
const COS_THETA_MIN: f64 = 1e-6;

/// What drives one DOF during a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Drive {
    /// Velocity reference ν_ref flown by the PI (schedule column index).
    Velocity(usize),
    /// Open-loop τ (schedule column index).
    Force(usize),
    /// Roll or pitch attitude reference η_ref (schedule column index),
    /// flown by the attitude loop ([`AttitudeLoop`]) over the velocity PI.
    Attitude(usize),
    /// Not modeled: τ = 0.
    Passive,
}

/// One flown experiment.
#[derive(Debug, Clone, PartialEq)]
pub struct FlownRun {
    /// Position in the run order, from 1.
    pub seq: u32,
    /// Experiment code, e.g. `DYN-1.5kn-sway-r1`.
    pub code: String,
    /// Family.
    pub family: ExperimentFamily,
    /// Grid speed (m/s); none for the validation run.
    pub grid_speed_mps: Option<f64>,
    /// How each DOF (index `Dof::index()`) was driven.
    pub drives: [Drive; 6],
    /// ν_ref at the logged samples (N × 6; an attitude loop's rate
    /// reference where attitude-driven, zero where force-driven).
    pub nu_ref: DMatrix<f64>,
    /// The logged run at the logger rate, with the noise-free truth.
    pub record: RovRecord,
    /// The log as uploaded: the profile's single-file columns
    /// ([`required_columns`]) in the project's CSV convention.
    pub csv: String,
}

/// Flies one planned experiment with `truth` and logs it for `profile`.
pub fn fly_experiment(
    profile: &VesselProfile,
    truth: &RovTruth,
    planned: &PlannedExperiment,
    settings: &TrialSettings,
) -> Result<FlownRun, TrialError> {
    let ex = &planned.experiment;
    let sim_err = |source| TrialError::Simulation {
        code: ex.code.clone(),
        source,
    };
    check_profile(profile)?;
    settings.validate()?;
    truth.validate().map_err(sim_err)?;
    let drives = drives(profile, planned)?;
    let sched = &planned.schedule;
    let fc = profile.controller_rate_hz;
    let h = 1.0 / fc;
    let decimation = decimation(profile)?;

    let full = sched.len();
    let n_run = match settings.max_duration_s {
        Some(m) => full.min(((m * fc) + 1e-9).floor() as usize + 1),
        None => full,
    };
    let t_max = profile
        .dofs
        .iter()
        .map(|&d| profile.limit(d).time_constant_s)
        .fold(0.0, f64::max);
    let lead_in = settings.lead_in_s.unwrap_or(LEAD_IN_TIME_CONSTANTS * t_max);
    let n_lead = (lead_in * fc).round() as usize;
    let n = n_lead + n_run;
    let reference = |c: usize, k: usize| sched.values[c][k.saturating_sub(n_lead)];

    let mut pis: Vec<Option<VelocityPi>> = Dof::ALL
        .iter()
        .map(|&d| match drives[d.index()] {
            Drive::Velocity(_) | Drive::Attitude(_) => {
                Some(VelocityPi::design(profile.limit(d), h))
            }
            _ => None,
        })
        .collect();

    let attitude: Vec<Option<AttitudeLoop>> = Dof::ALL
        .iter()
        .map(|&d| match drives[d.index()] {
            Drive::Attitude(_) => Some(AttitudeLoop::design(profile.limit(d))),
            _ => None,
        })
        .collect();

    // The vessel's own autopilot, when the profile declares one, flies
    // instead of the loops above.
    let mut declared = DeclaredAutopilot::of(profile, h);

    // Plant: the truth's own right-hand side.
    let mut f = truth.plant().map_err(sim_err)?;
    let acts = &truth.actuators;
    let lagged: [bool; 6] = std::array::from_fn(|i| acts.lagged(i));

    // Start at the first velocity references (trimmed at the grid speed).
    let mut current = CurrentProcess::new(&truth.current);
    let mut nu0 = Vector6::zeros();
    for (i, d) in drives.iter().enumerate() {
        if let Drive::Velocity(c) = d {
            nu0[i] = reference(*c, 0);
        }
    }
    let eta0 = Vector6::zeros();
    let nu_r0 = nu0 - body_current(&eta0, &current.ned());
    let mut x = [0.0; 18];
    x[0..6].copy_from_slice(nu_r0.as_slice());

    let n_log = n_run.div_ceil(decimation);
    let mut rec = RovRecord::zeros(n_log, h * decimation as f64);
    let mut nu_ref = DMatrix::zeros(n_log, 6);
    let mut tau_cmd = DMatrix::zeros(n, 6);
    let h_int = h / settings.substeps as f64;
    let mut u = [0.0; 9];
    let measured = settings.feedback == Feedback::Measured;
    let mut sensor = SplitMix64::new(mix(settings.seed ^ 0x5E45_0F0B));
    for k in 0..n {
        let eta = Vector6::from_column_slice(&x[6..12]);
        let v_ned = current.ned();
        let nu = Vector6::from_column_slice(&x[0..6]) + body_current(&eta, &v_ned);
        // What the controller reads: the truth, or the sensors.
        let (nu_m, eta_m) = if measured {
            let mut nu_m = nu;
            let mut eta_m = eta;
            for i in 0..6 {
                nu_m[i] += settings.noise.nu[i] * sensor.normal();
            }
            for i in 0..6 {
                eta_m[i] += settings.noise.eta[i] * sensor.normal();
            }
            eta_m[5] = wrap_pi(eta_m[5]);
            (nu_m, eta_m)
        } else {
            (nu, eta)
        };
        let mut rate_ref = [0.0; 6];
        // The declared autopilot's τ and rate references, when it flies.
        let declared_tau = match declared.as_mut() {
            Some(ap) => {
                let setpoints: [Setpoint; 6] = std::array::from_fn(|i| match drives[i] {
                    Drive::Velocity(c) => Setpoint::Velocity(reference(c, k)),
                    Drive::Attitude(c) => Setpoint::Attitude(reference(c, k)),
                    Drive::Force(_) | Drive::Passive => Setpoint::Idle,
                });
                let (tau, rate) = ap.step(&setpoints, &nu_m.into(), &eta_m.into(), k >= n_lead);
                rate_ref = rate;
                Some(tau)
            }
            None => None,
        };
        for (i, d) in drives.iter().enumerate() {
            if declared_tau.is_none() {
                rate_ref[i] = match (*d, &attitude[i]) {
                    (Drive::Velocity(c), _) => reference(c, k),
                    (Drive::Attitude(c), Some(a)) => a.rate_reference(reference(c, k), eta_m[i]),
                    _ => 0.0,
                };
            }
            tau_cmd[(k, i)] = match (*d, &declared_tau) {
                (Drive::Force(c), _) => {
                    let l = profile.limit(Dof::ALL[i]).max_force;
                    reference(c, k).clamp(-l, l)
                }
                (Drive::Passive, _) => 0.0,
                (_, Some(tau)) => tau[i].unwrap_or(0.0),
                (_, None) => pis[i]
                    .as_mut()
                    .map_or(0.0, |pi| pi.step(rate_ref[i], nu_m[i])),
            };
        }
        let shaped = acts.shaped(&tau_cmd, k);
        if k >= n_lead && (k - n_lead).is_multiple_of(decimation) {
            let j = (k - n_lead) / decimation;
            for i in 0..6 {
                rec.nu_true[(j, i)] = nu[i];
                rec.eta_true[(j, i)] = eta[i];
                rec.nu[(j, i)] = nu_m[i];
                rec.eta[(j, i)] = eta_m[i];
                rec.tau_commanded[(j, i)] = tau_cmd[(k, i)];
                rec.tau_applied[(j, i)] = if lagged[i] { x[12 + i] } else { shaped[i] };
                nu_ref[(j, i)] = rate_ref[i];
            }
            for i in 0..3 {
                rec.current_ned[(j, i)] = v_ned[i];
            }
        }
        if k + 1 == n {
            break;
        }
        u[0..6].copy_from_slice(&shaped);
        for _ in 0..settings.substeps {
            u[6..9].copy_from_slice(current.ned().as_slice());
            rk4_step(&mut f, &mut x, &u, h_int);
            current.advance(h_int);
        }
        let t = (k as f64 + 1.0 - n_lead as f64) * h;
        if !x.iter().all(|v| v.is_finite()) {
            return Err(sim_err(SimError::Diverged {
                t,
                reason: "the state is no longer finite (unstable parameters or too coarse an internal step)",
            }));
        }
        if x[10].cos().abs() < COS_THETA_MIN {
            return Err(sim_err(SimError::Diverged {
                t,
                reason: "pitch reached ±90°, where the Euler-angle kinematics T(Θ) is singular",
            }));
        }
    }

    // Measurement noise (with true feedback; with measured feedback the log
    // already holds what the sensors read): 12 draws per logged sample in a
    // fixed order (ν then η), as RovTruth::simulate draws them; the measured
    // heading is wrapped to (−π, π] like a compass's.
    if !measured {
        let mut rng = SplitMix64::new(settings.seed);
        rec.nu.copy_from(&rec.nu_true);
        rec.eta.copy_from(&rec.eta_true);
        for k in 0..n_log {
            for i in 0..6 {
                rec.nu[(k, i)] += settings.noise.nu[i] * rng.normal();
            }
            for i in 0..6 {
                rec.eta[(k, i)] += settings.noise.eta[i] * rng.normal();
            }
            rec.eta[(k, 5)] = wrap_pi(rec.eta[(k, 5)]);
        }
    }
    let csv = profile_csv(profile, &rec);
    Ok(FlownRun {
        seq: ex.seq,
        code: ex.code.clone(),
        family: ex.family,
        grid_speed_mps: ex.grid_speed_mps,
        drives,
        nu_ref,
        record: rec,
        csv,
    })
}

/// Flies every experiment of `plan` that `filter` accepts, in run order.
/// Run `seq` uses the noise seed mix(`settings.seed` ⊕ mix(seq)), so runs
/// carry independent noise and a campaign is reproducible from one seed.
pub fn fly_campaign(
    profile: &VesselProfile,
    truth: &RovTruth,
    plan: &Plan,
    settings: &TrialSettings,
    filter: impl Fn(&Experiment) -> bool,
) -> Result<Vec<FlownRun>, TrialError> {
    plan.experiments
        .iter()
        .filter(|p| filter(&p.experiment))
        .map(|p| {
            let s = TrialSettings {
                seed: run_seed(settings.seed, p.experiment.seq),
                ..*settings
            };
            fly_experiment(profile, truth, p, &s)
        })
        .collect()
}

/// Noise seed of run `seq` in [`fly_campaign`].
pub fn run_seed(seed: u64, seq: u32) -> u64 {
    mix(seed ^ mix(u64::from(seq)))
}

fn check_profile(profile: &VesselProfile) -> Result<(), TrialError> {
    profile
        .validate()
        .map_err(|e| TrialError::invalid(format!("profile.{}", e.field), e.to_string()))?;
    if profile.kind != VesselKind::Rov6 {
        return Err(TrialError::invalid(
            "profile.kind",
            "only ROV profiles are flown by the ROV truth; DP vessels need their own simulator",
        ));
    }
    if !matches!(profile.inputs, InputChannels::GeneralizedForces) {
        return Err(TrialError::invalid(
            "profile.inputs",
            "the ROV truth takes generalized forces τ; thruster-command profiles are not supported",
        ));
    }
    Ok(())
}

/// Logger decimation D = f_c / f_l, a whole number ≥ 1.
fn decimation(profile: &VesselProfile) -> Result<usize, TrialError> {
    let ratio = profile.controller_rate_hz / profile.logger_rate_hz;
    if ratio >= 1.0 - 1e-9 && (ratio - ratio.round()).abs() < 1e-9 {
        Ok(ratio.round() as usize)
    } else {
        Err(TrialError::invalid(
            "profile.logger_rate_hz",
            format!(
                "the controller rate ({} Hz) must be a whole multiple of the logger rate ({} Hz) to log it",
                profile.controller_rate_hz, profile.logger_rate_hz
            ),
        ))
    }
}

/// Which schedule column drives each DOF.
fn drives(profile: &VesselProfile, planned: &PlannedExperiment) -> Result<[Drive; 6], TrialError> {
    let s = &planned.schedule;
    if (s.sample_rate_hz - profile.controller_rate_hz).abs() > 1e-9 * profile.controller_rate_hz {
        return Err(TrialError::invalid(
            "schedule.sample_rate_hz",
            format!(
                "the schedule is sampled at {} Hz but the controller runs at {} Hz",
                s.sample_rate_hz, profile.controller_rate_hz
            ),
        ));
    }
    if s.columns.len() != s.values.len() {
        return Err(TrialError::invalid(
            "schedule.values",
            format!(
                "{} columns named but {} sampled",
                s.columns.len(),
                s.values.len()
            ),
        ));
    }
    let n = s.len();
    if n == 0 {
        return Err(TrialError::invalid(
            "schedule.values",
            "the schedule is empty",
        ));
    }
    let mut out = [Drive::Passive; 6];
    for (c, name) in s.columns.iter().enumerate() {
        let field = format!("schedule.columns[{c}]");
        let drive = Dof::ALL.iter().find_map(|&d| {
            if *name == format!("{}_ref", d.velocity_symbol()) {
                Some((d, Drive::Velocity(c)))
            } else if holds_attitude(d) && name == attitude_column(d) {
                Some((d, Drive::Attitude(c)))
            } else if name == d.force_column() {
                Some((d, Drive::Force(c)))
            } else {
                None
            }
        });
        let Some((d, drive)) = drive else {
            return Err(TrialError::invalid(
                field,
                format!(
                    "'{name}' is neither a velocity reference (u_ref…r_ref), an attitude reference (phi_ref, theta_ref) nor a force (tau_X…tau_N)"
                ),
            ));
        };
        if !profile.dofs.contains(&d) {
            return Err(TrialError::invalid(
                field,
                format!(
                    "'{name}' drives {}, which the profile does not model",
                    d.name()
                ),
            ));
        }
        if out[d.index()] != Drive::Passive {
            return Err(TrialError::invalid(
                field,
                format!("{} is driven by two columns", d.name()),
            ));
        }
        if s.values[c].len() != n {
            return Err(TrialError::invalid(
                format!("schedule.values[{c}]"),
                format!(
                    "{} samples, but the first column has {n}",
                    s.values[c].len()
                ),
            ));
        }
        if let Some(k) = s.values[c].iter().position(|v| !v.is_finite()) {
            return Err(TrialError::invalid(
                format!("schedule.values[{c}][{k}]"),
                "must be a finite number",
            ));
        }
        out[d.index()] = drive;
    }
    if let Some(d) = profile
        .dofs
        .iter()
        .find(|d| out[d.index()] == Drive::Passive)
    {
        return Err(TrialError::invalid(
            "schedule.columns",
            format!("no reference for the modeled DOF {}", d.name()),
        ));
    }
    Ok(out)
}

/// ν_c = [Rᵀ(Θ) V_c; 0₃].
fn body_current(eta: &Vector6<f64>, v_ned: &Vector3<f64>) -> Vector6<f64> {
    let v = rotation(eta[3], eta[4], eta[5]).transpose() * v_ned;
    Vector6::new(v.x, v.y, v.z, 0.0, 0.0, 0.0)
}

pub(crate) fn wrap_pi(a: f64) -> f64 {
    let w = a.rem_euclid(std::f64::consts::TAU);
    if w > std::f64::consts::PI {
        w - std::f64::consts::TAU
    } else {
        w
    }
}

/// The single-file log of `profile`'s columns, numbers in Rust's shortest
/// round-trip form (as [`RovRecord::to_csv`]).
fn profile_csv(profile: &VesselProfile, rec: &RovRecord) -> String {
    let cols = required_columns(profile, LogRole::Single, None);
    let source: Vec<(&DMatrix<f64>, usize)> = cols
        .iter()
        .skip(1)
        .filter_map(|c| {
            Dof::ALL.iter().find_map(|&d| {
                if c == d.force_column() {
                    Some((&rec.tau_commanded, d.index()))
                } else if c == d.velocity_symbol() {
                    Some((&rec.nu, d.index()))
                } else if c == pose_column(d) {
                    Some((&rec.eta, d.index()))
                } else {
                    None
                }
            })
        })
        .collect();
    debug_assert_eq!(cols.first().map(String::as_str), Some(TIME_COLUMN));
    let mut out = cols.join(",");
    out.push('\n');
    for k in 0..rec.len() {
        out.push_str(&rec.t[k].to_string());
        for (m, i) in &source {
            out.push(',');
            out.push_str(&m[(k, *i)].to_string());
        }
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests;
