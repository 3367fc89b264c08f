//! Only a better model is kept: an augmented model found by discovery is
//! stored as a new version only when, on the held-out runs, it improves the
//! baseline's fit beyond noise in some channel and worsens none — 1-step,
//! k-step, the 10 s restarted free run and the free run over the whole run
//! — and simulates wherever the baseline did.

use nalgebra::DMatrix;

use crate::identification::document::ModelDocument;
use crate::identification::outcome::RunValidation;
use crate::numbers::sig3;
use crate::validation::ChannelValidation;

pub use crate::discrepancy::discover::FIT_NOISE;
use crate::discrepancy::discover::fit_gain;
use crate::discrepancy::model::inertia_floor;

/// Whether the augmented model is kept, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct HeldOutVerdict {
    /// Store it.
    pub keep: bool,
    /// The reason, with the deciding numbers (a clause: "on the held-out
    /// runs it improves …").
    pub reason: String,
}

impl HeldOutVerdict {
    /// The verdict on a whole model, in a sentence.
    pub fn text(&self) -> String {
        format!(
            "The augmented model was {}: {}.",
            if self.keep { "stored" } else { "not stored" },
            self.reason
        )
    }
}

/// One compared number: run, channel, metric, baseline, augmented.
struct Change {
    run: String,
    channel: String,
    metric: &'static str,
    before: Option<f64>,
    after: Option<f64>,
}

impl Change {
    /// See [`fit_gain`].
    fn gain(&self) -> f64 {
        fit_gain(self.before, self.after)
    }

    /// Whether the fit fell beyond noise: by more than [`FIT_NOISE`] of the
    /// normalized error 1 − fit (at least [`FIT_NOISE`]), on the raw fits,
    /// so a channel already below zero cannot get worse unseen (the gain's
    /// floor at 0 would hide sway falling from −5.0 to −16.6); a fit lost
    /// where there was one is worse.
    fn is_worse(&self) -> bool {
        match (self.before, self.after) {
            (Some(b), Some(a)) => b - a > FIT_NOISE * (1.0 - b).max(1.0),
            (Some(_), None) => true,
            (None, _) => false,
        }
    }

    fn text(&self) -> String {
        let f = |v: Option<f64>| v.map_or("no fit".to_string(), |x| format!("{x:.3}"));
        format!(
            "{} on '{}' ({} fit {} → {})",
            self.channel,
            self.run,
            self.metric,
            f(self.before),
            f(self.after)
        )
    }
}

fn changes(run: &str, b: &ChannelValidation, a: &ChannelValidation) -> Vec<Change> {
    fit_pairs(b, a)
        .into_iter()
        .map(|(metric, before, after)| Change {
            run: run.to_string(),
            channel: b.output.clone(),
            metric,
            before,
            after,
        })
        .collect()
}

/// A channel's four held-out fits, before (`b`) and after (`a`): 1-step,
/// k-step, 10 s restarted and whole-run free run.
pub(crate) fn fit_pairs(
    b: &ChannelValidation,
    a: &ChannelValidation,
) -> [(&'static str, Option<f64>, Option<f64>); 4] {
    [
        ("1-step", b.fit_one_step, a.fit_one_step),
        ("k-step", b.fit_k_step, a.fit_k_step),
        ("10 s restarted free-run", b.fit_restarted, a.fit_restarted),
        ("whole-run free-run", b.fit_simulation, a.fit_simulation),
    ]
}

/// Σ (a − b) over the held-out fits both give (run, channel, each of the
/// four fits), each fit clamped to [−1, 1] so that one divergent channel
/// counts as a total loss and no more; and how many were compared.
pub(crate) fn advantage(a: &[RunValidation], b: &[RunValidation]) -> (f64, usize) {
    let mut sum = 0.0;
    let mut n = 0;
    for (_, cb, ca) in paired(b, a) {
        for (_, y, x) in fit_pairs(cb, ca) {
            if let (Some(x), Some(y)) = (x.filter(|v| v.is_finite()), y.filter(|v| v.is_finite())) {
                sum += x.clamp(-1.0, 1.0) - y.clamp(-1.0, 1.0);
                n += 1;
            }
        }
    }
    (sum, n)
}

/// How many held-out fits of `augmented` on the channels `outputs` are
/// better than `baseline`'s by more than [`FIT_NOISE`] and how many worse
/// beyond noise (the rules of [`compare_against`]): (better, worse).
pub(crate) fn fit_tally(
    baseline: &[RunValidation],
    augmented: &[RunValidation],
    outputs: &[&str],
) -> (usize, usize) {
    let (mut better, mut worse) = (0, 0);
    for (a, cb, ca) in paired(baseline, augmented) {
        if !outputs.contains(&ca.output.as_str()) {
            continue;
        }
        for c in changes(&a.run_name, cb, ca) {
            if c.gain() < -FIT_NOISE || c.is_worse() {
                worse += 1;
            } else if c.gain() > FIT_NOISE {
                better += 1;
            }
        }
    }
    (better, worse)
}

/// Each channel of `augmented`'s runs with the same run's channel of the
/// same output in `baseline`: (run, before, after).
pub(crate) fn paired<'a>(
    baseline: &'a [RunValidation],
    augmented: &'a [RunValidation],
) -> impl Iterator<
    Item = (
        &'a RunValidation,
        &'a ChannelValidation,
        &'a ChannelValidation,
    ),
