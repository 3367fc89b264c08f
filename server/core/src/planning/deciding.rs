//! Deciding runs: a discovery report's proposed experiment (the run on
//! which two look-alike hypotheses predict most differently) added to the
//! campaign as planned runs, one per heading leg, after the plan's own.
//!
//! The proposal is kept as discovery wrote it (`CampaignSpec::deciding`);
//! the planner re-checks it against the vessel: force columns of its
//! DOFs only, offsets within the force limits, every channel clipped to
//! the vessel's force and rate limits whatever the proposal says.

use super::plan::{ChannelSpec, Ctx, ExperimentHead, PlannedExperiment, assemble};
use super::{Dof, ExperimentFamily, PlanError, VesselProfile};
use crate::discrepancy::experiment::ExperimentProposal;

/// Most deciding experiments a campaign holds.
pub const MAX_DECIDING: usize = 8;
/// Most heading legs of one deciding experiment.
pub const MAX_HEADINGS: usize = 4;
/// Longest leg of a deciding run (s): discovery proposes 60 s legs; the
/// bound keeps 8 proposals × 4 legs within a plan's usual size.
pub const MAX_LEG_S: f64 = 1800.0;
/// Longest text of a proposal (instruction, hypothesis labels).
const MAX_TEXT: usize = 2000;

/// Checks the deciding experiments of a campaign against the vessel; every
/// error names `deciding[k]` and the field.
pub(super) fn validate(
    deciding: &[ExperimentProposal],
    vessel: &VesselProfile,
) -> Result<(), PlanError> {
    if deciding.len() > MAX_DECIDING {
        return Err(PlanError::over_limit(
            "deciding",
            format!(
                "at most {MAX_DECIDING} deciding experiments, got {}",
                deciding.len()
            ),
            MAX_DECIDING as f64,
        ));
    }
    if !deciding.is_empty() && vessel.kind != super::vessel::VesselKind::Rov6 {
        return Err(PlanError::invalid(
            "deciding",
            format!(
                "deciding runs are planned for 6-DOF ROVs (discovery's proposals are generalised forces); vessel '{}' flies thruster schedules",
                vessel.name
            ),
        ));
    }
    for (k, p) in deciding.iter().enumerate() {
        let field = |f: &str| format!("deciding[{k}].{f}");
        if !matches!(
            p.family,
            ExperimentFamily::Static | ExperimentFamily::Dynamic
        ) {
            return Err(PlanError::invalid(
                field("family"),
                format!(
                    "a deciding run is static or dynamic, got {}",
                    p.family.name()
                ),
            ));
        }
        if !vessel.dofs.contains(&p.dof) {
            return Err(PlanError::invalid(
                field("dof"),
                format!("{} is not a DOF of vessel '{}'", p.dof.name(), vessel.name),
            ));
        }
        if !(p.duration_s.is_finite() && p.duration_s > 0.0 && p.duration_s <= MAX_LEG_S) {
            return Err(PlanError::over_limit(
                field("duration_s"),
                format!("must be a number of seconds in (0, {MAX_LEG_S}]"),
                MAX_LEG_S,
            ));
        }
        if !(p.grid_speed_mps.is_finite() && p.grid_speed_mps >= 0.0) {
            return Err(PlanError::invalid(
                field("grid_speed_mps"),
                "must be a finite speed ≥ 0 m/s",
            ));
        }
        if p.headings_deg.is_empty() || p.headings_deg.len() > MAX_HEADINGS {
            return Err(PlanError::over_limit(
                field("headings_deg"),
                format!("1 to {MAX_HEADINGS} headings, got {}", p.headings_deg.len()),
                MAX_HEADINGS as f64,
            ));
        }
        if let Some(h) = p
            .headings_deg
            .iter()
            .find(|h| !(h.is_finite() && h.abs() <= 360.0))
        {
            return Err(PlanError::invalid(
                field("headings_deg"),
                format!("a heading is in [−360, 360] degrees, got {h}"),
            ));
        }
        for (what, text) in [
            ("instruction", p.instruction.as_str()),
            ("separates[0]", p.separates[0].as_str()),
            ("separates[1]", p.separates[1].as_str()),
        ] {
            if text.chars().count() > MAX_TEXT || text.chars().any(char::is_control) {
                return Err(PlanError::invalid(
                    field(what),
                    format!("at most {MAX_TEXT} characters, no control characters"),
                ));
            }
        }
        if p.channels.is_empty() {
            return Err(PlanError::invalid(field("channels"), "no channel given"));
        }
        if !p.channels.iter().any(|c| c.excited && c.dof == Some(p.dof)) {
            return Err(PlanError::invalid(
                field("channels"),
                format!("no excited channel of {}", p.dof.name()),
            ));
        }
        for (j, c) in p.channels.iter().enumerate() {
            let cf = |f: &str| format!("deciding[{k}].channels[{j}].{f}");
            let dof = c
                .dof
                .filter(|d| vessel.dofs.contains(d) && c.column == d.force_column());
            let Some(dof) = dof else {
                return Err(PlanError::invalid(
                    cf("column"),
                    format!(
                        "'{}' is not a force column of the vessel's DOFs (tau_X … tau_N with its dof)",
                        c.column
                    ),
                ));
            };
            if p.channels[..j].iter().any(|o| o.column == c.column) {
                return Err(PlanError::invalid(
                    cf("column"),
                    format!("'{}' appears twice", c.column),
                ));
            }
            let max = vessel.limit(dof).max_force;
            if !(c.offset.is_finite() && c.offset.abs() <= max * (1.0 + 1e-9)) {
                return Err(PlanError::over_limit(
                    cf("offset"),
                    format!("the operating point must lie within ±{max} {}", c.unit),
                    max,
                ));
            }
            if !(c.amplitude.is_finite() && c.amplitude >= 0.0) {
                return Err(PlanError::invalid(
                    cf("amplitude"),
                    "must be finite and ≥ 0",
                ));
            }
        }
    }
    Ok(())
}

