//! What a run is, inferred from its data when no plan (and no supervisor)
//! says it: grid speed, excited DOFs, role and excitation signal, each with
//! its reason in words.
//!
//! - **Activity per DOF.** The input τ_j and the velocity ν_j about their
//!   means, each as a fraction of the DOF's scale (velocity: the vessel's
//!   velocity limit, surge: [`SURGE_SCALE_MPS`]; force: the force limit, or
//!   Σ|T_ji|·max command for thruster commands). The score is the geometric
//!   mean of the two: an excited DOF moves both its input and its velocity,
//!   while an open-loop neighbour moves only ν. A DOF is *active* when its
//!   score is above the noise floor [`NOISE_FLOOR`] and it is not *held
//!   against coupling*; it is *excited dynamically* when its velocity also
//!   switches at least twice (Schmitt trigger at mean ± σ/2) and one step
//!   explains less than [`STEP_MAX_SHARE`] of its variance (roll, pitch with
//!   a quiet rate: of its velocity's and of its attitude's), otherwise it was *stepped* once
//!   and held (a static run: a speed, rate or attitude hold).
//! - **Held against coupling.** A closed loop holding a DOF against the
//!   coupling from an excited neighbour moves its input as much as the
//!   excitation moves the neighbour's (more, on a small vehicle), and need
//!   not stop the motion. What tells them apart is the sign of the work the
//!   actuators do: they push an excited DOF along its motion (its input and
//!   velocity correlate positively: they supply what damping dissipates)
//!   and push a held DOF against it (negatively: the controller opposes the
//!   motion the coupling causes). The correlation is taken after a moving
//!   average over [`WORK_WINDOW_S`], which removes the measurement noise a
//!   controller feeds straight back into its input; for roll and pitch, the
//!   part of the input that follows the attitude (holding it against the
//!   restoring moment, which does no net work) is removed first. When
//!   exactly one DOF above the noise floor is pushed along, every other one
//!   (pushed against, or not measurably at all) is held against its
//!   coupling, not excited; when several are pushed along (a recursive or
//!   validation run), a DOF's own excitation and the coupling it resists mix
//!   and the sign decides nothing; when none is, nothing is held.
//! - **Grid speed.** The grid point nearest the mean forward speed u, and
//!   how far the mean was from it.
//! - **Role.** Forward speed (moving average over [`SPEED_WINDOW_TIME_CONSTANTS`]
//!   surge time constants, ≥ 30 s) spending ≥ [`MIN_BIN_SHARE`] of the run in
//!   each of two grid bins of a grid of ≥ 2 speeds → validation (the
//!   thesis's validation run steps through the grid); no DOF excited
//!   dynamically → static; on a DP vessel,
//!   more than one kind of thruster (main, tunnel, azimuth) driven →
//!   validation, else the manoeuvre of the one kind driven (SI1 / SI2 / SI3);
//!   on a ROV, ≥ [`RECURSIVE_MIN_DOFS`] DOFs excited at once → recursive,
//!   else dynamic.
//! - **Signal.** The switching intervals of the most excited DOF (its input
//!   when the input is two-level, open loop; else its velocity, which
//!   follows a closed-loop reference): regular intervals (coefficient of
//!   variation < [`SQUARE_MAX_CV`]) → square; multiples of one chip (mean
//!   deviation < [`CHIP_MAX_DEVIATION`] of a chip, some ≥ 2) → PRBS; else
//!   other.

use serde::{Deserialize, Serialize};

use super::description::{RunRole, RunSignal, dof_words};
use crate::planning::campaign::ExperimentFamily;
use crate::planning::vessel::{InputChannels, ThrusterKind, VesselKind, VesselProfile};
use crate::planning::{Dof, KNOT};
use crate::timeseries::UniformRecord;

mod dp_force;
mod signal;
mod speed;
mod stats;
use stats::{blocks, covariance, mean_std, moving_average, step_share, switch_times};

pub use signal::{CHIP_MAX_DEVIATION, MIN_INTERVALS, SQUARE_MAX_CV};
pub use speed::{MIN_BIN_SHARE, SPEED_WINDOW_TIME_CONSTANTS};

/// Velocity scale of surge (m/s): twice the default speed excursion of a
/// dynamic surge run (0.3 kn, thesis Table 3.1), so that a default surge
/// excitation reads like the other DOFs' default of half their limit.
pub const SURGE_SCALE_MPS: f64 = 0.6 * KNOT;

