//! Missing-physics discovery on a stored model (issue 5): the model's
//! estimation and validation runs, grouped by grid speed, are handed to
//! [`crate::discrepancy::discover`] with that speed's sub-model as the
//! baseline. The result is one report per grid speed, a campaign-level
//! summary (an effect found at every speed is a property of the vehicle; one
//! found at a single speed may be a property of the runs), and — when terms
//! were chosen — the augmented LPV model, validated on the same held-out runs
//! as the original so the two can be compared number for number.

use serde::{Deserialize, Serialize};

use super::augmented::augmented_at;
use super::dataset::RunInput;
use super::document::{ModelDocument, ModelKind};
use super::error::IdentifyError;
use super::lambda_settings::LambdaCampaignSettings;
use super::outcome::Identified;
use crate::discrepancy::{
    AugmentedModel, DiscoveryError, DiscoveryReport, DiscoverySettings, Effect, Record,
    discover_from,
};
use crate::estimation::Progress;
use crate::planning::VesselProfile;
use crate::planning::campaign::ExperimentFamily;

/// Settings of a discovery job.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(default, deny_unknown_fields)]
pub struct DiscoverCampaignSettings {
    /// Grid speeds (m/s) to examine; default every grid speed of the model
    /// that has estimation and validation runs.
    pub grid_speeds_mps: Option<Vec<f64>>,
    /// Runs the augmentation is fitted on; default the model's estimation runs.
    pub estimation_run_ids: Option<Vec<String>>,
    /// Runs held out for the before/after comparison; default the model's
    /// validation runs.
    pub validation_run_ids: Option<Vec<String>>,
    /// Settings of the discovery itself (filter, criteria, library); the
    /// vessel is taken from the campaign when not given.
    pub discovery: DiscoverySettings,
    /// When a force fixed in NED is named on a surface model identified
    /// without a current, identify the campaign again with the NED current
    /// estimated and keep whichever model is better on the held-out runs
    /// (a current and a pull look alike at one speed; the current's force
    /// follows the damping, which the identification fits with it).
    pub reidentify_current: bool,
    /// The λ-filter identification settings for that (the examined model's
    /// own when not given; `ned_current` is set and the held-out runs are
    /// discovery's).
    pub identification: Option<LambdaCampaignSettings>,
}

impl Default for DiscoverCampaignSettings {
    fn default() -> Self {
        DiscoverCampaignSettings {
            grid_speeds_mps: None,
            estimation_run_ids: None,
            validation_run_ids: None,
            discovery: DiscoverySettings::default(),
            reidentify_current: true,
            identification: None,
        }
    }
}

/// Discovery at one grid speed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct PointDiscovery {
    /// Grid speed of the sub-model (m/s).
    pub grid_speed_mps: f64,
    /// Runs the augmentation was fitted on.
    pub estimation_run_ids: Vec<String>,
    /// Runs held out.
    pub validation_run_ids: Vec<String>,
    /// The report: location, hypotheses, findings, before/after.
    pub report: DiscoveryReport,
}

/// One effect across the grid.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct EffectAcrossGrid {
    /// The effect.
    pub effect: Effect,
    /// Its label.
    pub label: String,
    /// Grid speeds (m/s) where it was chosen.
    pub grid_speeds_mps: Vec<f64>,
    /// Its first coefficient at each of those speeds: [value, std] (std
    /// `null` when the fit gives none).
    pub magnitudes: Vec<[Option<f64>; 2]>,
    /// The evidence at each of those speeds: the held-out free-run fit it
    /// gained there when chosen (1 − NRMSE, summed over channels), given
    /// the terms chosen before it at that speed.
    #[serde(default)]
    pub held_out_gains: Vec<f64>,
    /// At each of those speeds, what that speed's findings gain added
    /// alone to the baseline: their held-out fits (1-step, k-step, 10 s
    /// restarted and whole-run free run, each clamped to [−1, 1]) summed,
    /// less the baseline's (`null` where a fit was lost, M was not
    /// positive definite, or it was not judged).
    #[serde(default)]
    pub held_out_advantages: Vec<Option<f64>>,
    /// The campaign's held-out case for the effect, by which effects are
    /// ranked (then by how many speeds chose them, then by the sum of
    /// `held_out_gains`; those not confirmed come last): the positive
    /// `held_out_advantages` summed. A force the campaign shares
    /// (`campaign_estimate`) is held at every grid speed examined, so
    /// every speed's findings carry it: its sum runs over all of them.
    #[serde(default)]
    pub held_out_advantage: f64,
    /// Whether the stored model keeps it: the model with every finding, or
    /// else each grid speed's findings added one speed at a time, is kept
    /// only where the held-out runs are better with them than without and
    /// no worse anywhere (`null` when it was not judged).
    #[serde(default)]
    pub kept: Option<bool>,
    /// Why it was kept or left out, with the deciding held-out fits.
    #[serde(default)]
    pub held_out_verdict: Option<String>,
    /// What the campaign shares of the effect, estimated once: a force (a
    /// current, a pull fixed in NED), pooled over the grid speeds and held
    /// by every speed's model; or an actuator's shape parameter (a lag, a
    /// delay, a saturation level or dead zone), pooled over the speeds that
    /// chose it and held by theirs (`null` for effects that may vary with
    /// speed).
    #[serde(default)]
    pub campaign_estimate: Option<CampaignEstimate>,
    /// Tried, not confirmed: at every grid speed that chose it, that
    /// speed's findings added alone to the baseline gain nothing on the
    /// held-out runs on balance (`held_out_verdict` gives the sums). Such
    /// effects are listed after the named ones and are not findings.
    #[serde(default)]
    pub unconfirmed: bool,
}

