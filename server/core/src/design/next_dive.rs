//! Re-planning after a dive: the information the runs already flown give
//! the identification (their own logged data, bad runs left out by the
//! caller), and the planned experiments that buy the most of what is still
//! short per ship-hour for the next dive — greedily, each pick the one
//! that lowers the D criterion ([`super::information`]) most per hour of
//! run and set-up time, until the dive's hours are spent. A grid point
//! without data scores as no information at all, so its runs come first;
//! the validation run comes before anything when none has been flown
//! (the identification holds one out).

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::DesignError;
use super::information::{
    InformationCache, PlanInformation, Scaling, d_criterion, experiment_information,
    plan_information,
};
use crate::estimation::Progress;
use crate::identification::RunInput;
use crate::identification::lambda_information::{exogenous_count, lambda_information};
use crate::logs::input_columns;
use crate::planning::{ExperimentFamily, Plan, VesselProfile};
use crate::simulation::rov::RovTruth;

/// A planned experiment proposed for the next dive.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct ProposedRun {
    /// Experiment code (as in the plan and its run sheet).
    pub code: String,
    /// Run order in the plan.
    pub seq: u32,
    /// Family.
    pub family: ExperimentFamily,
    /// Grid speed (m/s), none for the validation run.
    pub grid_speed_mps: Option<f64>,
    /// Run length (s).
    pub duration_s: f64,
    /// Geometric-mean std of the campaign after this run, relative to the
    /// whole plan flown: 1.2 means 20 % above what the plan promises; 0
    /// while a grid point still has no data (not yet identifiable).
    pub relative_std_after: f64,
    /// Why it was chosen, in words.
    pub reason: String,
}

/// The next dive's proposal.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct NextDive {
    /// Hours available for the dive (runs and set-up).
    pub dive_hours: f64,
    /// Runs whose data counted as flown.
    pub flown_runs: usize,
    /// Geometric-mean std now, relative to the whole plan flown (absent
    /// while a grid point has no data: the LPV model cannot be identified).
    pub relative_std_now: Option<f64>,
    /// The same after the proposed runs.
    pub relative_std_after: Option<f64>,
    /// Grid speeds (m/s) still without estimation data after the dive.
    pub uncovered_speeds_mps: Vec<f64>,
    /// The runs, in the order to fly them.
    pub proposed: Vec<ProposedRun>,
    /// Their hours (runs and set-up).
    pub hours: f64,
    /// Planned experiments not yet flown and not proposed.
    pub left_for_later: usize,
    /// How the proposal was made.
    pub notes: Vec<String>,
}