/// Smallest activity score (fraction of the DOF's scale) that is not noise:
/// a work-class ROV's DVL (±1 cm/s) and gyros (±0.005 rad/s) read ≈ 1–2 % of
/// the limits, and a controller holding the DOF against them moves τ less.
pub const NOISE_FLOOR: f64 = 0.03;

/// Moving-average window (s) over which the input and the velocity are
/// averaged before their correlation (the sign of the actuators' work) is
/// taken: longer than the 10–20 Hz noise a controller feeds back into its
/// input, shorter than an excitation's switching time (≥ 2 s).
pub const WORK_WINDOW_S: f64 = 1.0;

/// A driven thruster's command spread is at least this fraction of the
/// run's largest (DP vessels): a thruster trimming against the manoeuvre of
/// another kind stays below it.
pub const THRUSTER_RELATIVE_LEVEL: f64 = 0.25;

/// A ROV run exciting at least this many DOFs at once is a recursive run
/// (thesis Table 3.1); fewer make a dynamic run.
pub const RECURSIVE_MIN_DOFS: usize = 3;

/// Largest share of a velocity's variance one step may explain in an
/// excited DOF: a square wave of two periods is ≈ 0.33 one step, short
/// PRBS runs of the planner flown under PI control ≤ 0.6; a step-and-hold
/// (a static run, even one the controller overshoots) ≥ 0.73.
pub const STEP_MAX_SHARE: f64 = 0.67;

/// Largest velocity level (fraction of the rate limit) of a roll or pitch
/// whose attitude counts as held: bringing the attitude to a new level once
/// moves the rate only while it slews (10° over a 50 s hold: ≈ 3 % of the
/// Surveyor's 0.3 rad/s), a dynamic excitation by its amplitude (≈ 50 %),
/// and under a rate excitation the attitude may wander to one side, which
/// must not read as a hold.
pub const ATTITUDE_HOLD_MAX_VELOCITY_LEVEL: f64 = 0.1;

/// How much one DOF moved in a run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct DofActivity {
    /// The DOF.
    pub dof: Dof,
    /// Std of the input about its mean, as a fraction of the DOF's force scale.
    pub input_level: f64,
    /// Std of the velocity about its mean, as a fraction of the DOF's velocity scale.
    pub velocity_level: f64,
    /// √(input level · velocity level).
    pub score: f64,
    /// Times the velocity crossed from below mean − σ/2 to above mean + σ/2 or back.
    pub switches: usize,
    /// Share of the velocity's variance explained by one step (the best
    /// single breakpoint between two constant levels); roll and pitch with
    /// a quiet rate ([`ATTITUDE_HOLD_MAX_VELOCITY_LEVEL`]): of the velocity's
    /// or the attitude's, whichever is larger (an attitude brought to a
    /// level once and held is a static hold, though its rate only pulses).
    pub step_share: f64,
    /// Correlation of the input with the velocity, both averaged over 1 s
    /// (roll, pitch: the input beyond what holds the attitude against the
    /// restoring moment): the sign of the work the actuators do in the DOF
    /// (> 0 pushed along its motion, < 0 held against it).
    pub input_work: f64,
    /// Active: above the noise floor and not held against the coupling of
    /// the one DOF pushed along.
    pub active: bool,
    /// Active, switching at least twice and not mostly one step: a dynamic
    /// excitation (else the DOF was stepped once and held).
    pub excited: bool,
}

/// What the data say a run is.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct InferredDescription {
    /// Inferred role.
    pub role: RunRole,
    /// Why.
    pub role_reason: String,
    /// The family identification treats it as (for a DP vessel's dynamic
    /// run: the manoeuvre of the thrusters it drove).
    pub family: ExperimentFamily,
    /// Grid point nearest the mean forward speed (m/s); none when the speed
    /// wanders across the grid or cannot be read.
    pub grid_speed_mps: Option<f64>,
    /// Why, with the distance of the mean from the grid point.
    pub grid_speed_reason: String,
    /// Mean forward speed over the valid samples (m/s).
    pub mean_forward_speed_mps: Option<f64>,
    /// DOFs that moved (excited or stepped), in DOF order.
    pub excited_dofs: Vec<Dof>,
    /// Why.
    pub excited_dofs_reason: String,
    /// Excitation signal of the most excited DOF.
    pub signal: RunSignal,
    /// Why.
    pub signal_reason: String,
    /// The evidence per modelled DOF.
    pub dofs: Vec<DofActivity>,
}

/// Why nothing could be inferred.
#[derive(Debug, Clone, PartialEq)]
pub struct DescribeError(pub String);

impl std::fmt::Display for DescribeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for DescribeError {}