/// The deciding experiments as planned runs, appended to `out`: proposal
/// k's leg at heading h is `DEC{k}-{dof}-{h:03}`, in the proposal's family
/// at the grid point nearest its predicted speed.
pub(super) fn deciding_runs(
    ctx: &Ctx<'_>,
    out: &mut Vec<PlannedExperiment>,
) -> Result<(), PlanError> {
    for (k, p) in ctx.spec.deciding.iter().enumerate() {
        let grid_index = nearest(&ctx.speeds, p.grid_speed_mps);
        for &heading in &p.headings_deg {
            let h = heading.rem_euclid(360.0).round() as u32 % 360;
            let channels = p
                .channels
                .iter()
                .map(|c| {
                    let mut plan = c.clone();
                    // Validated: a force column of one of the vessel's DOFs.
                    let l = ctx.vessel.limit(plan.dof.unwrap_or(Dof::Surge));
                    plan.limit = if plan.limit.is_finite() && plan.limit > 0.0 {
                        plan.limit.min(l.max_force)
                    } else {
                        l.max_force
                    };
                    plan.rate_limit = Some(match plan.rate_limit {
                        Some(r) if r.is_finite() && r > 0.0 => r.min(l.max_force_rate),
                        _ => l.max_force_rate,
                    });
                    plan.analysis = None;
                    ChannelSpec {
                        plan,
                        duration_s: p.duration_s,
                    }
                })
                .collect();
            let head = ExperimentHead {
                code: format!("DEC{}-{}-{h:03}", k + 1, p.dof.name()),
                family: p.family,
                grid_index,
                dofs: vec![p.dof],
                sign: None,
                repetition: 1,
                instruction: format!(
                    "Deciding run {} of discovery (separates {} from {}), heading {h}°: {}",
                    k + 1,
                    p.separates[0],
                    p.separates[1],
                    p.instruction
                ),
                pe_required: 1,
                field: format!("deciding[{k}]"),
            };
            let mut e = assemble(ctx, head, channels)?;
            e.experiment.separates = Some(p.separates.clone());
            out.push(e);
        }
    }
    Ok(())
}