/// Proposes the next dive of `plan` within `dive_hours`, given the `flown`
/// runs' data (good and weak runs; rejected and insufficient ones left out
/// by the caller) and the codes of the planned experiments already covered
/// (`done`, not proposed again); candidates are flown with `truth`.
/// Order: the validation run while none has been flown, then discovery's
/// deciding runs (`Experiment::separates`) in plan order, then the runs
/// with the most precision per hour.
///
/// # Errors
/// A dive of no hours; a planned experiment the identification's data path
/// refuses (named); cancellation. A flown run it refuses is left out and
/// named in the notes.
pub fn propose_next_dive(
    profile: &VesselProfile,
    plan: &Plan,
    flown: &[RunInput],
    done: &[String],
    truth: &RovTruth,
    dive_hours: f64,
    progress: &mut dyn Progress,
) -> Result<NextDive, DesignError> {
    if !(dive_hours.is_finite() && dive_hours > 0.0) {
        return Err(DesignError::new(
            "settings.dive_hours",
            format!("must be a positive number of hours (got {dive_hours})"),
        ));
    }
    let grid = plan.grid_speeds();
    let n = profile.dofs.len();
    let p = 2 * n + exogenous_count(profile);
    let mut cache = InformationCache::default();
    progress
        .update(0.0, "flying the whole plan in simulation")
        .map_err(|_| super::predict::cancelled())?;
    let full = plan_information(profile, plan, truth, &mut cache)?;
    let scaling = Scaling::of(&full, &grid)?;
    let d_full = d_criterion(profile, &full, &scaling).ok_or_else(|| {
        DesignError::new(
            "plan",
            "the whole plan's information is singular at a grid point",
        )
    })?;

    // What the flown runs gave: their own data.
    let mut now = PlanInformation {
        grams: vec![None; grid.len()],
    };
    let inputs = input_columns(profile);
    let mut notes = Vec::new();
    for run in flown
        .iter()
        .filter(|r| r.family != Some(ExperimentFamily::Validation))
    {
        match lambda_information(profile, &grid, &inputs, std::slice::from_ref(run)) {
            Ok(info) => {
                for i in info {
                    now.add(i.grid_index, &i.gram);
                }
            }
            Err(e) => notes.push(format!(
                "run '{}' left out: the identification could not use it ({e})",
                run.name
            )),
        }
    }
    let score = |info: &PlanInformation| -> f64 {
        let filled = PlanInformation {
            grams: info
                .grams
                .iter()
                .map(|g| Some(g.clone().unwrap_or_else(|| DMatrix::zeros(p, p))))
                .collect(),
        };
        d_criterion(profile, &filled, &scaling).unwrap_or(f64::MAX)
    };
    let rel = |info: &PlanInformation| -> Option<f64> {
        d_criterion(profile, info, &scaling).map(|d| (0.5 * (d - d_full)).exp())
    };
    let relative_std_now = rel(&now);
    let setup_s = plan.totals.setup_time_s / plan.experiments.len().max(1) as f64;

    let mut candidates: Vec<usize> = (0..plan.experiments.len())
        .filter(|&i| !done.contains(&plan.experiments[i].experiment.code))
        .collect();
    let mut proposed = Vec::new();
    let mut used_s = 0.0;
    let budget_s = dive_hours * 3600.0;
    let has_validation = flown
        .iter()
        .any(|r| r.family == Some(ExperimentFamily::Validation))
        || plan.experiments.iter().any(|e| {
            e.experiment.family == ExperimentFamily::Validation && done.contains(&e.experiment.code)
        });
    if !has_validation
        && let Some(k) = candidates
            .iter()
            .position(|&i| plan.experiments[i].experiment.family == ExperimentFamily::Validation)
    {
        let i = candidates.remove(k);
        let e = &plan.experiments[i].experiment;
        if e.duration_s + setup_s <= budget_s {
            used_s += e.duration_s + setup_s;
            proposed.push(proposal(
                plan,
                i,
                rel(&now).unwrap_or(0.0),
                "no validation run has been flown, and the identification holds one out".into(),
            ));
        }
    }
    // Discovery's deciding runs next: they settle which physics the model
    // needs, which no precision criterion of the current structure sees.
    let mut k = 0;
    while k < candidates.len() {
        let i = candidates[k];
        let pe = &plan.experiments[i];
        let fits = used_s + pe.experiment.duration_s + setup_s <= budget_s;
        let Some([a, b]) = pe.experiment.separates.as_ref().filter(|_| fits) else {
            k += 1;
            continue;
        };
        let reason = format!(
            "a deciding run: discovery found {a} and {b} explain the flown runs about equally; this run separates them"
        );
        for (g, gram) in experiment_information(profile, &grid, pe, truth, &mut cache)? {
            now.add(*g, gram);
        }
        used_s += pe.experiment.duration_s + setup_s;
        candidates.remove(k);
        proposed.push(proposal(plan, i, rel(&now).unwrap_or(0.0), reason));
    }
    let total = candidates.len();
    loop {
        progress
            .update(
                0.2 + 0.8 * (total - candidates.len()) as f64 / total.max(1) as f64,
                "choosing the runs that buy the most precision per hour",
            )
            .map_err(|_| super::predict::cancelled())?;
        let d_now = score(&now);
        let mut best: Option<(usize, f64, PlanInformation)> = None;
        for (k, &i) in candidates.iter().enumerate() {
            let pe = &plan.experiments[i];
            if pe.experiment.family == ExperimentFamily::Validation
                || used_s + pe.experiment.duration_s + setup_s > budget_s
            {
                continue;
            }
            let mut with = now.clone();
            for (g, gram) in experiment_information(profile, &grid, pe, truth, &mut cache)? {
                with.add(*g, gram);
            }
            let per_hour = (d_now - score(&with)) / ((pe.experiment.duration_s + setup_s) / 3600.0);
            if per_hour > 0.0 && best.as_ref().is_none_or(|(_, b, _)| per_hour > *b) {
                best = Some((k, per_hour, with));
            }
        }
        let Some((k, _, with)) = best else { break };
        let i = candidates.remove(k);
        let e = &plan.experiments[i].experiment;
        let uncovered_before = now.grams.iter().filter(|g| g.is_none()).count();
        let uncovered_after = with.grams.iter().filter(|g| g.is_none()).count();
        now = with;
        used_s += e.duration_s + setup_s;
        let reason = if uncovered_after < uncovered_before {
            format!(
                "the first data at {} m/s: without it the LPV model has no sub-model there",
                e.grid_speed_mps.map_or("–".into(), |s| format!("{s:.2}"))
            )
        } else {
            "the most precision per hour among the runs not yet flown".into()
        };
        proposed.push(proposal(plan, i, rel(&now).unwrap_or(0.0), reason));
    }
    let uncovered_speeds_mps = grid
        .iter()
        .zip(&now.grams)
        .filter(|(_, g)| g.is_none())
        .map(|(s, _)| *s)
        .collect();
    Ok(NextDive {
        dive_hours,
        flown_runs: flown.len(),
        relative_std_now,
        relative_std_after: rel(&now),
        uncovered_speeds_mps,
        hours: used_s / 3600.0,
        left_for_later: candidates.len(),
        proposed,
        notes: [
            "the flown runs count with their own logged data; runs with rejected or insufficient excitation are left out".into(),
            "candidates are the plan's experiments not yet covered by a good run, each flown noise-free with the prior; the λ regression's information (port–starboard structure, constant loads and g(η)'s shapes) ranks them per hour of run and set-up".into(),
            "stds are geometric means over the parameters, relative to the whole plan flown".into(),
        ]
        .into_iter()
        .chain(notes)
        .collect(),
    })
}

fn proposal(plan: &Plan, i: usize, relative_std_after: f64, reason: String) -> ProposedRun {
    let e = &plan.experiments[i].experiment;
    ProposedRun {
        code: e.code.clone(),
        seq: e.seq,
        family: e.family,
        grid_speed_mps: e.grid_speed_mps,
        duration_s: e.duration_s,
        relative_std_after,
        reason,
    }
}