/// The attitude a DOF's input holds against the restoring moment: φ for
/// roll, θ for pitch (log column names).
fn restored_attitude(d: Dof) -> Option<&'static str> {
    match d {
        Dof::Roll => Some("phi"),
        Dof::Pitch => Some("theta"),
        _ => None,
    }
}

/// The sign of the actuators' work in one DOF: the correlation of its input
/// `tau` with its velocity `nu` over the valid samples, each averaged over
/// `w` samples within its block. With `attitude` (roll, pitch), the part of
/// the input proportional to the attitude — holding it against the
/// restoring moment, which does no net work — is removed first. 0 when
/// either is constant.
fn input_work(
    rec: &UniformRecord,
    tau: &[f64],
    nu: &[f64],
    attitude: Option<&[f64]>,
    w: usize,
) -> f64 {
    let pooled = |col: &[f64]| -> Vec<f64> {
        blocks(rec, col)
            .flat_map(|b| moving_average(b, w))
            .collect()
    };
    let (mut t, v) = (pooled(tau), pooled(nu));
    if v.len() < 2 || t.len() != v.len() {
        return 0.0;
    }
    if let Some(a) = attitude.map(pooled).filter(|a| a.len() == t.len()) {
        let var = covariance(&a, &a);
        if var > 0.0 {
            let k = covariance(&t, &a) / var;
            for (x, y) in t.iter_mut().zip(&a) {
                *x -= k * y;
            }
        }
    }
    let (tt, vv) = (covariance(&t, &t), covariance(&v, &v));
    if tt > 0.0 && vv > 0.0 {
        covariance(&t, &v) / (tt * vv).sqrt()
    } else {
        0.0
    }
}

/// The force scale of each modelled DOF for the input columns.
fn force_scales(profile: &VesselProfile) -> Vec<f64> {
    match &profile.inputs {
        InputChannels::GeneralizedForces => profile
            .dofs
            .iter()
            .map(|d| profile.limit(*d).max_force)
            .collect(),
        InputChannels::Thrusters {
            thrusters,
            configuration,
        } => configuration
            .iter()
            .map(|row| {
                row.iter()
                    .zip(thrusters)
                    .map(|(t, th)| t.abs() * th.max_command)
                    .sum()
            })
            .collect(),
    }
}

fn velocity_scale(profile: &VesselProfile, d: Dof) -> f64 {
    let v = profile.limit(d).max_velocity;
    if d == Dof::Surge {
        v.min(SURGE_SCALE_MPS)
    } else {
        v
    }
}

/// Activity of every modelled DOF; `inputs` are the generalized-force
/// columns in DOF order.
fn activity(
    rec: &UniformRecord,
    profile: &VesselProfile,
    inputs: &[String],
) -> Result<Vec<DofActivity>, DescribeError> {
    let scales = force_scales(profile);
    let window = ((WORK_WINDOW_S * rec.sample_rate_hz).round() as usize).max(1);
    let column = |name: &str| {
        rec.column(name)
            .ok_or_else(|| DescribeError(format!("the record has no column '{name}'")))
    };
    let mut out = Vec::new();
    for ((&d, input), &f) in profile.dofs.iter().zip(inputs).zip(&scales) {
        let tau = column(input)?;
        let (_, s_tau) = mean_std(rec, tau);
        let nu = column(d.velocity_symbol())?;
        let (m_nu, s_nu) = mean_std(rec, nu);
        let input_level = if f > 0.0 { s_tau / f } else { 0.0 };
        let velocity_level = s_nu / velocity_scale(profile, d);
        let switches = switch_times(rec, nu, m_nu - 0.5 * s_nu, m_nu + 0.5 * s_nu)
            .iter()
            .map(Vec::len)
            .sum();
        out.push(DofActivity {
            dof: d,
            input_level,
            velocity_level,
            score: (input_level * velocity_level).sqrt(),
            switches,
            step_share: match restored_attitude(d).and_then(|c| rec.column(c)) {
                Some(att) if velocity_level <= ATTITUDE_HOLD_MAX_VELOCITY_LEVEL => {
                    step_share(rec, nu).max(step_share(rec, att))
                }
                _ => step_share(rec, nu),
            },
            input_work: input_work(
                rec,
                tau,
                nu,
                restored_attitude(d).and_then(|c| rec.column(c)),
                window,
            ),
            active: false,
            excited: false,
        });
    }
    let moving = |a: &DofActivity| a.score >= NOISE_FLOOR;
    let pushed_along = out
        .iter()
        .filter(|a| moving(a) && a.input_work > 0.0)
        .count();
    for a in &mut out {
        let held = pushed_along == 1 && a.input_work <= 0.0;
        a.active = moving(a) && !held;
        a.excited = a.active && a.switches >= 2 && a.step_share < STEP_MAX_SHARE;
    }
    Ok(out)
}

