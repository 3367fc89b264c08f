//! Only what is better is kept. The model with every grid speed's findings
//! is kept if, on the held-out runs, it is better than the start model
//! beyond noise in some fit and worse in none (1-step, k-step, 10 s
//! restarted and whole-run free run), simulates wherever that model did, and keeps M
//! positive definite. Otherwise the grid speeds' augmentations are added
//! one at a time, strongest evidence first, each staying only if the model
//! with it passes the same test against the model without it and against
//! the baseline (so losses within noise cannot add up).
//!
//! The unit is a grid speed's augmentation as discovery fitted it: its
//! terms were fitted together with refitted rows of M and D̄, and a subset
//! of them on those rows is a model nobody fitted (one term's row without
//! its companion can diverge). The held-out runs decide which augmentations
//! enter but never fit a coefficient: the terms were fitted on the
//! estimation runs alone.

use std::collections::BTreeSet;

use super::super::discover_gate::{
    HeldOutVerdict, advantage, compare_against, fit_pairs, inertia_verdict, paired,
};
use super::super::error::IdentifyError;
use super::super::outcome::{Identified, RunValidation};
use super::assemble::Assembly;
use super::{EffectAcrossGrid, speeds_text};
use crate::discrepancy::Verdict;
use crate::estimation::Progress;
use crate::numbers::sig3;

/// The outcome of the gate.
pub(super) struct Kept {
    /// The model with every kept augmentation (`None` when none was kept).
    pub model: Option<Identified>,
    /// Per effect (in the order of `effects`): whether the model keeps it
    /// and why.
    pub verdicts: Vec<HeldOutVerdict>,
    /// The verdict on the whole model against the start model.
    pub overall: HeldOutVerdict,
    /// Per effect: `Some(why)` when it is not confirmed (see
    /// [`confirmation`]).
    pub unconfirmed: Vec<Option<String>>,
    /// Per grid speed with findings (its index in the assembly's points):
    /// the held-out advantage of its findings alone on the baseline, −∞
    /// where a fit was lost or M is not positive definite.
    pub alone: Vec<(usize, f64)>,
}

/// The held-out evidence discovery gave a grid speed's findings: the
/// cross-validated gains of its chosen hypotheses, summed.
fn evidence(asm: &Assembly<'_>, i: usize) -> f64 {
    asm.points[i]
        .report
        .hypotheses
        .iter()
        .filter(|h| h.verdict == Verdict::Chosen)
        .filter_map(|h| h.cv_gain)
        .filter(|g| g.is_finite())
        .sum()
}

