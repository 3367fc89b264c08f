//! The campaign plan: every experiment (grid point × DOF × repetition) with
//! its reference schedule, in the order it is flown, and the trial time.

use std::collections::BTreeMap;

use super::analysis::analyse;
use super::campaign::{CampaignSpec, ExperimentFamily, Quantity, SignalKind, SpeedUnit};
use super::design::{ChannelRequest, MAX_SEED, design_channel};
use super::dof::{Dof, KNOT};
use super::error::PlanError;
use super::statics::{
    ATTITUDE_LOOP_TIME_CONSTANTS, attitude_column, attitude_limit, holds_attitude, static_angle,
};
use super::vessel::{VesselKind, VesselProfile};
use super::waveform::Waveform;
use crate::rng::mix;
use crate::signals;

mod types;
pub use types::{ChannelPlan, Experiment, Plan, PlanTotals, PlannedExperiment, Schedule};

/// Most samples one run may hold per channel (4 h at 1 kHz).
pub const MAX_SAMPLES_PER_CHANNEL: usize = 14_400_000;
/// Fraction of power above the logger's Nyquist frequency that earns a warning.
pub const NYQUIST_WARNING_FRACTION: f64 = 0.05;

pub(super) fn run_seed(
    seed: u64,
    family: ExperimentFamily,
    grid: usize,
    dof: usize,
    rep: u32,
) -> u64 {
    let mut h = mix(seed);
    for v in [family as u64, grid as u64, dof as u64, u64::from(rep)] {
        h = mix(h ^ v);
    }
    h & MAX_SEED
}

/// A channel before sampling.
pub(super) struct ChannelSpec {
    pub(super) plan: ChannelPlan,
    pub(super) duration_s: f64,
}

/// Shared context while planning.
pub(super) struct Ctx<'a> {
    pub(super) vessel: &'a VesselProfile,
    pub(super) spec: &'a CampaignSpec,
    pub(super) speeds: Vec<f64>,
    fs: f64,
    decimation: usize,
}

