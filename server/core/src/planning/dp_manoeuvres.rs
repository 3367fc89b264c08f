//! Decoupled DP manoeuvres (Fossen et al. sec. 4.2): thruster groups that
//! share a schedule, the clock from the vessel's time constants, and the
//! SI1 → SI2 → SI3 run sheets.

use super::campaign::{ExperimentFamily, SignalKind};
use super::design::{ChannelRequest, design_channel};
use super::dof::Dof;
use super::error::PlanError;
use super::plan::{
    ChannelPlan, ChannelSpec, Ctx, ExperimentHead, PlannedExperiment, assemble, fmt_speed,
    pe_required, run_seed,
};
use super::vessel::{ThrusterKind, VesselProfile};
use super::waveform::Waveform;

/// Whether T's column `i` pushes mostly in surge (a main propeller, an
/// azimuth near the bow direction).
fn pushes_surge(vessel: &VesselProfile, i: usize) -> bool {
    let super::vessel::InputChannels::Thrusters { configuration, .. } = &vessel.inputs else {
        return false;
    };
    let col: Vec<f64> = configuration.iter().map(|row| row[i]).collect();
    let norm = col.iter().map(|v| v * v).sum::<f64>().sqrt();
    vessel
        .dofs
        .iter()
        .position(|d| *d == Dof::Surge)
        .is_some_and(|r| col[r].abs() >= 0.5 * norm)
}

/// Whether the thrusters are the paper's six (main, main, tunnel, tunnel,
/// tunnel, azimuth).
fn paper_kinds(vessel: &VesselProfile) -> bool {
    use ThrusterKind::*;
    vessel
        .thrusters()
        .iter()
        .map(|t| t.kind)
        .eq([Main, Main, Tunnel, Tunnel, Tunnel, Azimuth])
}

/// The thruster groups of a DP manoeuvre: thrusters in one group share a
/// signal. The paper's layout by kind; any other by where each thruster
/// pushes: SI1 every thruster that pushes mostly in surge, together (a
/// symmetric pair cancels its sway and yaw), SI2 the lateral ones (its
/// tunnels when it has any), stern and bow independently.
pub(super) fn dp_groups(vessel: &VesselProfile, fam: ExperimentFamily) -> Vec<Vec<usize>> {
    let thr = vessel.thrusters();
    let of_kind =
        |k: ThrusterKind| -> Vec<usize> { (0..thr.len()).filter(|&i| thr[i].kind == k).collect() };
    let yaw_arm = |i: usize| -> f64 {
        match &vessel.inputs {
            super::vessel::InputChannels::Thrusters { configuration, .. } => vessel
                .dofs
                .iter()
                .position(|d| *d == Dof::Yaw)
                .map_or(0.0, |r| configuration[r][i]),
            _ => 0.0,
        }
    };
    let nonempty = |g: Vec<Vec<usize>>| g.into_iter().filter(|v| !v.is_empty()).collect();
    let general = !paper_kinds(vessel);
    let surge: Vec<usize> = (0..thr.len())
        .filter(|&i| pushes_surge(vessel, i))
        .collect();
    match fam {
        // Main propellers together: K₁ = K₂ (eq. 31).
        ExperimentFamily::DpSurge if general => nonempty(vec![surge]),
        ExperimentFamily::DpSurge => nonempty(vec![of_kind(ThrusterKind::Main)]),
        // Stern and bow tunnels driven independently, so sway and yaw are both excited.
        ExperimentFamily::DpSwayYaw => {
            let lateral: Vec<usize> = (0..thr.len()).filter(|i| !surge.contains(i)).collect();
            let tunnels = of_kind(ThrusterKind::Tunnel);
            let t = if general && !lateral.iter().any(|i| tunnels.contains(i)) {
                lateral
            } else {
                tunnels
            };
            let (stern, bow): (Vec<usize>, Vec<usize>) =
                t.into_iter().partition(|&i| yaw_arm(i) < 0.0);
            nonempty(vec![stern, bow])
        }
        ExperimentFamily::DpAzimuth => nonempty(vec![of_kind(ThrusterKind::Azimuth)]),
        _ => nonempty(vec![
            of_kind(ThrusterKind::Main),
            of_kind(ThrusterKind::Tunnel),
            of_kind(ThrusterKind::Azimuth),
        ]),
    }
}

/// The DOF groups of a DP manoeuvre of a vessel that logs forces τ: SI1
/// surge, SI2 sway and yaw independently, validation all three; no SI3.
fn force_groups(fam: ExperimentFamily) -> Vec<Vec<Dof>> {
    match fam {
        ExperimentFamily::DpSurge => vec![vec![Dof::Surge]],
        ExperimentFamily::DpSwayYaw => vec![vec![Dof::Sway], vec![Dof::Yaw]],
        ExperimentFamily::DpAzimuth => Vec::new(),
        _ => vec![vec![Dof::Surge], vec![Dof::Sway], vec![Dof::Yaw]],
    }
}

