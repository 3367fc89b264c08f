//! The validation run (thesis sec. 3.5): held out of every fit, stepping
//! the forward speed through the grid with every DOF still, then moving;
//! a DP vessel's thruster groups together on random-binary schedules.

use super::campaign::ExperimentFamily;
use super::design::{MAX_SEED, SQUARE_HOLD_TIME_CONSTANTS};
use super::dof::Dof;
use super::dp_manoeuvres::dp_channels;
use super::dynamic_runs::attitude_note;
use super::error::PlanError;
use super::plan::{ChannelSpec, Ctx, ExperimentHead, PlannedExperiment, assemble, run_seed};
use super::vessel::VesselKind;
use super::waveform::Waveform;
use crate::rng::mix;

/// Validation (thesis sec. 3.5): ≥ 300 s over the whole grid, constant and
/// changing speeds in every DOF.
pub(super) fn validation(
    ctx: &Ctx<'_>,
    reps: u32,
    out: &mut Vec<PlannedExperiment>,
) -> Result<(), PlanError> {
    let total = ctx.spec.durations.validation_s;
    let n_grid = ctx.speeds.len();
    let dofs = &ctx.vessel.dofs;
    for rep in 1..=reps {
        let seed = run_seed(ctx.spec.seed, ExperimentFamily::Validation, 0, 0, rep);
        let channels = match ctx.vessel.kind {
            VesselKind::Dp3 => dp_channels(ctx, ExperimentFamily::Validation, total, seed)?,
            VesselKind::Rov6 => {
                let t_max = dofs
                    .iter()
                    .map(|&d| ctx.vessel.limit(d).time_constant_s)
                    .fold(0.0, f64::max);
                let segment = (total / n_grid as f64).max(2.0 * SQUARE_HOLD_TIME_CONSTANTS * t_max);
                let duration = segment * n_grid as f64;
                let mut channels = Vec::new();
                for (i, &d) in dofs.iter().enumerate() {
                    let mut p = ctx.held(d, ctx.speeds[0]);
                    p.excited = true;
                    let mut clock = ctx.vessel.limit(d).time_constant_s;
                    if ctx.excites_attitude(d) {
                        let (column, unit, limit, rate, _) = ctx.excitation_channel(d);
                        (p.column, p.unit, p.limit, p.rate_limit) = (column, unit, limit, rate);
                        clock = ctx.excitation_time_constant(d);
                    }
                    if d == Dof::Surge {
                        p.waveform = Waveform::Staircase {
                            levels: ctx.speeds.clone(),
                            segment_s: segment,
                        };
                    } else {
                        p.amplitude = ctx.amplitude(d)?;
                        p.offset = 0.0;
                        p.waveform = Waveform::ConstantThenRandom {
                            segment_s: segment,
                            constant_fraction: 0.4,
                            clock_period_s: clock,
                            seed: mix(seed ^ i as u64) & MAX_SEED,
                        };
                    }
                    channels.push(ChannelSpec {
                        plan: p,
                        duration_s: duration,
                    });
                }
                channels
            }
        };
        let instruction = match ctx.vessel.kind {
            VesselKind::Rov6 => format!(
                "Validation (never used for fitting): step the forward speed through every grid speed; in each step hold all other DOFs still for the first 40 %, then follow their changing references. Covers {:.3}–{:.3} m/s.{}",
                ctx.speeds[0],
                ctx.speeds[n_grid - 1],
                attitude_note(ctx)
            ),
            VesselKind::Dp3 => "Validation (never used for fitting): drive all thruster groups together with independent random-binary schedules.".to_string(),
        };
        out.push(assemble(
            ctx,
            ExperimentHead {
                code: format!("VAL-r{rep}"),
                family: ExperimentFamily::Validation,
                grid_index: None,
                dofs: dofs.clone(),
                sign: None,
                repetition: rep,
                instruction,
                pe_required: 2,
                field: "durations.validation_s".into(),
            },
            channels,
        )?);
    }
    Ok(())
}
