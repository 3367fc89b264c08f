//! Only what is better is kept. The model with every grid speed's findings
//! is kept if, on the held-out runs, it is better than the start model
//! beyond noise in some fit and worse in none (1-step, k-step, 10 s
//! restarted and whole-run free run), simulates wherever that model did, and keeps M
//! positive definite — less the findings of speeds that add nothing to
//! their null refit (below) and share no effect with a speed that adds,
//! where the model without them is no worse on the held-out fits summed.
//! Otherwise the grid speeds' augmentations are added
//! one at a time, strongest evidence first, each staying only if the model
//! with it passes the same test against the model without it and against
//! the baseline (so losses within noise cannot add up).
//!
//! Each speed is also refitted with no new term (its null refit: the same
//! rows on the same estimation runs). A speed's findings are credited only
//! with what they add to that refit where it beats the baseline; a speed
//! whose findings add nothing is added one at a time as its null refit,
//! and only beside another speed's findings (a refit alone is no
//! discovery).
//!
//! The unit is a grid speed's augmentation as discovery fitted it: its
//! terms were fitted together with refitted rows of M and D̄, and a subset
//! of them on those rows is a model nobody fitted (one term's row without
//! its companion can diverge). The held-out runs decide which augmentations
//! enter but never fit a coefficient: the terms were fitted on the
//! estimation runs alone.

use std::collections::BTreeSet;

use super::super::discover_gate::{HeldOutVerdict, advantage, compare_against, inertia_verdict};
use super::super::error::IdentifyError;
use super::super::outcome::{Identified, RunValidation};
use super::assemble::Assembly;
use super::credit::{Alone, alone_advantages, confirmation, refit_gains};
use super::{EffectAcrossGrid, speeds_text};
use crate::discrepancy::Verdict;
use crate::discrepancy::report::ModelReport;
use crate::discrepancy::{AugmentedModel, DiscoverySettings, Record, refit_holding};
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
    /// Per grid speed with findings: its findings alone on the baseline
    /// against its null refit ([`alone_advantages`]).
    pub alone: Vec<Alone>,
    /// (grid speed, held-out advantage) where the null refit alone is
    /// better than the baseline ([`refit_gains`]).
    pub refits: Vec<(f64, f64)>,
}

/// What each effect was credited with: [`Kept::unconfirmed`],
/// [`Kept::alone`], [`Kept::refits`].
type Credit = (Vec<Option<String>>, Vec<Alone>, Vec<(f64, f64)>);

impl Kept {
    /// Nothing stored, for `reason`, with what each effect was credited.
    fn nothing(
        verdicts: Vec<HeldOutVerdict>,
        reason: String,
        (unconfirmed, alone, refits): Credit,
    ) -> Self {
        Kept {
            model: None,
            verdicts,
            overall: HeldOutVerdict {
                keep: false,
                reason,
            },
            unconfirmed,
            alone,
            refits,
        }
    }
}

/// Per grid point (in the assembly's order): its start model and
/// estimation records, for its null refit ([`null_model`]).
pub(super) type Starts<'a> = [(AugmentedModel, &'a [Record])];

