//! Dynamic and recursive ROV runs (thesis Tables 3.1, 3.4–3.5): one DOF,
//! or every DOF at once, excited about a grid speed, with the run sheet's
//! words for the pilot.

use super::campaign::ExperimentFamily;
use super::dof::Dof;
use super::error::PlanError;
use super::plan::{
    ChannelPlan, ChannelSpec, Ctx, ExperimentHead, PlannedExperiment, assemble, fmt_speed,
    pe_required, run_seed,
};
use super::waveform::Waveform;

/// What the pilot does in a dynamic roll or pitch run excited by attitude:
/// hold +A, then −A, switching as the schedule says.
fn attitude_words(d: Dof, p: &ChannelPlan) -> String {
    let (name, col, a) = (d.name(), &p.column, p.amplitude);
    let deg = a.to_degrees();
    let switching = match &p.waveform {
        Waveform::Square { period_s } => format!("switching every {:.0} s", period_s / 2.0),
        Waveform::Prbs { clock_period_s, .. } => format!(
            "switching as the {col} schedule says (a PRBS: each level held a whole number of {clock_period_s:.0} s chips)"
        ),
        Waveform::RandomBinary { clock_period_s, .. } => format!(
            "switching as the {col} schedule says (random levels, each held a whole number of {clock_period_s:.0} s chips)"
        ),
        _ => format!("moving between them as the {col} schedule says"),
    };
    let slew = p.rate_limit.map_or(String::new(), |r| {
        format!(", bringing it over at no more than {r:.2} rad/s")
    });
    format!(
        "hold {name} at +{deg:.0}°, then −{deg:.0}° (±{a:.3} rad about level) by attitude control, {switching}{slew}: the {name} rate moves at every switch, the attitude stays within about ±{deg:.0}°"
    )
}

/// The run sheet's note on roll and pitch in runs that excite every DOF.
pub(super) fn attitude_note(ctx: &Ctx<'_>) -> String {
    let parts: Vec<String> = ctx
        .vessel
        .dofs
        .iter()
        .filter(|&&d| ctx.excites_attitude(d))
        .map(|&d| {
            let deg = ctx.amplitude(d).unwrap_or(0.0).to_degrees();
            format!("{} between +{deg:.0}° and −{deg:.0}°", d.name())
        })
        .collect();
    if parts.is_empty() {
        return String::new();
    }
    format!(
        " Roll and pitch references are attitudes ({}): hold them there by attitude control, never as a rate.",
        parts.join(", ")
    )
}

/// Dynamic runs (Tables 3.4–3.5): one DOF excited about the grid speed.
pub(super) fn rov_dynamic(
    ctx: &Ctx<'_>,
    gi: usize,
    reps: u32,
    out: &mut Vec<PlannedExperiment>,
) -> Result<(), PlanError> {
    let u0 = ctx.speeds[gi];
    for &d in &ctx.vessel.dofs {
        for rep in 1..=reps {
            let seed = run_seed(ctx.spec.seed, ExperimentFamily::Dynamic, gi, d.index(), rep);
            let signal = ctx.signal_for(d);
            let ex = ctx.dynamic_dof(d, u0, ctx.spec.durations.dynamic_s, signal, seed, (0, 1))?;
            let duration = ex.duration_s;
            let instruction = if d == Dof::Surge {
                format!(
                    "Alternate the forward speed about {} following the u_ref schedule (±{:.3} m/s); no other motion.",
                    fmt_speed(ctx, gi),
                    ex.plan.amplitude
                )
            } else if ctx.excites_attitude(d) {
                format!(
                    "At a constant {}, {}; no other motion.",
                    fmt_speed(ctx, gi),
                    attitude_words(d, &ex.plan)
                )
            } else {
                format!(
                    "At a constant {}, follow the {} schedule on {} (±{:.3} {} about 0); no other motion.",
                    fmt_speed(ctx, gi),
                    ex.plan.column,
                    d.name(),
                    ex.plan.amplitude,
                    ex.plan.unit
                )
            };
            let mut channels = Vec::new();
            let mut ex = Some(ex);
            for &c in &ctx.vessel.dofs {
                if c == d {
                    channels.push(ex.take().expect("one excited channel"));
                } else {
                    channels.push(ChannelSpec {
                        plan: ctx.held(c, u0),
                        duration_s: duration,
                    });
                }
            }
            out.push(assemble(
                ctx,
                ExperimentHead {
                    code: format!("DYN-{}-{}-r{rep}", ctx.speed_label(gi), d.name()),
                    family: ExperimentFamily::Dynamic,
                    grid_index: Some(gi),
                    dofs: vec![d],
                    sign: None,
                    repetition: rep,
                    instruction,
                    pe_required: pe_required(ExperimentFamily::Dynamic, 1),
                    field: format!("excitation.per_dof.{}", d.name()),
                },
                channels,
            )?);
        }
    }
    Ok(())
}

/// Recursive runs (Table 3.1): every DOF excited at once about the grid speed.
pub(super) fn rov_recursive(
    ctx: &Ctx<'_>,
    gi: usize,
    reps: u32,
    out: &mut Vec<PlannedExperiment>,
) -> Result<(), PlanError> {
    let u0 = ctx.speeds[gi];
    let dofs = &ctx.vessel.dofs;
    for rep in 1..=reps {
        let seed = run_seed(ctx.spec.seed, ExperimentFamily::Recursive, gi, 0, rep);
        let mut channels = Vec::new();
        for (i, &d) in dofs.iter().enumerate() {
            channels.push(ctx.dynamic_dof(
                d,
                u0,
                ctx.spec.durations.recursive_s,
                ctx.signal_for(d),
                seed,
                (i, dofs.len()),
            )?);
        }
        out.push(assemble(
            ctx,
            ExperimentHead {
                code: format!("REC-{}-r{rep}", ctx.speed_label(gi)),
                family: ExperimentFamily::Recursive,
                grid_index: Some(gi),
                dofs: dofs.clone(),
                sign: None,
                repetition: rep,
                instruction: format!(
                    "Fly about {} and follow the references on all DOFs at once (Table 3.1).{}",
                    fmt_speed(ctx, gi),
                    attitude_note(ctx)
                ),
                pe_required: pe_required(ExperimentFamily::Recursive, dofs.len()),
                field: "excitation".into(),
            },
            channels,
        )?);
    }
    Ok(())
}