/// Index of the grid speed nearest `u` (the first on a tie).
fn nearest(speeds: &[f64], u: f64) -> Option<usize> {
    speeds
        .iter()
        .enumerate()
        .min_by(|a, b| (a.1 - u).abs().total_cmp(&(b.1 - u).abs()))
        .map(|(i, _)| i)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::planning::examples::{deciding_proposal, surveyor_campaign, surveyor_rov};
    use crate::planning::revision::identity;
    use crate::planning::{CampaignSpec, generate_plan};

    fn with(spec: &CampaignSpec, deciding: Vec<ExperimentProposal>) -> CampaignSpec {
        CampaignSpec {
            deciding,
            ..spec.clone()
        }
    }

    #[test]
    fn a_proposal_becomes_one_run_per_heading_after_the_plan_which_keeps_its_runs() {
        let v = surveyor_rov();
        let spec = surveyor_campaign(7);
        let base = generate_plan(&v, &spec).unwrap();
        let p = deciding_proposal(&v, Dof::Sway, 0.5, vec![0.0, 90.0]);
        let plan = generate_plan(&v, &with(&spec, vec![p])).unwrap();
        let n = base.experiments.len();
        assert_eq!(plan.experiments.len(), n + 2);
        // The plan's own runs: the same, in the same places.
        for (a, b) in base.experiments.iter().zip(&plan.experiments) {
            assert_eq!(a, b);
            assert_eq!(identity(&a.experiment), identity(&b.experiment));
        }
        let grid = plan.grid_speeds();
        let near = grid
            .iter()
            .enumerate()
            .min_by(|a, b| (a.1 - 0.4).abs().total_cmp(&(b.1 - 0.4).abs()))
            .unwrap()
            .0;
        for (e, h) in plan.experiments[n..].iter().zip(["000", "090"]) {
            let x = &e.experiment;
            assert_eq!(x.code, format!("DEC1-sway-{h}"));
            assert_eq!(x.family, ExperimentFamily::Dynamic);
            assert_eq!(x.dofs, vec![Dof::Sway]);
            assert_eq!(x.grid_index, Some(near));
            assert!(x.separates.is_some());
            assert!(
                x.instruction
                    .contains("separates quadratic damping in sway from Coriolis")
            );
            assert!(identity(x).starts_with("deciding|"));
            assert!((x.duration_s - 120.0).abs() < 1.0 / x.sample_rate_hz + 1e-9);
            // Every force column, within the vessel's limits.
            for d in &v.dofs {
                let c = e
                    .schedule
                    .columns
                    .iter()
                    .position(|c| c == d.force_column())
                    .unwrap();
                let max = v.limit(*d).max_force;
                assert!(
                    e.schedule.values[c]
                        .iter()
                        .all(|f| f.abs() <= max * (1.0 + 1e-12))
                );
            }
            let sway = e
                .schedule
                .columns
                .iter()
                .position(|c| c == "tau_Y")
                .unwrap();
            let s = &e.schedule.values[sway];
            let (lo, hi) = s
                .iter()
                .fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(*v), b.max(*v)));
            assert!(
                hi - lo > 0.5 * v.limit(Dof::Sway).max_force,
                "sway swings {lo} … {hi}"
            );
        }
        // The totals count them.
        assert_eq!(plan.totals.experiments, n + 2);
        assert!(plan.totals.run_time_s > base.totals.run_time_s + 239.0);
    }

    #[test]
    fn a_proposal_beyond_the_vessel_is_refused_naming_the_field() {
        let v = surveyor_rov();
        let spec = surveyor_campaign(7);
        let err = |p: ExperimentProposal| generate_plan(&v, &with(&spec, vec![p])).unwrap_err();

        let mut p = deciding_proposal(&v, Dof::Sway, 0.5, vec![0.0]);
        p.channels[0].offset = 2.0 * v.limit(Dof::Surge).max_force;
        assert_eq!(err(p).field, "deciding[0].channels[0].offset");

        let mut p = deciding_proposal(&v, Dof::Sway, 0.5, vec![0.0]);
        p.channels[2].column = "u_ref".into();
        assert_eq!(err(p).field, "deciding[0].channels[2].column");

        let mut p = deciding_proposal(&v, Dof::Sway, 0.5, vec![0.0]);
        p.family = ExperimentFamily::Validation;
        assert_eq!(err(p).field, "deciding[0].family");

        let p = deciding_proposal(&v, Dof::Sway, 0.5, vec![0.0, 90.0, 180.0, 270.0, 45.0]);
        assert_eq!(err(p).field, "deciding[0].headings_deg");

        let mut p = deciding_proposal(&v, Dof::Sway, 0.5, vec![0.0]);
        p.duration_s = f64::NAN;
        assert_eq!(err(p).field, "deciding[0].duration_s");

        let mut p = deciding_proposal(&v, Dof::Sway, 0.5, vec![0.0]);
        p.instruction = "fly\u{1b}[31m".into();
        assert_eq!(err(p).field, "deciding[0].instruction");

        let many = vec![deciding_proposal(&v, Dof::Sway, 0.5, vec![0.0]); MAX_DECIDING + 1];
        let e = generate_plan(&v, &with(&spec, many)).unwrap_err();
        assert_eq!(e.field, "deciding");

        // A DP ship flies thruster schedules: no generalised-force runs.
        let dp = crate::planning::examples::supply_vessel();
        let dp_spec = crate::planning::examples::supply_vessel_campaign(7);
        let e = generate_plan(
            &dp,
            &with(
                &dp_spec,
                vec![deciding_proposal(&v, Dof::Sway, 0.5, vec![0.0])],
            ),
        )
        .unwrap_err();
        assert_eq!(e.field, "deciding");
        assert!(e.message.contains("6-DOF ROVs"), "{}", e.message);
    }

    /// The clip bound is the vessel's, whatever the proposal says: an
    /// amplitude of twice the force limit is flown at the limit.
    #[test]
    fn channels_are_clipped_to_the_vessel_whatever_the_proposal_says() {
        let v = surveyor_rov();
        let spec = surveyor_campaign(7);
        let mut p = deciding_proposal(&v, Dof::Heave, 2.0, vec![0.0]);
        for c in &mut p.channels {
            c.limit = 1e9;
            c.rate_limit = None;
        }
        let plan = generate_plan(&v, &with(&spec, vec![p])).unwrap();
        let e = plan.experiments.last().unwrap();
        let heave = e
            .schedule
            .columns
            .iter()
            .position(|c| c == "tau_Z")
            .unwrap();
        let max = v.limit(Dof::Heave).max_force;
        let x = &e.schedule.values[heave];
        assert!(x.iter().all(|f| f.abs() <= max * (1.0 + 1e-12)));
        assert!(x.iter().any(|f| (f.abs() - max).abs() < 1e-9 * max));
        let ch = e
            .experiment
            .channels
            .iter()
            .find(|c| c.column == "tau_Z")
            .unwrap();
        assert_eq!(ch.limit, max);
        assert_eq!(ch.rate_limit, Some(v.limit(Dof::Heave).max_force_rate));
    }
}