/// DOFs above the noise floor that are held against the coupling of the
/// one DOF pushed along (see [`activity`]).
fn held_against_coupling(acts: &[DofActivity]) -> Vec<&DofActivity> {
    acts.iter()
        .filter(|a| a.score >= NOISE_FLOOR && !a.active)
        .collect()
}

/// "sway 42 %, yaw 3 %" — the scores as percentages of the DOFs' scales.
fn score_words(acts: &[&DofActivity]) -> String {
    acts.iter()
        .map(|a| format!("{} {:.0} %", a.dof.name(), 100.0 * a.score))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The excited DOFs and why.
fn excited_dofs(acts: &[DofActivity]) -> (Vec<Dof>, String) {
    let active: Vec<&DofActivity> = acts.iter().filter(|a| a.active).collect();
    let dofs: Vec<Dof> = active.iter().map(|a| a.dof).collect();
    let held = held_against_coupling(acts);
    let quiet: Vec<&DofActivity> = acts.iter().filter(|a| a.score < NOISE_FLOOR).collect();
    let reason = if active.is_empty() {
        format!(
            "no DOF moves above the noise floor of {:.0} % of its scale (largest: {})",
            100.0 * NOISE_FLOOR,
            score_words(&acts.iter().collect::<Vec<_>>())
        )
    } else {
        let stepped: Vec<&str> = active
            .iter()
            .filter(|a| !a.excited)
            .map(|a| a.dof.name())
            .collect();
        let mut s = format!(
            "input and velocity spread about the mean (geometric mean, % of the DOF's scale): {}",
            score_words(&active)
        );
        if !stepped.is_empty() {
            s.push_str(&format!(
                "; {} step{} once and hold{}",
                stepped.join(", "),
                if stepped.len() == 1 { "s" } else { "" },
                if stepped.len() == 1 { "s" } else { "" }
            ));
        }
        if !held.is_empty() {
            let work = held
                .iter()
                .map(|a| {
                    format!(
                        "{} {:.0} % ({:+.2})",
                        a.dof.name(),
                        100.0 * a.score,
                        a.input_work
                    )
                })
                .collect::<Vec<_>>()
                .join(", ");
            s.push_str(&format!(
                "; {} held against {}'s coupling: the actuators push against {} motion (input–velocity correlation, 1 s averages: {work})",
                dof_words(&held.iter().map(|a| a.dof).collect::<Vec<_>>()),
                dof_words(&dofs),
                if held.len() == 1 { "its" } else { "their" },
            ));
        }
        if !quiet.is_empty() {
            s.push_str(&format!(
                "; the others stay below the noise floor of {:.0} % ({})",
                100.0 * NOISE_FLOOR,
                score_words(&quiet)
            ));
        }
        s
    };
    (dofs, reason)
}

/// Thruster kinds driven in a run (DP vessels): those whose command std
/// (over the max command) is above the noise floor and at least
/// [`THRUSTER_RELATIVE_LEVEL`] of the largest.
fn driven_kinds(rec: &UniformRecord, profile: &VesselProfile) -> Vec<ThrusterKind> {
    let thr = profile.thrusters();
    let levels: Vec<f64> = thr
        .iter()
        .enumerate()
        .map(|(i, t)| {
            rec.column(&format!("thr_{}", i + 1)).map_or(0.0, |c| {
                mean_std(rec, c).1 / t.max_command.max(f64::MIN_POSITIVE)
            })
        })
        .collect();
    let top = levels.iter().copied().fold(0.0, f64::max);
    let mut kinds = Vec::new();
    for (t, &l) in thr.iter().zip(&levels) {
        if l >= NOISE_FLOOR && l >= THRUSTER_RELATIVE_LEVEL * top && !kinds.contains(&t.kind) {
            kinds.push(t.kind);
        }
    }
    kinds
}

fn kind_name(k: ThrusterKind) -> &'static str {
    match k {
        ThrusterKind::Main => "main propellers",
        ThrusterKind::Tunnel => "tunnel thrusters",
        ThrusterKind::Azimuth => "azimuth thruster",
    }
}