> {
    augmented
        .iter()
        .filter_map(move |a| Some((a, baseline.iter().find(|b| b.run_id == a.run_id)?)))
        .flat_map(|(a, b)| {
            a.report.channels.iter().filter_map(move |ca| {
                let cb = b.report.channels.iter().find(|c| c.output == ca.output)?;
                Some((a, cb, ca))
            })
        })
}

/// Refuses an augmented model whose inertia is not physical: at some grid
/// speed the symmetric part of M, ½(M + Mᵀ), has an eigenvalue ≤ 0, so the
/// kinetic energy ½νᵀMν is not positive. (Refitting rows leaves M
/// slightly asymmetric; its symmetric part must still be positive.)
pub fn inertia_verdict(doc: &ModelDocument) -> Option<HeldOutVerdict> {
    let lpv = doc.lpv.as_ref()?;
    let mut bad = Vec::new();
    for p in &lpv.points {
        let n = p.m.len();
        if p.m.iter().any(|r| r.len() != n) {
            continue;
        }
        let low = inertia_floor(&DMatrix::from_fn(n, n, |i, j| p.m[i][j]));
        if low.is_nan() || low <= 0.0 {
            bad.push(format!(
                "at {} m/s (smallest eigenvalue of ½(M + Mᵀ): {})",
                sig3(p.speed_mps),
                sig3(low)
            ));
        }
    }
    (!bad.is_empty()).then(|| HeldOutVerdict {
        keep: false,
        reason: format!("its inertia M is not positive definite {}", bad.join(", ")),
    })
}

/// Compares the augmented model's held-out validation with the baseline's
/// on the same runs (matched by run id and channel name).
pub fn compare_held_out(baseline: &[RunValidation], augmented: &[RunValidation]) -> HeldOutVerdict {
    compare_against(baseline, augmented, "the baseline")
}