/// Runs the gate over the grid speeds with findings, between progress
/// `from` and `to`.
pub(super) fn keep_better(
    asm: &Assembly<'_>,
    effects: &[EffectAcrossGrid],
    before: &[RunValidation],
    progress: &mut dyn Progress,
    (from, to): (f64, f64),
) -> Result<Kept, IdentifyError> {
    let mut order: Vec<usize> = (0..asm.points.len())
        .filter(|&i| !asm.points[i].report.findings.is_empty())
        .collect();
    order.sort_by(|&a, &b| evidence(asm, b).total_cmp(&evidence(asm, a)));
    let all: BTreeSet<usize> = order.iter().copied().collect();
    progress.update(from, "held-out check of the model with every effect found")?;
    let full = asm.model(&all)?;
    let verdict = inertia_verdict(&full.document)
        .unwrap_or_else(|| compare_against(before, &full.validation, "the baseline"));
    // Each speed's findings alone on the baseline (the model with every
    // finding when only one speed has any): for the confirmation, and the
    // gate's candidates while nothing is kept.
    let mut alone: Vec<Option<Identified>> = Vec::new();
    if order.len() > 1 {
        for &i in &order {
            alone.push(Some(asm.model(&std::iter::once(i).collect())?));
        }
    }
    let (unconfirmed, alone_gains) = {
        let models: Vec<&Identified> = if alone.is_empty() {
            vec![&full]
        } else {
            alone.iter().flatten().collect()
        };
        let gains = alone_advantages(&order, before, &models);
        (confirmation(asm, effects, &gains), gains)
    };
    if verdict.keep || order.len() == 1 {
        return Ok(Kept {
            model: verdict.keep.then_some(full),
            verdicts: vec![verdict.clone(); effects.len()],
            overall: verdict,
            unconfirmed,
            alone: alone_gains,
        });
    }
    let step = (to - from) / (order.len() + 1) as f64;
    let mut kept = BTreeSet::new();
    let mut best: Option<Identified> = None;
    // Per grid point tried: its verdict against the model without it.
    let mut at: Vec<(usize, HeldOutVerdict)> = Vec::new();
    for (n, &i) in order.iter().enumerate() {
        let speed = asm.points[i].grid_speed_mps;
        progress.update(
            from + step * (n + 1) as f64,
            &format!(
                "held-out check of the findings at {speed:.2} m/s ({} of {})",
                n + 1,
                order.len()
            ),
        )?;
        let mut trial = kept.clone();
        trial.insert(i);
        let candidate = match alone[n].take() {
            Some(m) if kept.is_empty() => m,
            _ => asm.model(&trial)?,
        };
        let reference = best.as_ref().map_or(before, |b| b.validation.as_slice());
        let against = if best.is_some() {
            "the model without them"
        } else {
            "the baseline"
        };
        let mut v = inertia_verdict(&candidate.document)
            .unwrap_or_else(|| compare_against(reference, &candidate.validation, against));
        // Small losses within noise must not add up past the baseline.
        if v.keep && best.is_some() {
            let vb = compare_against(before, &candidate.validation, "the baseline");
            if !vb.keep {
                v = vb;
            }
        }
        if v.keep {
            kept = trial;
            best = Some(candidate);
        }
        at.push((i, v));
    }
    let kept_speeds: Vec<f64> = kept.iter().map(|&i| asm.points[i].grid_speed_mps).collect();
    let overall = match &best {
        Some(b) => {
            let mut v = compare_against(before, &b.validation, "the baseline");
            v.reason = format!(
                "with the findings at {} of {} grid speeds ({} m/s; the model with all of them was refused: {}), {}",
                kept.len(),
                order.len(),
                speeds_text(&kept_speeds),
                verdict.reason,
                v.reason
            );
            v
        }
        None => HeldOutVerdict {
            keep: false,
            reason: format!(
                "with every effect found, {}; added one grid speed at a time, none made a held-out fit better without making another worse",
                verdict.reason
            ),
        },
    };
    let stored = best.is_some() && overall.keep;
    // An effect is kept where a grid speed that chose it is kept; its
    // reason is that speed's verdict (or the first speed's that chose it).
    let verdicts = effects
        .iter()
        .map(|e| {
            let chose = |i: usize| {
                asm.points[i]
                    .report
                    .findings
                    .iter()
                    .any(|f| f.effect == e.effect)
            };
            let pick = at
                .iter()
                .find(|(i, v)| v.keep && stored && chose(*i))
                .or_else(|| at.iter().find(|(i, _)| chose(*i)));
            match pick {
                Some((i, v)) => HeldOutVerdict {
                    keep: v.keep && stored,
                    reason: format!(
                        "at {:.2} m/s with that speed's other findings, {}",
                        asm.points[*i].grid_speed_mps, v.reason
                    ),
                },
                None => HeldOutVerdict {
                    keep: false,
                    reason: verdict.reason.clone(),
                },
            }
        })
        .collect();
    Ok(Kept {
        model: best.filter(|_| overall.keep),
        verdicts,
        overall,
        unconfirmed,
        alone: alone_gains,
    })
}