impl Ctx<'_> {
    pub(super) fn speed_label(&self, i: usize) -> String {
        let (v, unit) = match self.spec.grid.unit {
            SpeedUnit::Knots => (self.spec.grid.speeds[i], "kn"),
            SpeedUnit::MetersPerSecond => (self.spec.grid.speeds[i], "m/s"),
        };
        format!("{v}{unit}")
    }

    fn quantity(&self) -> Quantity {
        self.spec.excitation.quantity
    }

    fn override_of(&self, d: Dof) -> Option<&super::campaign::DofExcitation> {
        self.spec.excitation.per_dof.get(&d)
    }

    pub(super) fn signal_for(&self, d: Dof) -> SignalKind {
        self.override_of(d)
            .and_then(|o| o.signal)
            .unwrap_or(self.spec.excitation.signal)
    }

    /// Column, unit, clip limit and slew limit of a DOF channel.
    pub(super) fn dof_channel(&self, d: Dof) -> (String, String, f64, Option<f64>, String) {
        let l = self.vessel.limit(d);
        if d == Dof::Surge || self.quantity() == Quantity::Velocity {
            (
                format!("{}_ref", d.velocity_symbol()),
                d.velocity_unit().to_string(),
                l.max_velocity,
                l.max_accel,
                format!("limits.{}.max_accel", d.name()),
            )
        } else {
            (
                d.force_column().to_string(),
                d.force_unit().to_string(),
                l.max_force,
                Some(l.max_force_rate),
                format!("limits.{}.max_force_rate", d.name()),
            )
        }
    }

    /// True when `d` is excited by an attitude reference (`phi_ref`,
    /// `theta_ref`) in dynamic, recursive and validation runs: roll and
    /// pitch under velocity references. A rate reference p_ref, q_ref on a
    /// metacentrically stable vehicle integrates to a random walk of
    /// attitude (25–45° on the Surveyor), far outside the linear model; an
    /// attitude square wave or PRBS about level stays within ±A while the
    /// attitude loop moves the rate at every switch.
    pub(super) fn excites_attitude(&self, d: Dof) -> bool {
        holds_attitude(d) && self.quantity() == Quantity::Velocity
    }

    /// Column, unit, clip limit, slew limit (and its field) of `d`'s
    /// excited channel: an attitude for roll and pitch under velocity
    /// references (slewed at no more than the DOF's rate limit), else the
    /// DOF's velocity or force channel.
    pub(super) fn excitation_channel(&self, d: Dof) -> (String, String, f64, Option<f64>, String) {
        if self.excites_attitude(d) {
            (
                attitude_column(d).to_string(),
                "rad".to_string(),
                attitude_limit(self.vessel, d),
                Some(self.vessel.limit(d).max_velocity),
                format!("limits.{}.max_velocity", d.name()),
            )
        } else {
            self.dof_channel(d)
        }
    }

    /// Time constant of the response an excited channel of `d` drives: the
    /// attitude loop's ([`ATTITUDE_LOOP_TIME_CONSTANTS`] · T) for an
    /// attitude reference, else the DOF's T.
    pub(super) fn excitation_time_constant(&self, d: Dof) -> f64 {
        let t = self.vessel.limit(d).time_constant_s;
        if self.excites_attitude(d) {
            ATTITUDE_LOOP_TIME_CONSTANTS * t
        } else {
            t
        }
    }

    /// Amplitude of a non-surge DOF's excitation, checked against its
    /// limit: for an attitude, ±10° or the profile's `max_angle` when
    /// smaller (as static holds), at most `max_angle` (10° without one);
    /// else `amplitude_fraction` of the DOF's limit.
    pub(super) fn amplitude(&self, d: Dof) -> Result<f64, PlanError> {
        let (_, unit, limit, _, _) = self.excitation_channel(d);
        match self.override_of(d).and_then(|o| o.amplitude) {
            Some(a) => check_amplitude(
                &format!("excitation.per_dof.{}.amplitude", d.name()),
                a,
                limit,
                &unit,
            ),
            None if self.excites_attitude(d) => Ok(static_angle(self.vessel, d)),
            None => Ok(self.spec.excitation.amplitude_fraction * limit),
        }
    }

    /// Surge excursion about grid speed u0, and the offset it is flown about.
    fn surge_excursion(&self, u0: f64) -> Result<(f64, f64), PlanError> {
        let max = self.vessel.max_forward_speed();
        match self.override_of(Dof::Surge).and_then(|o| o.amplitude) {
            Some(a) => {
                let a = check_amplitude("excitation.per_dof.surge.amplitude", a, max, "m/s")?;
                if u0 + a > max + 1e-12 {
                    return Err(PlanError::over_limit(
                        "excitation.per_dof.surge.amplitude",
                        format!(
                            "{a} m/s about the grid speed {u0:.3} m/s exceeds the maximum forward speed {max:.3} m/s"
                        ),
                        max - u0,
                    ));
                }
                Ok((a, u0))
            }
            None => {
                // Table 3.1: u within ±0.3 kn of the grid speed; at the top of
                // the envelope the band is flown just below it.
                let a = (0.3 * KNOT).min(self.spec.excitation.amplitude_fraction * max);
                Ok((a, u0.min(max - a)))
            }
        }
    }

    pub(super) fn held(&self, d: Dof, u0: f64) -> ChannelPlan {
        let (column, unit, limit, rate, _) = self.dof_channel(d);
        ChannelPlan {
            column,
            unit,
            dof: Some(d),
            thruster: None,
            excited: false,
            waveform: Waveform::Constant,
            offset: if d == Dof::Surge { u0 } else { 0.0 },
            amplitude: 0.0,
            limit,
            rate_limit: rate,
            analysis: None,
        }
    }

    /// Designs an excited DOF channel.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn dynamic_dof(
        &self,
        d: Dof,
        u0: f64,
        min_duration: f64,
        signal: SignalKind,
        seed: u64,
        channel: (usize, usize),
    ) -> Result<ChannelSpec, PlanError> {
        let (column, unit, limit, rate, rate_field) = self.excitation_channel(d);
        let (amplitude, offset) = if d == Dof::Surge {
            self.surge_excursion(u0)?
        } else {
            (self.amplitude(d)?, 0.0)
        };
        let field = format!("excitation.per_dof.{}", d.name());
        let o = self.override_of(d);
        let design = design_channel(&ChannelRequest {
            field: &field,
            signal,
            time_constant_s: self.excitation_time_constant(d),
            amplitude,
            rate_limit: rate,
            rate_field: &rate_field,
            clock_period_s: o.and_then(|o| o.clock_period_s),
            prbs_order: o.and_then(|o| o.prbs_order),
            min_duration_s: min_duration,
            logger_rate_hz: self.vessel.logger_rate_hz,
            seed,
            channel,
        })?;
        Ok(ChannelSpec {
            plan: ChannelPlan {
                column,
                unit,
                dof: Some(d),
                thruster: None,
                excited: true,
                waveform: design.waveform,
                offset,
                amplitude,
                limit,
                rate_limit: rate,
                analysis: None,
            },
            duration_s: design.duration_s,
        })
    }
}