/// Grid point `i` refitted with no new term (the null refit: the start
/// model's rows of M and D̄ and its carried terms refitted on the same
/// estimation runs, by the same choice of rows, as discovery fitted its
/// findings), and that model validated: what the refit gains on the
/// held-out runs is the refit's, not a term's. `None` when the refit fails
/// (the baseline is then the reference).
fn null_model(
    asm: &Assembly<'_>,
    starts: &Starts<'_>,
    settings: &DiscoverySettings,
    i: usize,
) -> Result<Option<Box<(ModelReport, Identified)>>, IdentifyError> {
    let (start, est) = &starts[i];
    let Ok(refit) = refit_holding(start, est, settings, &[], &[]) else {
        return Ok(None);
    };
    let report = ModelReport::of(&refit);
    let model = asm.model_from(&[(asm.points[i].grid_speed_mps, &report)], false)?;
    Ok(Some(Box::new((report, model))))
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

/// Whether grid point `i`'s findings name `e`.
fn chose(asm: &Assembly<'_>, e: &EffectAcrossGrid, i: usize) -> bool {
    asm.points[i]
        .report
        .findings
        .iter()
        .any(|f| f.effect == e.effect)
}

/// A model built for the confirmation.
enum Built {
    Alone(Box<Identified>),
    Null(Option<Box<(ModelReport, Identified)>>),
}

/// What the gate may put at a grid speed: discovery's model with its
/// findings, or — where those add nothing to it and it is better than the
/// baseline — the null refit.
enum Candidate {
    Findings,
    Refit(Box<ModelReport>),
}

/// Runs the gate over the grid speeds with findings, between progress
/// `from` and `to`.
pub(super) fn keep_better(
    asm: &Assembly<'_>,
    (starts, settings): (&Starts<'_>, &DiscoverySettings),
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
    // The model with every finding; each speed's findings alone on the
    // baseline (when more than one speed has any) and each speed's null
    // refit, for the confirmation and as the gate's candidates while
    // nothing is kept: side by side on the pool.
    let singles = if order.len() > 1 { order.len() } else { 0 };
    let built = crate::par::fan_out(
        1 + singles + order.len(),
        progress,
        (from, from + (to - from) / 2.0),
        "held-out check of the model with every effect found, of each grid speed's findings alone and of its null refit",
        |k, _| match k {
            0 => Ok(Built::Alone(Box::new(asm.model(&all)?))),
            k if k <= singles => Ok(Built::Alone(Box::new(
                asm.model(&std::iter::once(order[k - 1]).collect())?,
            ))),
            k => null_model(asm, starts, settings, order[k - 1 - singles]).map(Built::Null),
        },
    )?;
    let (mut alone, mut nulls) = (Vec::new(), Vec::new());
    for b in built {
        match b {
            Built::Alone(m) => alone.push(*m),
            Built::Null(m) => nulls.push(m),
        }
    }
    let full = alone.remove(0);
    let singles_built = !alone.is_empty();
    let null_models: Vec<Option<&Identified>> =
        nulls.iter().map(|n| n.as_ref().map(|b| &b.1)).collect();
    let models: Vec<&Identified> = if alone.is_empty() {
        vec![&full]
    } else {
        alone.iter().collect()
    };
    let alone_gains = alone_advantages(asm, &order, before, &models, &null_models);
    let refits = refit_gains(asm, &order, before, &null_models);
    let unconfirmed = confirmation(asm, effects, &alone_gains);

    // The candidates: the speeds whose findings add to their null refit
    // (strongest evidence first), then those whose null refit alone is
    // better than the baseline.
    let adds = |i: usize| alone_gains.iter().any(|a| a.point == i && a.adds());
    let better = |i: usize| {
        refits
            .iter()
            .any(|&(s, _)| s == asm.points[i].grid_speed_mps)
    };
    // Beside each, its model alone on the baseline where already built.
    let (mut cands, mut prebuilt): (Vec<(usize, Candidate)>, Vec<Option<Identified>>) =
        (Vec::new(), Vec::new());
    let mut later = Vec::new();
    let mut alone = alone.into_iter();
    for (&i, null) in order.iter().zip(nulls) {
        let single = if singles_built {
            alone.next()
        } else {
            Some(full.clone())
        };
        match null {
            _ if adds(i) => {
                cands.push((i, Candidate::Findings));
                prebuilt.push(single);
            }
            Some(b) if better(i) => {
                let (report, model) = *b;
                later.push((i, Box::new(report), model));
            }
            _ => {}
        }
    }
    for (i, report, model) in later {
        cands.push((i, Candidate::Refit(report)));
        prebuilt.push(Some(model));
    }
    let idle: Vec<f64> = order
        .iter()
        .filter(|&&i| !adds(i))
        .map(|&i| asm.points[i].grid_speed_mps)
        .collect();
    let named_at = |i: usize| {
        cands
            .iter()
            .any(|(j, c)| *j == i && matches!(c, Candidate::Findings))
    };
    let add_nothing = |e: &EffectAcrossGrid| HeldOutVerdict {
        keep: false,
        reason: format!(
            "with the findings at {} m/s, the held-out fits gain nothing over that grid speed refitted without a new term",
            speeds_text(&e.grid_speeds_mps)
        ),
    };
    let build = |set: &BTreeSet<usize>| {
        let at: Vec<(f64, &ModelReport)> = cands
            .iter()
            .filter(|(i, _)| set.contains(i))
            .map(|(i, c)| {
                let speed = asm.points[*i].grid_speed_mps;
                match c {
                    Candidate::Findings => (speed, &asm.points[*i].report.model),
                    Candidate::Refit(r) => (speed, &**r),
                }
            })
            .collect();
        asm.model_from(&at, set.iter().any(|&i| named_at(i)))
    };
    // The model with every grid speed's findings, as discovery fitted
    // them, is stored if it passes as a whole.
    let verdict = inertia_verdict(&full.document)
        .unwrap_or_else(|| compare_against(before, &full.validation, "the baseline"));
    if verdict.keep {
        // Findings that add nothing to their speed's null refit are left
        // out where the model without them is as good on the held-out runs
        // — unless an effect among them is kept at a speed where findings
        // add (an actuator limit or a current is one for the campaign).
        let shares = |i: usize| {
            asm.points[i].report.findings.iter().any(|f| {
                order.iter().any(|&j| {
                    adds(j)
                        && asm.points[j]
                            .report
                            .findings
                            .iter()
                            .any(|g| g.effect == f.effect)
                })
            })
        };
        let dropped: Vec<usize> = order
            .iter()
            .copied()
            .filter(|&i| !adds(i) && !shares(i))
            .collect();
        if dropped.len() == order.len()
            && let Some(gain) = beyond_refits(asm, &full, &cands)?
            && gain <= 0.0
        {
            let reason = format!(
                "with every effect found, {}; but the findings at {} m/s gain nothing over those grid speeds refitted without a new term, alone or together (fits summed against the refits alone: {}), so no effect is named",
                verdict.reason,
                speeds_text(&idle),
                sig3(gain)
            );
            let verdicts = effects.iter().map(add_nothing).collect();
            return Ok(Kept::nothing(
                verdicts,
                reason,
                (unconfirmed, alone_gains, refits),
            ));
        }
        let slim = if dropped.is_empty() || dropped.len() == order.len() {
            None
        } else {
            let at: Vec<(f64, &ModelReport)> = order
                .iter()
                .filter_map(|&i| {
                    let speed = asm.points[i].grid_speed_mps;
                    if !dropped.contains(&i) {
                        return Some((speed, &asm.points[i].report.model));
                    }
                    cands.iter().find_map(|(j, c)| match c {
                        Candidate::Refit(r) if *j == i => Some((speed, &**r)),
                        _ => None,
                    })
                })
                .collect();
            let slim = asm.model_from(&at, true)?;
            let passes = inertia_verdict(&slim.document)
                .unwrap_or_else(|| compare_against(before, &slim.validation, "the baseline"));
            let (gain, _) = advantage(&full.validation, &slim.validation);
            (passes.keep && gain <= 0.0).then_some((slim, passes, gain))
        };
        if let Some((slim, mut overall, gain)) = slim {
            let kept_at: Vec<f64> = order
                .iter()
                .filter(|i| !dropped.contains(i))
                .map(|&i| asm.points[i].grid_speed_mps)
                .collect();
            let dropped_at: Vec<f64> = dropped
                .iter()
                .map(|&i| asm.points[i].grid_speed_mps)
                .collect();
            let refitted: BTreeSet<usize> = dropped.iter().copied().collect();
            overall.reason = with_refits(
                &format!(
                    "with the findings at {} of {} grid speeds ({} m/s), {}; those at {} m/s add nothing over their speed refitted without a new term and are left out (the model with them too is no better on the held-out runs: fits summed {})",
                    kept_at.len(),
                    order.len(),
                    speeds_text(&kept_at),
                    overall.reason,
                    speeds_text(&dropped_at),
                    sig3(gain)
                ),
                asm,
                &cands,
                &refitted,
            );
            let verdicts = effects
                .iter()
                .map(|e| {
                    if order
                        .iter()
                        .any(|i| !dropped.contains(i) && chose(asm, e, *i))
                    {
                        overall.clone()
                    } else {
                        add_nothing(e)
                    }
                })
                .collect();
            return Ok(Kept {
                model: Some(slim),
                verdicts,
                overall,
                unconfirmed,
                alone: alone_gains,
                refits,
            });
        }
        return Ok(Kept {
            model: Some(full),
            verdicts: vec![verdict.clone(); effects.len()],
            overall: verdict,
            unconfirmed,
            alone: alone_gains,
            refits,
        });
    }
    if !cands.iter().any(|(i, _)| named_at(*i)) {
        let reason = format!(
            "with every effect found, {}; the findings at {} m/s gain nothing on the held-out runs over those grid speeds refitted without a new term (their rows of M and D̄ and carried terms refitted on the same runs)",
            verdict.reason,
            speeds_text(&idle)
        );
        let verdicts = effects.iter().map(add_nothing).collect();
        return Ok(Kept::nothing(
            verdicts,
            reason,
            (unconfirmed, alone_gains, refits),
        ));
    }
    let from = from + (to - from) / 2.0;
    let step = (to - from) / (cands.len() + 1) as f64;
    let mut kept = BTreeSet::new();
    let mut best: Option<Identified> = None;
    // Per grid point tried: its verdict against the model without it.
    let mut at: Vec<(usize, HeldOutVerdict)> = Vec::new();
    for n in 0..cands.len() {
        let i = cands[n].0;
        // A refit alone is no discovery: it enters only beside a speed's
        // findings (they come first).
        if !named_at(i) && !kept.iter().any(|&j| named_at(j)) {
            break;
        }
        let speed = asm.points[i].grid_speed_mps;
        progress.update(
            from + step * (n + 1) as f64,
            &format!(
                "held-out check of the findings at {speed:.2} m/s ({} of {})",
                n + 1,
                cands.len()
            ),
        )?;
        let mut trial = kept.clone();
        trial.insert(i);
        let candidate = match prebuilt[n].take() {
            Some(m) if kept.is_empty() => m,
            _ => build(&trial)?,
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
    let findings_kept: Vec<f64> = kept
        .iter()
        .filter(|&&i| named_at(i))
        .map(|&i| asm.points[i].grid_speed_mps)
        .collect();
    let overall = match &best {
        Some(b) => {
            let mut v = compare_against(before, &b.validation, "the baseline");
            v.reason = with_refits(
                &format!(
                    "with the findings at {} of {} grid speeds ({} m/s; the model with all of them was refused: {}), {}",
                    findings_kept.len(),
                    order.len(),
                    speeds_text(&findings_kept),
                    verdict.reason,
                    v.reason
                ),
                asm,
                &cands,
                &kept,
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
            let named = |i: usize| named_at(i) && chose(asm, e, i);
            let pick = at
                .iter()
                .find(|(i, v)| v.keep && stored && named(*i))
                .or_else(|| at.iter().find(|(i, _)| named(*i)));
            match pick {
                Some((i, v)) => HeldOutVerdict {
                    keep: v.keep && stored,
                    reason: format!(
                        "at {:.2} m/s with that speed's other findings, {}",
                        asm.points[*i].grid_speed_mps, v.reason
                    ),
                },
                None => add_nothing(e),
            }
        })
        .collect();
    Ok(Kept {
        model: best.filter(|_| overall.keep),
        verdicts,
        overall,
        unconfirmed,
        alone: alone_gains,
        refits,
    })
}

/// What `full` gains on the held-out fits (summed) over the model with
/// only the null refits among `cands`; `None` when there are none.
fn beyond_refits(
    asm: &Assembly<'_>,
    full: &Identified,
    cands: &[(usize, Candidate)],
) -> Result<Option<f64>, IdentifyError> {
    let at: Vec<(f64, &ModelReport)> = cands
        .iter()
        .filter_map(|(i, c)| match c {
            Candidate::Refit(r) => Some((asm.points[*i].grid_speed_mps, &**r)),
            Candidate::Findings => None,
        })
        .collect();
    if at.is_empty() {
        return Ok(None);
    }
    let refitted = asm.model_from(&at, false)?;
    Ok(Some(advantage(&full.validation, &refitted.validation).0))
}

/// `reason`, and where `kept` holds null refits, at which speeds the model
/// takes its rows refitted without a new term.
fn with_refits(
    reason: &str,
    asm: &Assembly<'_>,
    cands: &[(usize, Candidate)],
    kept: &BTreeSet<usize>,
) -> String {
    let speeds: Vec<f64> = cands
        .iter()
        .filter(|(i, c)| kept.contains(i) && matches!(c, Candidate::Refit(_)))
        .map(|(i, _)| asm.points[*i].grid_speed_mps)
        .collect();
    if speeds.is_empty() {
        reason.to_owned()
    } else {
        format!(
            "{reason}; at {} m/s, whose findings add nothing to it, the model takes the rows refitted without a new term",
            speeds_text(&speeds)
        )
    }
}