/// [`compare_held_out`] against a reference model named `against` in the
/// reason ("the baseline", "the model without it").
pub fn compare_against(
    baseline: &[RunValidation],
    augmented: &[RunValidation],
    against: &str,
) -> HeldOutVerdict {
    let mut all = Vec::new();
    let mut diverged = Vec::new();
    for (a, cb, ca) in paired(baseline, augmented) {
        if let (None, Some(d)) = (&cb.diverged.simulation, &ca.diverged.simulation) {
            diverged.push(format!(
                "its free run on '{}' diverged at t = {:.1} s in {}",
                a.run_name, d.t_s, ca.output
            ));
        }
        all.extend(changes(&a.run_name, cb, ca));
    }
    if all.is_empty() {
        return HeldOutVerdict {
            keep: false,
            reason: format!("there is no held-out run to show that it is better than {against}"),
        };
    }
    if !diverged.is_empty() {
        return HeldOutVerdict {
            keep: false,
            reason: format!("{} ({against} did not diverge)", diverged.join("; ")),
        };
    }
    let mut worse: Vec<&Change> = all
        .iter()
        .filter(|c| c.gain() < -FIT_NOISE || c.is_worse())
        .collect();
    worse.sort_by(|x, y| x.gain().total_cmp(&y.gain()));
    let mut better: Vec<&Change> = all.iter().filter(|c| c.gain() > FIT_NOISE).collect();
    better.sort_by(|x, y| y.gain().total_cmp(&x.gain()));
    if !worse.is_empty() {
        let shown: Vec<String> = worse.iter().take(3).map(|c| c.text()).collect();
        // What it gained beside: a model better in most fits and worse in
        // one is a different finding from one worse throughout.
        let beside = match better.first() {
            Some(best) => format!(
                " (it improves {} of {} fits by more than {FIT_NOISE}; largest gain: {})",
                better.len(),
                all.len(),
                best.text()
            ),
            None => String::new(),
        };
        return HeldOutVerdict {
            keep: false,
            reason: format!(
                "on the held-out runs it is worse than {against} in {}{}{beside}",
                shown.join(", "),
                if worse.len() > 3 {
                    format!(" and {} more", worse.len() - 3)
                } else {
                    String::new()
                }
            ),
        };
    }
    match better.first() {
        None => HeldOutVerdict {
            keep: false,
            reason: format!(
                "on the held-out runs no fit differs by more than {FIT_NOISE} from {against}'s"
            ),
        },
        Some(best) => HeldOutVerdict {
            keep: true,
            reason: format!(
                "on the held-out runs it improves {} of {} fits over {against} by more than {FIT_NOISE} and worsens none (largest gain: {})",
                better.len(),
                all.len(),
                best.text()
            ),
        },
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::estimation::NoProgress;
    use crate::identification::lambda_campaign::{
        LambdaCampaignSettings, identify_lambda_campaign,
    };
    use crate::identification::tests::{force_columns, simulate, to_run};
    use crate::planning::campaign::ExperimentFamily;
    use crate::planning::examples::surveyor_rov;
    use crate::simulation::rov::RovTruth;
    use crate::validation::{Divergence, DivergenceReason};

    /// A real held-out validation: a λ model of a simulated ROV at one
    /// speed, validated on its own held-out run.
    pub(crate) fn held_out() -> Vec<RunValidation> {
        let truth = RovTruth::surveyor_like();
        let runs: Vec<_> = (0..3u64)
            .map(|r| {
                let rec = simulate(&truth, vec![0.5; 2000], 500 + r);
                let family = if r < 2 {
                    ExperimentFamily::Recursive
                } else {
                    ExperimentFamily::Validation
                };
                to_run(&format!("run-{r}"), family, Some(0.5), &rec)
            })
            .collect();
        let profile = surveyor_rov();
        let settings = LambdaCampaignSettings {
            estimate_restoring: false,
            ..LambdaCampaignSettings::default()
        };
        identify_lambda_campaign(
            &profile,
            &[0.5],
            &force_columns(&profile),
            &runs,
            &settings,
            &mut NoProgress,
        )
        .unwrap()
        .validation
    }

    fn shift(v: &mut [RunValidation], channel: &str, by: f64) {
        for r in v.iter_mut() {
            for c in r.report.channels.iter_mut().filter(|c| c.output == channel) {
                c.fit_one_step = c.fit_one_step.map(|f| f + by);
            }
        }
    }

    #[test]
    fn only_a_model_better_somewhere_and_worse_nowhere_is_kept() {
        let base = held_out();
        assert!(!base.is_empty());
        let same = compare_held_out(&base, &base);
        assert!(
            !same.keep && same.text().contains("no fit differs"),
            "{}",
            same.text()
        );

        let mut better = base.clone();
        shift(&mut better, "v", 0.05);
        let v = compare_held_out(&base, &better);
        assert!(
            v.keep && v.text().contains("v on 'run-2' (1-step fit"),
            "{}",
            v.text()
        );

        let mut mixed = better.clone();
        shift(&mut mixed, "r", -0.02);
        let v = compare_held_out(&base, &mixed);
        assert!(!v.keep, "{}", v.text());
        assert!(
            v.text()
                .contains("worse than the baseline in r on 'run-2' (1-step fit"),
            "{}",
            v.text()
        );
        // What it gained beside is said too; a model worse throughout has
        // no such clause.
        let n = 4 * base.iter().map(|r| r.report.channels.len()).sum::<usize>();
        assert!(
            v.text().contains(&format!(
                "(it improves 1 of {n} fits by more than {FIT_NOISE}; largest gain: v on 'run-2' (1-step fit"
            )),
            "{}",
            v.text()
        );
        let mut worse = base.clone();
        shift(&mut worse, "r", -0.02);
        let w = compare_held_out(&base, &worse);
        assert!(!w.keep && !w.text().contains("it improves"), "{}", w.text());

        let mut within_noise = better.clone();
        shift(&mut within_noise, "r", -0.5 * FIT_NOISE);
        assert!(compare_held_out(&base, &within_noise).keep);
    }

    #[test]
    fn a_channel_below_zero_that_falls_further_is_worse() {
        let base = held_out();
        let set = |v: &mut [RunValidation], sway: f64, surge_gain: f64| {
            for r in v.iter_mut() {
                for c in r.report.channels.iter_mut() {
                    match c.output.as_str() {
                        "v" => c.fit_simulation = Some(sway),
                        "u" => c.fit_simulation = c.fit_simulation.map(|f| f + surge_gain),
                        _ => {}
                    }
                }
            }
        };
        let mut before = base.clone();
        set(&mut before, -4.97, 0.0);
        let mut after = base.clone();
        set(&mut after, -16.6, 0.05);
        let v = compare_held_out(&before, &after);
        assert!(!v.keep, "{}", v.text());
        assert!(
            v.text()
                .contains("v on 'run-2' (whole-run free-run fit -4.970 → -16.600)"),
            "{}",
            v.text()
        );
        // Within the noise of its normalized error (1 − fit = 5.97): kept.
        let mut close = base.clone();
        set(&mut close, -4.99, 0.05);
        assert!(compare_held_out(&before, &close).keep);
    }

    #[test]
    fn a_model_whose_free_run_diverges_is_not_kept() {
        let base = held_out();
        let mut worse = base.clone();
        shift(&mut worse, "u", 0.1);
        let c = &mut worse[0].report.channels[0];
        c.diverged.simulation = Some(Divergence {
            t_s: 42.0,
            after_s: 42.0,
            output: c.output.clone(),
            dof: None,
            reason: DivergenceReason::NonFinite,
            plausible: [-1.0, 1.0],
            text: "diverged".into(),
        });
        let v = compare_held_out(&base, &worse);
        assert!(!v.keep);
        assert!(v.text().contains("diverged at t = 42.0 s"), "{}", v.text());
        assert!(
            compare_held_out(&[], &base)
                .text()
                .contains("no held-out run")
        );
    }

    #[test]
    fn a_model_whose_inertia_is_not_positive_is_not_kept() {
        use crate::identification::tests::lpv_doc;
        use crate::planning::dof::Dof;
        let m = vec![vec![100.0, 10.0], vec![10.0, 50.0]];
        let d = vec![vec![20.0, 0.0], vec![0.0, 10.0]];
        let ok = lpv_doc(
            vec![Dof::Surge, Dof::Sway],
            vec![(0.5, m.clone(), d.clone()), (1.0, m.clone(), d.clone())],
        );
        assert!(inertia_verdict(&ok).is_none());
        // Positive diagonal, but the coupling makes νᵀMν < 0 along (1, −1).
        let bad_m = vec![vec![100.0, 90.0], vec![90.0, 50.0]];
        let bad = lpv_doc(
            vec![Dof::Surge, Dof::Sway],
            vec![(0.5, m, d.clone()), (1.0, bad_m, d)],
        );
        let v = inertia_verdict(&bad).expect("refused");
        assert!(!v.keep);
        assert!(
            v.text().contains(
                "not positive definite at 1 m/s (smallest eigenvalue of ½(M + Mᵀ): −18.4)"
            ),
            "{}",
            v.text()
        );
    }
}