fn check_amplitude(field: &str, a: f64, limit: f64, unit: &str) -> Result<f64, PlanError> {
    if !(a.is_finite() && a > 0.0) {
        return Err(PlanError::invalid(
            field,
            format!("must be a finite number > 0 (got {a})"),
        ));
    }
    if a > limit + 1e-12 {
        return Err(PlanError::over_limit(
            field,
            format!("amplitude {a} {unit} is over the limit of {limit} {unit}"),
            limit,
        ));
    }
    Ok(a)
}

/// PE order an experiment needs per excited channel: two per DOF its data
/// must identify (a first-order response per DOF: A_λ and B_λ entries), one
/// for a static run (a steady-state gain).
pub(super) fn pe_required(family: ExperimentFamily, n_dofs: usize) -> usize {
    use ExperimentFamily::*;
    match family {
        Static => 1,
        Dynamic | DpSurge | DpAzimuth => 2,
        DpSwayYaw => 4,
        Recursive | Validation => 2 * n_dofs,
    }
}

/// Builds the plan for a campaign. Pure and deterministic for a given seed.
pub fn generate_plan(vessel: &VesselProfile, spec: &CampaignSpec) -> Result<Plan, PlanError> {
    vessel.validate()?;
    spec.validate(vessel)?;
    let fs = vessel.controller_rate_hz;
    let ratio = vessel.controller_rate_hz / vessel.logger_rate_hz;
    let decimation = if ratio >= 1.0 && (ratio - ratio.round()).abs() < 1e-9 {
        ratio.round() as usize
    } else {
        1
    };
    let ctx = Ctx {
        vessel,
        spec,
        speeds: spec.grid.speeds_si(),
        fs,
        decimation,
    };
    let reps = spec.repetitions_for(vessel.kind);
    let mut out: Vec<PlannedExperiment> = Vec::new();
    let has = |f: ExperimentFamily| spec.families.contains(&f);
    match vessel.kind {
        VesselKind::Rov6 => {
            for gi in 0..ctx.speeds.len() {
                if has(ExperimentFamily::Static) {
                    super::statics::rov_static(&ctx, gi, reps, &mut out)?;
                }
                if has(ExperimentFamily::Dynamic) {
                    super::dynamic_runs::rov_dynamic(&ctx, gi, reps, &mut out)?;
                }
                if has(ExperimentFamily::Recursive) {
                    super::dynamic_runs::rov_recursive(&ctx, gi, reps, &mut out)?;
                }
            }
        }
        VesselKind::Dp3 => {
            // SI1 → SI2 → SI3: each stage's parameters are frozen for the next (Fig. 4).
            for fam in [
                ExperimentFamily::DpSurge,
                ExperimentFamily::DpSwayYaw,
                ExperimentFamily::DpAzimuth,
            ] {
                if has(fam) {
                    for gi in 0..ctx.speeds.len() {
                        super::dp_manoeuvres::dp_manoeuvre(&ctx, fam, gi, reps, &mut out)?;
                    }
                }
            }
        }
    }
    if has(ExperimentFamily::Validation) {
        super::validation_run::validation(&ctx, reps, &mut out)?;
    }
    super::deciding::deciding_runs(&ctx, &mut out)?;
    let mut per_family = BTreeMap::new();
    let mut run_time_s = 0.0;
    for (i, p) in out.iter_mut().enumerate() {
        p.experiment.seq = i as u32 + 1;
        run_time_s += p.experiment.duration_s;
        *per_family
            .entry(p.experiment.family.name().to_string())
            .or_insert(0) += 1;
    }
    let setup_time_s = spec.durations.setup_s * out.len() as f64;
    let totals = PlanTotals {
        experiments: out.len(),
        per_family,
        run_time_s,
        setup_time_s,
        total_time_s: run_time_s + setup_time_s,
    };
    Ok(Plan {
        experiments: out,
        totals,
    })
}

/// What an experiment is, before its channels are sampled.
pub(super) struct ExperimentHead {
    pub(super) code: String,
    pub(super) family: ExperimentFamily,
    pub(super) grid_index: Option<usize>,
    pub(super) dofs: Vec<Dof>,
    pub(super) sign: Option<i8>,
    pub(super) repetition: u32,
    pub(super) instruction: String,
    pub(super) pe_required: usize,
    /// Field to blame when the excitation is not persistent enough.
    pub(super) field: String,
}