impl EffectAcrossGrid {
    /// `effect` named at no grid speed yet: nothing measured, nothing kept.
    pub(super) fn unnamed(effect: Effect, label: String) -> Self {
        EffectAcrossGrid {
            effect,
            label,
            grid_speeds_mps: vec![],
            magnitudes: vec![],
            held_out_gains: vec![],
            held_out_advantages: vec![],
            held_out_advantage: 0.0,
            kept: None,
            held_out_verdict: None,
            campaign_estimate: None,
            unconfirmed: false,
        }
    }

    /// The campaign's evidence for the effect: its held-out gains summed
    /// over the grid speeds.
    pub fn evidence(&self) -> f64 {
        self.held_out_gains.iter().sum()
    }
}

/// Discovery over a model's grid.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct DiscrepancyReport {
    /// The story in a few sentences.
    pub summary: Vec<String>,
    /// Effects chosen, with where and how large.
    pub effects: Vec<EffectAcrossGrid>,
    /// Per grid speed.
    pub points: Vec<PointDiscovery>,
    /// Grid speeds not examined, and why.
    pub skipped: Vec<String>,
}

/// What [`discover_campaign`] returns.
#[derive(Debug, Clone)]
pub struct CampaignDiscovery {
    /// The report.
    pub report: DiscrepancyReport,
    /// The augmented model (when any term was chosen), validated on the
    /// original model's held-out runs.
    pub augmented: Option<Identified>,
}

fn discovery_error(e: DiscoveryError, speed: f64) -> IdentifyError {
    match e {
        DiscoveryError::Cancelled => IdentifyError::Cancelled,
        e => IdentifyError::invalid(
            e.field().to_string(),
            format!("at grid speed {speed} m/s: {e}"),
        ),
    }
}