/// DP time constant that sets the clock of a manoeuvre.
fn dp_time_constant(vessel: &VesselProfile, fam: ExperimentFamily) -> f64 {
    let t = |d: Dof| {
        vessel
            .limits
            .get(&d)
            .map_or(f64::INFINITY, |l| l.time_constant_s)
    };
    let v = match fam {
        ExperimentFamily::DpSurge => t(Dof::Surge),
        ExperimentFamily::DpSwayYaw => t(Dof::Sway).min(t(Dof::Yaw)),
        _ => t(Dof::Yaw).min(t(Dof::Sway)),
    };
    if v.is_finite() {
        v
    } else {
        vessel.limit(Dof::Surge).time_constant_s
    }
}

#[allow(clippy::too_many_arguments)]
pub(super) fn thruster_channels(
    ctx: &Ctx<'_>,
    groups: &[Vec<usize>],
    fam: ExperimentFamily,
    min_duration: f64,
    seed: u64,
) -> Result<Vec<ChannelSpec>, PlanError> {
    let thr = ctx.vessel.thrusters();
    let t = dp_time_constant(ctx.vessel, fam);
    let mut specs: Vec<Option<ChannelSpec>> = (0..thr.len()).map(|_| None).collect();
    for (gi, group) in groups.iter().enumerate() {
        // The group's amplitude and rate are set by its weakest thruster.
        let max_cmd = group
            .iter()
            .map(|&i| thr[i].max_command)
            .fold(f64::INFINITY, f64::min);
        let rate = group
            .iter()
            .map(|&i| thr[i].max_rate)
            .fold(f64::INFINITY, f64::min);
        let amplitude = ctx.spec.excitation.amplitude_fraction * max_cmd;
        let field = format!("inputs.thrusters[{}]", group[0]);
        let design = design_channel(&ChannelRequest {
            field: "excitation",
            signal: if fam == ExperimentFamily::Validation {
                SignalKind::RandomBinary
            } else {
                ctx.spec.excitation.signal
            },
            time_constant_s: t,
            amplitude,
            rate_limit: Some(rate),
            rate_field: &format!("{field}.max_rate"),
            clock_period_s: None,
            prbs_order: None,
            min_duration_s: min_duration,
            logger_rate_hz: ctx.vessel.logger_rate_hz,
            seed,
            channel: (gi, groups.len()),
        })?;
        for &i in group {
            specs[i] = Some(ChannelSpec {
                plan: thruster_plan(ctx, i, true, design.waveform.clone(), amplitude),
                duration_s: design.duration_s,
            });
        }
    }
    Ok(with_idle(specs, |i| {
        thruster_plan(ctx, i, false, Waveform::Constant, 0.0)
    }))
}

/// The command channel `thr_{i+1}` of thruster `i`.
fn thruster_plan(
    ctx: &Ctx<'_>,
    i: usize,
    excited: bool,
    waveform: Waveform,
    amplitude: f64,
) -> ChannelPlan {
    let t = &ctx.vessel.thrusters()[i];
    ChannelPlan {
        column: format!("thr_{}", i + 1),
        unit: "1".into(),
        dof: None,
        thruster: Some(i),
        excited,
        waveform,
        offset: 0.0,
        amplitude,
        limit: t.max_command,
        rate_limit: Some(t.max_rate),
        analysis: None,
    }
}

/// The channels with the undriven ones (`None`) filled by `idle(i)`, held
/// for the longest driven channel's duration.
fn with_idle(
    specs: Vec<Option<ChannelSpec>>,
    idle: impl Fn(usize) -> ChannelPlan,
) -> Vec<ChannelSpec> {
    let duration = specs
        .iter()
        .flatten()
        .map(|s| s.duration_s)
        .fold(0.0, f64::max);
    specs
        .into_iter()
        .enumerate()
        .map(|(i, s)| {
            s.unwrap_or_else(|| ChannelSpec {
                plan: idle(i),
                duration_s: duration,
            })
        })
        .collect()
}

/// Force channels τ of a DP vessel that logs forces: each DOF group one
/// signal at `amplitude_fraction` of the DOF's force limit, slewed at its
/// force-rate limit; the other DOFs held at 0.
fn force_channels(
    ctx: &Ctx<'_>,
    fam: ExperimentFamily,
    min_duration: f64,
    seed: u64,
) -> Result<Vec<ChannelSpec>, PlanError> {
    let groups = force_groups(fam);
    let t = dp_time_constant(ctx.vessel, fam);
    let dofs = &ctx.vessel.dofs;
    let mut specs: Vec<Option<ChannelSpec>> = dofs.iter().map(|_| None).collect();
    for (gi, group) in groups.iter().enumerate() {
        for &d in group {
            let l = ctx.vessel.limit(d);
            let amplitude = ctx.spec.excitation.amplitude_fraction * l.max_force;
            let design = design_channel(&ChannelRequest {
                field: "excitation",
                signal: if fam == ExperimentFamily::Validation {
                    SignalKind::RandomBinary
                } else {
                    ctx.spec.excitation.signal
                },
                time_constant_s: t,
                amplitude,
                rate_limit: Some(l.max_force_rate),
                rate_field: &format!("limits.{}.max_force_rate", d.name()),
                clock_period_s: None,
                prbs_order: None,
                min_duration_s: min_duration,
                logger_rate_hz: ctx.vessel.logger_rate_hz,
                seed,
                channel: (gi, groups.len()),
            })?;
            let i = dofs.iter().position(|x| *x == d).unwrap_or(0);
            specs[i] = Some(ChannelSpec {
                plan: force_plan(ctx, d, true, design.waveform, amplitude),
                duration_s: design.duration_s,
            });
        }
    }
    Ok(with_idle(specs, |i| {
        force_plan(ctx, dofs[i], false, Waveform::Constant, 0.0)
    }))
}