/// Samples, shapes and checks the channels of one experiment.
pub(super) fn assemble(
    ctx: &Ctx<'_>,
    head: ExperimentHead,
    channels: Vec<ChannelSpec>,
) -> Result<PlannedExperiment, PlanError> {
    let duration = channels
        .iter()
        .map(|c| c.duration_s)
        .fold(0.0_f64, f64::max);
    let n = (duration * ctx.fs).round() as usize;
    if n > MAX_SAMPLES_PER_CHANNEL {
        return Err(PlanError::over_limit(
            head.field.clone(),
            format!(
                "experiment {} would need {n} samples per channel ({duration:.0} s at {} Hz)",
                head.code, ctx.fs
            ),
            MAX_SAMPLES_PER_CHANNEL as f64,
        ));
    }
    let mut warnings = Vec::new();
    let mut columns = Vec::new();
    let mut values = Vec::new();
    let mut plans = Vec::new();
    let pe_cap = (2 * head.pe_required).clamp(8, 32);
    for c in channels {
        let mut p = c.plan;
        let raw = p
            .waveform
            .sample(p.offset, p.amplitude, ctx.fs, n)
            .map_err(|e| PlanError::invalid(head.field.clone(), e.to_string()))?;
        let shaped = match p.rate_limit {
            Some(r) => signals::rate_limit(&raw, r, ctx.fs, p.offset),
            None => raw,
        };
        let x = signals::clip(&shaped, -p.limit, p.limit);
        if p.excited && p.waveform != Waveform::Constant {
            let a = analyse(
                &x,
                p.offset,
                ctx.fs,
                ctx.decimation,
                ctx.vessel.logger_rate_hz,
                head.pe_required,
                pe_cap,
            );
            if p.waveform.is_dynamic() && a.pe_order < a.pe_required {
                return Err(PlanError::over_limit(
                    head.field.clone(),
                    format!(
                        "{} in {}: the reference is persistently exciting of order {} as logged at {} Hz, but {} needs {}; shorten the clock or choose a PRBS",
                        p.column,
                        head.code,
                        a.pe_order,
                        ctx.vessel.logger_rate_hz,
                        head.family.name(),
                        a.pe_required
                    ),
                    a.pe_required as f64,
                ));
            }
            if a.power_above_logger_nyquist > NYQUIST_WARNING_FRACTION {
                warnings.push(format!(
                    "{}: {:.0} % of the reference's power lies above the logger's Nyquist frequency ({} Hz); log faster or lengthen the clock",
                    p.column,
                    100.0 * a.power_above_logger_nyquist,
                    ctx.vessel.logger_rate_hz / 2.0
                ));
            }
            if let (Some(d), Some([_, hi])) = (p.dof, a.band_hz) {
                // An attitude reference drives the attitude loop, whose
                // corner lies below the DOF's.
                let attitude = p.column == attitude_column(d) && holds_attitude(d);
                let t = ctx.vessel.limit(d).time_constant_s;
                let (t, what) = if attitude {
                    (
                        ATTITUDE_LOOP_TIME_CONSTANTS * t,
                        "attitude-loop corner frequency 1/(2π·2T)",
                    )
                } else {
                    (t, "corner frequency 1/(2πT)")
                };
                let corner = 1.0 / (2.0 * std::f64::consts::PI * t);
                if p.waveform.is_dynamic() && hi < corner {
                    warnings.push(format!(
                        "{}: usable band ends at {hi:.3} Hz, below the {} {what} = {corner:.3} Hz; a shorter clock would excite the dynamics better",
                        p.column,
                        d.name()
                    ));
                }
            }
            p.analysis = Some(a);
        }
        columns.push(p.column.clone());
        values.push(x);
        plans.push(p);
    }
    let experiment = Experiment {
        seq: 0,
        code: head.code,
        family: head.family,
        grid_index: head.grid_index,
        grid_speed_mps: head.grid_index.map(|i| ctx.speeds[i]),
        dofs: head.dofs,
        sign: head.sign,
        repetition: head.repetition,
        separates: None,
        instruction: head.instruction,
        duration_s: n as f64 / ctx.fs,
        sample_rate_hz: ctx.fs,
        channels: plans,
        warnings,
    };
    Ok(PlannedExperiment {
        experiment,
        schedule: Schedule {
            sample_rate_hz: ctx.fs,
            columns,
            values,
        },
    })
}

pub(super) fn fmt_speed(ctx: &Ctx<'_>, gi: usize) -> String {
    format!(
        "{} ({:.3} m/s)",
        ctx.speed_label(gi)
            .replace("kn", " kn")
            .replace("m/s", " m/s"),
        ctx.speeds[gi]
    )
}