/// Runs discovery on the stored LPV model `doc` at each grid speed.
///
/// `runs` must hold the estimation and validation runs (ids from
/// `estimation_run_ids` / `validation_run_ids`, overridable in `settings`);
/// `forces` are the generalized-force columns in the order of `doc.dofs`.
///
/// # Errors
/// [`IdentifyError::Invalid`] naming the field: not an LPV model, no grid
/// speed with both kinds of runs, unreadable runs, discovery's own checks.
#[allow(clippy::too_many_arguments)]
pub fn discover_campaign(
    doc: &ModelDocument,
    profile: &VesselProfile,
    forces: &[String],
    runs: &[RunInput],
    estimation_run_ids: &[String],
    validation_run_ids: &[String],
    settings: &DiscoverCampaignSettings,
    progress: &mut dyn Progress,
) -> Result<CampaignDiscovery, IdentifyError> {
    let doc = &*start::with_current_as_term(doc);
    if doc.kind != ModelKind::Lpv {
        return Err(IdentifyError::invalid(
            "model_id",
            "discovery needs a physical LPV model (λ-filter identification); a subspace or DP-ship model has no M, D̄ to augment",
        ));
    }
    let lpv = doc
        .lpv
        .as_ref()
        .ok_or_else(|| IdentifyError::invalid("document.lpv", "missing"))?;
    if forces.len() != doc.dofs.len() {
        return Err(IdentifyError::invalid(
            "inputs",
            format!("{} force columns for {} DOFs", forces.len(), doc.dofs.len()),
        ));
    }
    let est_ids = settings
        .estimation_run_ids
        .as_deref()
        .unwrap_or(estimation_run_ids);
    let val_ids = settings
        .validation_run_ids
        .as_deref()
        .unwrap_or(validation_run_ids);
    for (field, ids) in [
        ("settings.estimation_run_ids", est_ids),
        ("settings.validation_run_ids", val_ids),
    ] {
        if let Some(id) = ids.iter().find(|id| !runs.iter().any(|r| &r.run_id == *id)) {
            return Err(IdentifyError::invalid(
                field,
                format!("run '{id}' is not among the job's runs"),
            ));
        }
    }
    if let Some(id) = est_ids.iter().find(|id| val_ids.contains(id)) {
        return Err(IdentifyError::invalid(
            "settings.validation_run_ids",
            format!("run '{id}' is also an estimation run; held-out runs must not be fitted"),
        ));
    }
    let grid: Vec<f64> = lpv.points.iter().map(|p| p.speed_mps).collect();
    if let Some(speeds) = &settings.grid_speeds_mps {
        for (i, s) in speeds.iter().enumerate() {
            if !grid.iter().any(|g| (g - s).abs() < 1e-6) {
                return Err(IdentifyError::invalid(
                    format!("settings.grid_speeds_mps[{i}]"),
                    format!("{s} m/s is not a grid speed of the model ({grid:?})"),
                ));
            }
        }
    }
    let mut dset = settings.discovery.clone();
    if dset.vessel.is_none() {
        dset.vessel = Some(profile.clone());
    }
    let filter_note = slow_enough_filter(&mut dset, runs);

    // Records per grid point. Static runs (attitude holds) went into g(η);
    // discovery looks at the dynamics.
    let mut est: Vec<(Vec<Record>, Vec<String>)> = vec![Default::default(); grid.len()];
    let mut val: Vec<(Vec<Record>, Vec<String>)> = vec![Default::default(); grid.len()];
    for r in runs {
        let bucket = if est_ids.contains(&r.run_id) {
            if r.family == Some(ExperimentFamily::Static) {
                continue;
            }
            &mut est
        } else if val_ids.contains(&r.run_id) {
            &mut val
        } else {
            continue;
        };
        let h = 1.0 / r.record.sample_rate_hz;
        for (rec, i) in records(r, &doc.dofs, forces, &grid, min_record_len(&dset, h))? {
            if !bucket[i].1.contains(&r.run_id) {
                bucket[i].1.push(r.run_id.clone());
            }
            bucket[i].0.push(rec);
        }
    }

    let wanted: Vec<usize> = (0..grid.len())
        .filter(|&i| {
            settings
                .grid_speeds_mps
                .as_ref()
                .is_none_or(|s| s.iter().any(|v| (v - grid[i]).abs() < 1e-6))
        })
        .collect();
    let mut skipped: Vec<String> = (0..grid.len())
        .filter(|i| !wanted.contains(i))
        .map(|i| format!("{:.2} m/s: not among settings.grid_speeds_mps", grid[i]))
        .collect();
    let todo: Vec<usize> = wanted
        .into_iter()
        .filter(|&i| {
            let why = match (est[i].0.is_empty(), val[i].0.is_empty()) {
                (false, false) => return true,
                (true, true) => "no estimation or validation run",
                (true, false) => "no estimation run",
                (false, true) => "no validation run",
            };
            skipped.push(format!("{:.2} m/s: {why} long enough to use", grid[i]));
            false
        })
        .collect();
    if todo.is_empty() {
        return Err(IdentifyError::invalid(
            "run_ids",
            format!(
                "no grid speed has both estimation and held-out validation runs ({})",
                skipped.join("; ")
            ),
        ));
    }

    // The grid speeds are independent: side by side on the pool, each with
    // its sub-model as the start (a model from an earlier discovery
    // continues from its terms).
    let reports = crate::par::fan_out(
        todo.len(),
        progress,
        (0.0, 0.9),
        &format!("discovery at {} grid speed(s)", todo.len()),
        |k, p| {
            let i = todo[k];
            let start = augmented_at(doc, &lpv.points[i])?;
            discover_from(&start, &est[i].0, &val[i].0, &dset, p)
                .map_err(|e| discovery_error(e, grid[i]))
        },
    )?;
    let mut points: Vec<PointDiscovery> = todo
        .iter()
        .zip(reports)
        .map(|(&i, report)| PointDiscovery {
            grid_speed_mps: grid[i],
            estimation_run_ids: est[i].1.clone(),
            validation_run_ids: val[i].1.clone(),
            report,
        })
        .collect();

    // Shape parameters the campaign shares (a lag, a delay, a thruster's
    // limits): pooled, and held at every speed that chose them.
    let (shapes, scattered): (Vec<_>, Vec<_>) = shapes::pool_shapes(&points)
        .into_iter()
        .partition(|s| s.agree);
    if !shapes.is_empty() {
        let held = crate::par::fan_out(
            points.len(),
            progress,
            (0.9, 0.9),
            "holding the shared shapes at every grid speed",
            |k, _| {
                let i = todo[k];
                let start = augmented_at(doc, &lpv.points[i])?;
                Ok::<_, IdentifyError>(shapes::held_shapes(
                    &points[k], &start, &est[i].0, &dset, &shapes,
                ))
            },
        )?;
        for (p, q) in points.iter_mut().zip(held) {
            if let Some(q) = q {
                *p = q;
            }
        }
    }
    let mut effects = effects_across(&points);
    for s in &shapes {
        if let Some(e) = effects.iter_mut().find(|e| e.effect == s.effect) {
            e.campaign_estimate = Some(s.estimate.clone());
        }
    }
    // Forces the campaign shares: one estimate, held at every grid speed.
    // A current and a pull fixed in NED both turn with the heading: the
    // campaign holds one force fixed in NED, and the other is its look-alike.
    let carried: Vec<Effect> = points
        .iter()
        .flat_map(|p| p.report.carried.iter().copied())
        .collect();
    let (pooled, look_alikes) =
        shared::one_ned_force(shared::pool_all(&points), &effects, &carried);
    let mut shared_notes: Vec<String> = scattered.into_iter().map(|s| s.estimate.text).collect();
    for (term, estimate) in &pooled {
        match effects.iter_mut().find(|e| e.effect == term.effect) {
            Some(e) => e.campaign_estimate = Some(estimate.clone()),
            None => shared_notes.push(estimate.text.clone()),
        }
    }
    // A current found (pooled, or at the one speed that found it) that the
    // model was identified without.
    let found_current = pooled
        .iter()
        .map(|(t, _)| t)
        .chain(points.iter().flat_map(|p| &p.report.model.terms))
        .find(|t| t.effect == Effect::Current && t.coefficients.len() == 2)
        .filter(|_| effects.iter().any(|e| e.effect == Effect::Current));
    // Advice to identify again with the current (superseded when that is
    // done here).
    let mut advice = Vec::new();
    if let Some(t) = found_current {
        let v = [t.coefficients[0], t.coefficients[1]];
        advice.extend(shared::reidentify_note(doc, runs, est_ids, &grid, v));
    } else if effects.iter().any(|e| e.effect == Effect::TetherPull) {
        advice.extend(shared::pull_or_current_note(doc));
    }
    let assembled = if pooled.is_empty() {
        None
    } else {
        Some(crate::par::fan_out(
            points.len(),
            progress,
            (0.9, 0.9),
            "refitting every grid speed with the shared forces held",
            |k, _| {
                let i = todo[k];
                let start = augmented_at(doc, &lpv.points[i])?;
                shared::held_at(&points[k], &start, &est[i].0, &dset, &pooled)
            },
        )?)
    };
    // The grid speeds not examined hold the shared force too.
    let unexamined: Vec<(f64, AugmentedModel, &[Record])> = (0..grid.len())
        .filter(|i| !todo.contains(i) && !pooled.is_empty())
        .map(|i| Ok((grid[i], augmented_at(doc, &lpv.points[i])?, &est[i].0[..])))
        .collect::<Result<_, IdentifyError>>()?;
    let (held_only, notes) = shared::hold_unexamined(&unexamined, &dset, &pooled);
    shared_notes.extend(notes);
    progress.update(0.9, "validating the baseline on the held-out runs")?;
    let asm = Assembly {
        doc,
        points: assembled.as_deref().unwrap_or(&points),
        forces,
        runs,
        est_ids,
        val_ids,
        settings,
        k: dset.k_step,
        held_only: &held_only,
    };
    let again = current_again::applies(doc, settings, &effects, &carried);
    let gate_to = if again { 0.96 } else { 0.99 };
    let (mut augmented, mut overall, before, again_found) = if effects.is_empty() {
        (None, None, None, None)
    } else {
        // The start model through the same validation, on the same runs.
        let before = asm.validate(doc)?;
        let starts = todo
            .iter()
            .map(|&i| Ok((augmented_at(doc, &lpv.points[i])?, &est[i].0[..])))
            .collect::<Result<Vec<_>, IdentifyError>>()?;
        // The re-identification with the current reads nothing the gate
        // decides: it runs beside it.
        let (gate, again_found) = crate::par::beside(
            progress,
            |p| keep_better(&asm, (&starts, &dset), &effects, &before, p, (0.9, gate_to)),
            |p| again.then(|| current_again::identify_again(&asm, profile, &grid, &before, p)),
        );
        let gate = gate?;
        credit::set_advantages(&asm, &mut effects, &gate.alone, assembled.is_some());
        shared_notes.extend(credit::refit_note(&gate.refits));
        for ((e, v), u) in effects
            .iter_mut()
            .zip(&gate.verdicts)
            .zip(&gate.unconfirmed)
        {
            e.kept = Some(v.keep && gate.model.is_some());
            e.held_out_verdict = Some(match u {
                Some(why) if e.kept != Some(true) => {
                    e.unconfirmed = true;
                    format!("{why}; {}", v.reason)
                }
                _ => v.reason.clone(),
            });
        }
        for e in effects
            .iter_mut()
            .filter(|e| look_alikes.contains(&e.effect))
        {
            e.kept = Some(false);
            e.held_out_verdict = Some(format!(
                "{} is held for the campaign instead, its look-alike: both are forces fixed in NED that turn with the heading",
                pooled
                    .first()
                    .map_or_else(String::new, |(t, _)| t.effect.label())
            ));
        }
        // Ranked by what their speeds' findings gain alone on the held-out
        // runs, then (stable) by how many speeds chose them and their
        // gains there.
        effects.sort_by(|a, b| b.held_out_advantage.total_cmp(&a.held_out_advantage));
        (
            gate.model,
            Some(gate.overall.text()),
            Some(before),
            again_found,
        )
    };
    // A force fixed in NED on a surface model without a current: the
    // current, estimated with the damping, is tested against it.
    if let (Some(found), Some(before)) = (again_found, &before) {
        progress.update(
            0.975,
            "identified the campaign again with the NED current estimated",
        )?;
        match found? {
            Ok(a) => {
                let continued =
                    current_again::continue_discovery(&asm, profile, &a, augmented.as_ref(), progress)?;
                let settled =
                    current_again::settle(a, continued, augmented.take(), &mut effects, before);
                augmented = settled.model;
                if settled.overall.is_some() {
                    overall = settled.overall;
                }
                if let Some(p) = settled.points {
                    points = p;
                }
                advice = vec![settled.note];
            }
            Err(why) => advice.push(format!(
                "Identifying the campaign again with the NED current estimated gave no model to compare: {why}."
            )),
        }
    }
    shared_notes.extend(advice);
    // Tried and not confirmed: after the named effects (a model's
    // re-identification that keeps an effect confirms it).
    for e in &mut effects {
        e.unconfirmed &= e.kept != Some(true);
    }
    effects.sort_by_key(|e| e.unconfirmed);
    let mut summary = summarize(&points, &effects, &skipped);
    summary.extend(shared_notes);
    summary.extend(overall);
    summary.extend(filter_note);
    let augmented = augmented.map(|mut a| {
        a.document.notes.extend(summary.iter().cloned());
        a
    });
    Ok(CampaignDiscovery {
        report: DiscrepancyReport {
            summary,
            effects,
            points,
            skipped,
        },
        augmented,
    })
}

pub(super) fn speeds_text(v: &[f64]) -> String {
    v.iter()
        .map(|s| format!("{s:.2}"))
        .collect::<Vec<_>>()
        .join(", ")
}

mod assemble;
mod credit;
mod current_again;
mod keep;
mod records;
mod shapes;
mod shared;
mod start;
mod summary;
use records::{min_record_len, records, slow_enough_filter};

pub use shared::CampaignEstimate;

use assemble::Assembly;
use keep::keep_better;
use summary::{effects_across, summarize};

#[cfg(test)]
mod tests;