/// Sets each effect's `held_out_advantages` (at each speed that chose it,
/// that speed's `alone` advantage; `None` where a fit was lost) and the
/// `held_out_advantage` it is ranked by: their positive sum (a speed whose
/// findings lose on balance, perhaps through another of them, adds
/// nothing), over every speed judged for a force the campaign shares when
/// `shared_held` (it is held at each of them).
pub(super) fn set_advantages(
    asm: &Assembly<'_>,
    effects: &mut [EffectAcrossGrid],
    alone: &[(usize, f64)],
    shared_held: bool,
) {
    let finite = |a: f64| Some(a).filter(|a| a.is_finite());
    let positive = |a: &[Option<f64>]| a.iter().flatten().filter(|a| **a > 0.0).sum();
    let every: Vec<Option<f64>> = alone.iter().map(|&(_, a)| finite(a)).collect();
    for e in effects.iter_mut() {
        e.held_out_advantages = e
            .grid_speeds_mps
            .iter()
            .map(|&s| {
                alone
                    .iter()
                    .find(|(i, _)| asm.points[*i].grid_speed_mps == s)
                    .and_then(|&(_, a)| finite(a))
            })
            .collect();
        e.held_out_advantage = if e.campaign_estimate.is_some() && shared_held {
            positive(&every)
        } else {
            positive(&e.held_out_advantages)
        };
    }
}

/// Each grid speed's findings alone on the baseline, judged on balance:
/// their held-out fits against the baseline's (1-step, k-step, 10 s
/// restarted and whole-run free run, each clamped to [−1, 1], summed), a
/// fit lost or M not positive definite counting as −∞. `models`: each
/// speed's (in `order`). Returns (point index, advantage).
fn alone_advantages(
    order: &[usize],
    before: &[RunValidation],
    models: &[&Identified],
) -> Vec<(usize, f64)> {
    order
        .iter()
        .zip(models)
        .map(|(&i, model)| {
            let lost = inertia_verdict(&model.document).is_some()
                || paired(before, &model.validation).any(|(_, b, a)| {
                    fit_pairs(b, a)
                        .iter()
                        .any(|(_, x, y)| x.is_some() && y.is_none())
                });
            let gain = if lost {
                f64::NEG_INFINITY
            } else {
                advantage(&model.validation, before).0
            };
            (i, gain)
        })
        .collect()
}

/// An effect is not confirmed when at every speed that chose it the
/// advantage of that speed's findings alone ([`alone_advantages`]) is not
/// above zero: a hypothesis the estimation runs favoured and the held-out
/// runs did not, reported as tried rather than named (on the independent
/// truth's clean ROV, seed 1: cross-flow |q|r in yaw at 0.50 m/s, its
/// fits 1.09 lower over 24).
fn confirmation(
    asm: &Assembly<'_>,
    effects: &[EffectAcrossGrid],
    gains: &[(usize, f64)],
) -> Vec<Option<String>> {
    effects
        .iter()
        .map(|e| {
            let at: Vec<(f64, f64)> = gains
                .iter()
                .filter(|(i, _)| {
                    asm.points[*i]
                        .report
                        .findings
                        .iter()
                        .any(|f| f.effect == e.effect)
                })
                .map(|&(i, g)| (asm.points[i].grid_speed_mps, g))
                .collect();
            let confirmed = at.is_empty() || at.iter().any(|&(_, g)| g > 0.0);
            (!confirmed).then(|| {
                let each: Vec<String> = at
                    .iter()
                    .map(|&(s, g)| {
                        if g.is_finite() {
                            format!("{s:.2} m/s: {}", sig3(g))
                        } else {
                            format!("{s:.2} m/s: a fit lost or M not positive definite")
                        }
                    })
                    .collect();
                format!(
                    "not confirmed: with only its grid speed's findings added to the baseline, the held-out fits (1-step, k-step, 10 s restarted and whole-run free run, each clamped to [−1, 1]) gain nothing on balance ({})",
                    each.join("; ")
                )
            })
        })
        .collect()
}