/// The τ channel of `d`.
fn force_plan(
    ctx: &Ctx<'_>,
    d: Dof,
    excited: bool,
    waveform: Waveform,
    amplitude: f64,
) -> ChannelPlan {
    let l = ctx.vessel.limit(d);
    ChannelPlan {
        column: d.force_column().to_string(),
        unit: d.force_unit().to_string(),
        dof: Some(d),
        thruster: None,
        excited,
        waveform,
        offset: 0.0,
        amplitude,
        limit: l.max_force,
        rate_limit: Some(l.max_force_rate),
        analysis: None,
    }
}

/// The channels of a DP run of family `fam`: thruster schedules, or force
/// schedules for a vessel that logs τ.
pub(super) fn dp_channels(
    ctx: &Ctx<'_>,
    fam: ExperimentFamily,
    min_duration: f64,
    seed: u64,
) -> Result<Vec<ChannelSpec>, PlanError> {
    if ctx.vessel.thrusters().is_empty() {
        force_channels(ctx, fam, min_duration, seed)
    } else {
        thruster_channels(ctx, &dp_groups(ctx.vessel, fam), fam, min_duration, seed)
    }
}

/// Decoupled DP manoeuvres (Fossen et al. sec. 4.2), N ≥ 2 each.
pub(super) fn dp_manoeuvre(
    ctx: &Ctx<'_>,
    fam: ExperimentFamily,
    gi: usize,
    reps: u32,
    out: &mut Vec<PlannedExperiment>,
) -> Result<(), PlanError> {
    let groups = dp_groups(ctx.vessel, fam);
    let thr = ctx.vessel.thrusters();
    let forces = thr.is_empty();
    if forces && fam == ExperimentFamily::DpAzimuth {
        return Err(PlanError::invalid(
            "families",
            "a vessel that logs forces τ has no azimuth manoeuvre: SI1 and SI2 determine every θ″; leave 'dp_azimuth' out",
        ));
    }
    if groups.is_empty() && !forces {
        let kind = match fam {
            ExperimentFamily::DpSurge => "main propeller",
            ExperimentFamily::DpSwayYaw => "tunnel thruster",
            _ => "azimuth thruster",
        };
        return Err(PlanError::invalid(
            "families",
            format!(
                "'{}' needs at least one {kind}; the vessel has none",
                fam.name()
            ),
        ));
    }
    let names: Vec<String> = if forces {
        force_groups(fam)
            .iter()
            .flatten()
            .map(|d| d.force_column().to_string())
            .collect()
    } else {
        groups
            .iter()
            .flatten()
            .map(|&i| thr[i].name.clone())
            .collect()
    };
    let (dofs, instruction) = match fam {
        ExperimentFamily::DpSurge => (
            vec![Dof::Surge],
            format!(
                "Uncoupled surge (SI1): drive {} with the schedule; hold heading with a bow thruster on the heading autopilot; no sway command.",
                names.join(" and ")
            ),
        ),
        ExperimentFamily::DpSwayYaw => (
            vec![Dof::Sway, Dof::Yaw],
            format!(
                "Coupled sway–yaw (SI2): drive {} with the schedules (stern and bow independent); the heading is free to change; main propellers idle.",
                names.join(", ")
            ),
        ),
        _ => (
            vec![Dof::Sway, Dof::Yaw],
            format!(
                "Azimuth test (SI3): run {} alone with the schedule; all other thrusters idle.",
                names.join(", ")
            ),
        ),
    };
    for rep in 1..=reps {
        let seed = run_seed(ctx.spec.seed, fam, gi, 0, rep);
        let channels = dp_channels(ctx, fam, ctx.spec.durations.dp_manoeuvre_s, seed)?;
        out.push(assemble(
            ctx,
            ExperimentHead {
                code: format!("{}-{}-r{rep}", fam.code(), ctx.speed_label(gi)),
                family: fam,
                grid_index: Some(gi),
                dofs: dofs.clone(),
                sign: None,
                repetition: rep,
                instruction: format!("At {}: {instruction}", fmt_speed(ctx, gi)),
                pe_required: pe_required(fam, dofs.len()),
                field: "excitation".into(),
            },
            channels,
        )?);
    }
    Ok(())
}