/// Role, its family and why.
fn role(
    rec: &UniformRecord,
    profile: &VesselProfile,
    acts: &[DofActivity],
    wandering: Option<&str>,
) -> (RunRole, ExperimentFamily, String) {
    let excited: Vec<&DofActivity> = acts.iter().filter(|a| a.excited).collect();
    if let Some(w) = wandering {
        return (
            RunRole::Validation,
            ExperimentFamily::Validation,
            format!("{w}: a validation run steps through the grid speeds"),
        );
    }
    if excited.is_empty() {
        let stepped: Vec<&str> = acts
            .iter()
            .filter(|a| a.active)
            .map(|a| a.dof.name())
            .collect();
        let why = if stepped.is_empty() {
            "no DOF is excited: every input and velocity stays within the noise floor".to_string()
        } else {
            format!(
                "no DOF is excited dynamically: {} steps once to a level and holds it",
                stepped.join(", ")
            )
        };
        return (RunRole::Static, ExperimentFamily::Static, why);
    }
    let names: Vec<Dof> = excited.iter().map(|a| a.dof).collect();
    if profile.kind == VesselKind::Dp3 && !super::ekf_layout::is_paper_layout(profile) {
        return dp_force::dp_role_by_force(rec, profile, &names);
    }
    if profile.kind == VesselKind::Dp3 {
        let kinds = driven_kinds(rec, profile);
        let list = kinds
            .iter()
            .map(|k| kind_name(*k))
            .collect::<Vec<_>>()
            .join(", ");
        return match kinds.as_slice() {
            [k] => {
                let (fam, si) = match k {
                    ThrusterKind::Main => (ExperimentFamily::DpSurge, "SI1"),
                    ThrusterKind::Tunnel => (ExperimentFamily::DpSwayYaw, "SI2"),
                    ThrusterKind::Azimuth => (ExperimentFamily::DpAzimuth, "SI3"),
                };
                (
                    RunRole::Dynamic,
                    fam,
                    format!(
                        "only the {list} are driven (exciting {}): manoeuvre {si} ({})",
                        dof_words(&names),
                        fam.name()
                    ),
                )
            }
            [] => (
                RunRole::Dynamic,
                ExperimentFamily::Dynamic,
                format!(
                    "{} excited, but no thruster command moves clearly: the DP manoeuvre is unknown",
                    dof_words(&names)
                ),
            ),
            _ => (
                RunRole::Validation,
                ExperimentFamily::Validation,
                format!(
                    "{list} are driven together (exciting {}): the DP validation run",
                    dof_words(&names)
                ),
            ),
        };
    }
    if excited.len() >= RECURSIVE_MIN_DOFS {
        (
            RunRole::Recursive,
            ExperimentFamily::Recursive,
            format!(
                "{} of {} DOFs excited at once ({}) at a steady forward speed",
                excited.len(),
                acts.len(),
                dof_words(&names)
            ),
        )
    } else {
        (
            RunRole::Dynamic,
            ExperimentFamily::Dynamic,
            format!("{} excited at a steady forward speed", dof_words(&names)),
        )
    }
}

/// Infers what `rec` is. `inputs` are the generalized-force columns of the
/// profile's DOFs in order (τ, or τ_T = T·u); `grid` the campaign's grid
/// speeds (m/s).
pub fn infer_description(
    rec: &UniformRecord,
    profile: &VesselProfile,
    inputs: &[String],
    grid: &[f64],
) -> Result<InferredDescription, DescribeError> {
    if inputs.len() != profile.dofs.len() {
        return Err(DescribeError(format!(
            "{} input columns for {} DOFs",
            inputs.len(),
            profile.dofs.len()
        )));
    }
    if rec.valid.iter().map(|b| b.len()).sum::<usize>() < 10
        || !(rec.sample_rate_hz.is_finite() && rec.sample_rate_hz > 0.0)
    {
        return Err(DescribeError("fewer than 10 valid samples".into()));
    }
    let acts = activity(rec, profile, inputs)?;
    let (grid_speed_mps, grid_speed_reason, mean, wandering) =
        speed::grid_speed(rec, profile, grid);
    let (excited_dofs, excited_dofs_reason) = excited_dofs(&acts);
    let (role, family, role_reason) = role(rec, profile, &acts, wandering.as_deref());
    let (signal, signal_reason) = signal::signal(rec, inputs, &acts);
    Ok(InferredDescription {
        role,
        role_reason,
        family,
        grid_speed_mps,
        grid_speed_reason,
        mean_forward_speed_mps: mean,
        excited_dofs,
        excited_dofs_reason,
        signal,
        signal_reason,
        dofs: acts,
    })
}

#[cfg(test)]
mod tests;
