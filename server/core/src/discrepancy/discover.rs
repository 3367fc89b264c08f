//! The entry point: locate, name, model, show, ask, be honest.

use super::candidates::{Effect, library};
use super::data::{Baseline, Record};
use super::drift::current_drift;
use super::error::DiscoveryError;
use super::evidence::{effect_text, separating_evidence};
use super::fit::{Prepared, Spec};
use super::lines::{SpectralLine, spectral_lines};
use super::locate::{
    Predictions, capital, channel_fits, force_residual, locate, predict, residual,
};
use super::lookalike::{Selection, look_alikes};
use super::model::AugmentedModel;
use super::narrate::{hypothesis, plot_series, summary, unexplained};
use super::report::*;
use super::residual::whiteness;
use super::select::{Criteria, Scored, step};
use crate::estimation::Progress;
use crate::numbers::sig3;

mod refit;
mod settings;

pub(crate) use refit::fit_chosen;
pub use refit::{FIT_NOISE, fit_gain, refit_holding};
pub use settings::DiscoverySettings;

fn check(p: &mut dyn Progress, f: f64, stage: &str) -> Result<(), DiscoveryError> {
    p.update(f, stage).map_err(DiscoveryError::from)
}

/// Every narrow line of every row's 1-step residual force.
fn all_lines(model: &AugmentedModel, runs: &[&Record]) -> Vec<(usize, SpectralLine)> {
    let h = runs.first().map_or(0.1, |r| r.h);
    let preds: Vec<_> = runs.iter().map(|r| model.predict_k_step(r, 1)).collect();
    (0..model.dofs.len())
        .flat_map(|i| {
            let forces: Vec<Vec<f64>> = runs
                .iter()
                .zip(&preds)
                .map(|(r, p)| force_residual(model, r, p, i))
                .collect();
            spectral_lines(&forces, 1.0 / h)
                .into_iter()
                .map(move |l| (i, l))
        })
        .collect()
}

/// Runs missing-physics discovery (see the [module documentation](super)).
///
/// # Errors
/// [`DiscoveryError::Invalid`] naming the field for a malformed baseline,
/// settings or run (shape, non-finite sample, sample times that differ,
/// runs too short for the filter transient and the k-step horizon);
/// [`DiscoveryError::Cancelled`] when `progress` asks to stop.
pub fn discover(
    baseline: &Baseline,
    estimation_runs: &[Record],
    validation_runs: &[Record],
    settings: &DiscoverySettings,
    progress: &mut dyn Progress,
) -> Result<DiscoveryReport, DiscoveryError> {
    // Before the model is built from it (shapes, invertible M).
    baseline.validate()?;
    discover_from(
        &AugmentedModel::from_baseline(baseline),
        estimation_runs,
        validation_runs,
        settings,
        progress,
    )
}

/// [`discover`] continuing from a model that already carries discovered
/// terms (an earlier discovery's result): its terms are kept and refitted
/// with any new ones, not tested again, and the before/after comparison
/// starts from it. Nothing new found: the report's model is `start`.
///
/// # Errors
/// As [`discover`].
pub fn discover_from(
    start: &AugmentedModel,
    estimation_runs: &[Record],
    validation_runs: &[Record],
    settings: &DiscoverySettings,
    progress: &mut dyn Progress,
) -> Result<DiscoveryReport, DiscoveryError> {
    let baseline = &start.baseline();
    baseline.validate()?;
    settings.validate()?;
    let n = baseline.n();
    if estimation_runs.is_empty() {
        return Err(DiscoveryError::invalid(
            "estimation_runs",
            "at least one run is needed",
        ));
    }
    let h = estimation_runs
        .iter()
        .chain(validation_runs)
        .map(|r| r.h)
        .find(|h| h.is_finite() && *h > 0.0)
        .unwrap_or(estimation_runs[0].h);
    let skip = transient(settings, h);
    let min_len = skip + settings.k_step + 64;
    // One bad or short run is set aside with its reason; only a set with
    // no usable run fails.
    let mut set_aside = Vec::new();
    let mut usable = |name: &str, runs: &[Record]| -> Vec<Record> {
        let mut kept = Vec::new();
        for (i, r) in runs.iter().enumerate() {
            let f = format!("{name}[{i}]");
            let why = match r.validate(n, min_len, &f) {
                Err(e) => Some(e.to_string()),
                Ok(()) if (r.h - h).abs() > 1e-9 * h => Some(format!(
                    "`{f}.h`: sample time {} s differs from the campaign's {h} s",
                    r.h
                )),
                Ok(()) => None,
            };
            match why {
                Some(why) => set_aside.push(format!("run '{}' set aside ({why})", r.name)),
                None => kept.push(r.clone()),
            }
        }
        kept
    };
    let estimation_runs = usable("estimation_runs", estimation_runs);
    let validation_runs = usable("validation_runs", validation_runs);
    let Some(first) = estimation_runs.first() else {
        return Err(DiscoveryError::invalid(
            "estimation_runs",
            format!("no usable run: {}", set_aside.join("; ")),
        ));
    };
    // Cross-validation needs two folds: a single run is split in halves.
    let est: Vec<Record> = if estimation_runs.len() == 1 {
        let len = first.len();
        if len / 2 < min_len {
            return Err(DiscoveryError::invalid(
                "estimation_runs[0].nu",
                format!(
                    "a single run needs {} samples to be split for cross-validation",
                    2 * min_len
                ),
            ));
        }
        vec![
            first.slice(0, len / 2, format!("{} (first half)", first.name)),
            first.slice(len / 2, len, format!("{} (second half)", first.name)),
        ]
    } else {
        estimation_runs.to_vec()
    };
    let k = settings.k_step;
    check(progress, 0.0, "locating the misfit")?;
    let base_model = start.clone();
    let all_runs: Vec<&Record> = est.iter().chain(&validation_runs).collect();
    let location = locate(&base_model, &all_runs, k, settings.segment_s);

    check(progress, 0.1, "filtering the runs")?;
    let hac_lags = ((settings.hac_window_s / h).ceil() as usize).max(1);
    let prep = prepare(baseline, &est, settings, skip, hac_lags)?;
    let lib = library(
        &baseline.dofs,
        &baseline.m,
        &baseline.d_bar,
        &settings.library,
    );
    let crit = Criteria {
        min_z: settings.min_z,
        max_delta_bic: settings.max_delta_bic,
        min_cv_gain: settings.min_cv_gain,
        min_force_share: settings.min_force_share,
        cv_candidates: settings.cv_candidates,
        max_lag_s: settings.max_lag_s,
        max_delay_samples: (settings.max_delay_s / h).max(1.0),
        k_step: k,
    };
    let runs: Vec<usize> = (0..est.len()).collect();

    // Forward selection, from the terms the model already carries.
    let carried: Vec<Spec> = start
        .terms
        .iter()
        .map(|t| Spec {
            effect: t.effect,
            shape: t.shape,
        })
        .collect();
    let n_carried = carried.len();
    let mut chosen: Vec<Spec> = carried;
    let mut winners: Vec<Scored> = Vec::new();
    let mut steps: Vec<Vec<Scored>> = Vec::new();
    let mut pool = lib.clone();
    for s in 0..settings.max_terms {
        check(
            progress,
            0.15 + 0.6 * s as f64 / settings.max_terms.max(1) as f64,
            "testing hypotheses",
        )?;
        let st = step(&prep, &chosen, &pool, &runs, &crit);
        if s == 0 {
            // Later steps re-test only what showed at least weak evidence.
            pool = st
                .scored
                .iter()
                .filter(|x| x.z >= 0.5 * settings.min_z)
                .map(|x| x.spec.effect)
                .collect();
        }
        let Some(w) = st.winner else {
            steps.push(st.scored);
            break;
        };
        let win = st.scored[w].clone();
        chosen.push(win.spec);
        winners.push(win);
        steps.push(st.scored);
    }

    check(progress, 0.8, "fitting the augmented model")?;
    let fit_model = |chosen: &[Spec], winners: &[Scored]| -> AugmentedModel {
        if winners.is_empty() {
            return base_model.clone();
        }
        let shape_std: Vec<Option<f64>> = start
            .terms
            .iter()
            .map(|t| t.shape_std)
            .chain(winners.iter().map(|w| w.shape_std))
            .collect();
        fit_chosen(&prep, &base_model, &est, chosen, &shape_std, k)
    };
    let mut model = fit_model(&chosen, &winners);

    // A periodic force the chosen terms leave in a DOF — a narrow line of one
    // size in every run's residual — comes from outside the model's physics
    // (a term that caused it, as an actuator lag's closed-loop ringing,
    // halves it at least). The terms named in that DOF were fitted through it and
    // their gain is not evidence of them: they are withdrawn, the model
    // refitted, and the line reported unexplained.
    let mut withdrawn: Vec<String> = Vec::new();
    if !winners.is_empty() {
        let before = all_lines(&base_model, &all_runs);
        let after = all_lines(&model, &all_runs);
        // A term fits through a periodic force only where the force moves
        // the vessel: up to ten times the DOF's corner frequency a_ii/2π.
        let corner: Vec<f64> = match model.m.clone().try_inverse() {
            Some(mi) => (0..n)
                .map(|i| (mi.row(i) * model.d_bar.column(i))[(0, 0)].abs() / std::f64::consts::TAU)
                .collect(),
            None => vec![0.0; n],
        };
        let same = |a: &SpectralLine, b: &SpectralLine| {
            (a.frequency_hz - b.frequency_hz).abs() <= 2.0 * a.resolution_hz.max(b.resolution_hz)
        };
        // Rows whose lines the terms removed or halved: the terms explain
        // something periodic there (an actuator lag's ringing).
        let explained: Vec<usize> = before
            .iter()
            .filter(|(i, b)| {
                !after
                    .iter()
                    .any(|(j, l)| j == i && same(b, l) && l.amplitude >= 0.5 * b.amplitude)
            })
            .map(|(i, _)| *i)
            .collect();
        let lines: Vec<(usize, SpectralLine)> = after
            .into_iter()
            .filter(|(i, l)| !explained.contains(i) && l.frequency_hz <= 10.0 * corner[*i])
            .collect();
        let touches = |e: &Effect| {
            let rows = e.rows(&baseline.dofs, &baseline.d_bar);
            rows.len() < n && rows.iter().any(|r| lines.iter().any(|(i, _)| i == r))
        };
        if winners.iter().any(|w| touches(&w.spec.effect)) {
            for w in winners.iter().filter(|w| touches(&w.spec.effect)) {
                let (i, l) = lines
                    .iter()
                    .find(|(i, _)| {
                        w.spec
                            .effect
                            .rows(&baseline.dofs, &baseline.d_bar)
                            .contains(i)
                    })
                    .expect("a touched row has a line");
                withdrawn.push(format!(
                    "{} was fitted, then withdrawn: the {} residual keeps a periodic force at {} Hz that no term explains, and the term's gain came from fitting through it.",
                    capital(&w.spec.effect.label()),
                    baseline.dofs[*i].name(),
                    sig3(l.frequency_hz)
                ));
            }
            winners.retain(|w| !touches(&w.spec.effect));
            chosen.truncate(n_carried);
            chosen.extend(winners.iter().map(|w| w.spec));
            model = fit_model(&chosen, &winners);
        }
    }

    // Before/after on validation runs (estimation runs if none were given).
    let val: Vec<&Record> = if validation_runs.is_empty() {
        est.iter().collect()
    } else {
        validation_runs.iter().collect()
    };
    let before: Vec<Predictions> = val.iter().map(|r| predict(&base_model, r, k)).collect();
    let after: Vec<Predictions> = val.iter().map(|r| predict(&model, r, k)).collect();
    let validation: Vec<ChannelComparison> = (0..n)
        .map(|i| {
            let rb: Vec<Vec<f64>> = val
                .iter()
                .zip(&before)
                .map(|(r, p)| residual(r, &p.one, i))
                .collect();
            let ra: Vec<Vec<f64>> = val
                .iter()
                .zip(&after)
                .map(|(r, p)| residual(r, &p.one, i))
                .collect();
            ChannelComparison {
                dof: baseline.dofs[i],
                before: channel_fits(&val, &before, i),
                after: channel_fits(&val, &after, i),
                whiteness_before: whiteness(&rb, 30),
                whiteness_after: whiteness(&ra, 30),
            }
        })
        .collect();
    let plots = plot_series(
        val[0],
        &before[0],
        &after[0],
        &baseline.dofs,
        settings.plot_points,
    );

    check(progress, 0.85, "weighing look-alikes")?;
    let base_resid: Vec<Vec<Vec<f64>>> = all_runs
        .iter()
        .map(|r| {
            let p = base_model.predict_k_step(r, 1);
            (0..n).map(|i| residual(r, &p, i)).collect()
        })
        .collect();
    let noise_sigma: Vec<f64> = (0..n)
        .map(|i| {
            let v: Vec<f64> = base_resid
                .iter()
                .flat_map(|r| r[i].iter().copied())
                .filter(|x| x.is_finite())
                .collect();
            (v.iter().map(|x| x * x).sum::<f64>() / v.len().max(1) as f64).sqrt()
        })
        .collect();
    let ambiguities = look_alikes(
        &prep,
        &Selection {
            winners: &winners,
            steps: &steps,
            chosen: &chosen,
            n_carried,
        },
        &runs,
        settings,
        &noise_sigma,
        est[0].eta[(0, 5)],
        h,
    );

    check(progress, 0.92, "looking for unexplained structure")?;
    let unexplained = unexplained(&model, &all_runs, &chosen);

    // Hypotheses: the first step's tests, chosen terms first.
    let mut hypotheses: Vec<HypothesisReport> = Vec::new();
    for (si, w) in winners.iter().enumerate() {
        hypotheses.push(hypothesis(w, si + 1, Verdict::Chosen, &crit));
    }
    if let Some(first) = steps.first() {
        let mut rest: Vec<&Scored> = first
            .iter()
            .filter(|s| !chosen.iter().any(|c| c.effect == s.spec.effect))
            .collect();
        rest.sort_by(|a, b| {
            b.cv_gain
                .unwrap_or(f64::NEG_INFINITY)
                .total_cmp(&a.cv_gain.unwrap_or(f64::NEG_INFINITY))
                .then(a.delta_bic.total_cmp(&b.delta_bic))
        });
        for s in rest.into_iter().take(20) {
            let v = if s.significant(&crit) {
                Verdict::NotConfirmed
            } else {
                Verdict::NotSignificant
            };
            hypotheses.push(hypothesis(s, 1, v, &crit));
        }
    }

    let mut findings: Vec<Finding> = winners
        .iter()
        .enumerate()
        .map(|(i, w)| {
            let term = &model.terms[n_carried + i];
            let mut evidence = vec![format!(
                "ΔBIC {:.0}, significance z = {:.1}; on held-out runs the free-run fit gains {:.3} (summed over channels).",
                w.delta_bic,
                w.z,
                w.cv_gain.unwrap_or(0.0)
            )];
            if let Some(o) = steps[i]
                .iter()
                .filter(|o| o.spec.effect.family() != w.spec.effect.family() && o.cv_gain.is_some())
                .max_by(|a, b| a.cv_gain.unwrap_or(0.0).total_cmp(&b.cv_gain.unwrap_or(0.0)))
            {
                evidence.push(format!(
                    "The nearest alternative, {}, gains {:.3} on held-out runs (ΔBIC {:.0}).",
                    o.spec.effect.label(),
                    o.cv_gain.unwrap_or(0.0),
                    o.delta_bic
                ));
            }
            evidence.extend(separating_evidence(w.spec.effect, &all_runs, &base_resid, &baseline.dofs, h));
            let h_rep = hypothesis(w, i + 1, Verdict::Chosen, &crit);
            Finding {
                effect: w.spec.effect,
                label: w.spec.effect.label(),
                dofs: prep.rows_of(&[w.spec], &[]).iter().map(|&r| baseline.dofs[r]).collect(),
                coefficients: term
                    .coefficients
                    .iter()
                    .zip(w.spec.effect.coefficient_names())
                    .enumerate()
                    .map(|(j, (v, name))| Estimate {
                        name,
                        value: *v,
                        std: term.coefficient_std(j),
                    })
                    .collect(),
                shape: h_rep.shape,
                effect_text: effect_text(term, h),
                evidence,
            }
        })
        .collect();

    // A current is fitted as a constant: test whether it is one.
    let current_drift = current_drift(
        &model,
        &est,
        &chosen,
        settings.svf_time_constant_s,
        skip,
        hac_lags,
        settings.drift_window_s,
    );
    if let Some(d) = &current_drift
        && let Some(f) = findings.iter_mut().find(|f| f.effect == Effect::Current)
    {
        f.evidence.push(d.text.clone());
        if d.varies {
            f.effect_text = format!("{} {}", f.effect_text, d.text);
        }
    }
    let carried: Vec<Effect> = start.terms.iter().map(|t| t.effect).collect();
    let mut summary = summary(
        &location,
        &carried,
        &findings,
        &validation,
        &ambiguities,
        &unexplained,
    );
    summary.extend(withdrawn);
    summary.extend(set_aside);
    check(progress, 1.0, "done")?;
    Ok(DiscoveryReport {
        dofs: baseline.dofs.clone(),
        summary,
        location,
        hypotheses,
        findings,
        current_drift,
        model: ModelReport::of(&model),
        validation,
        plots,
        ambiguities,
        unexplained,
        carried,
    })
}

/// Samples dropped at the start of each run: the filter transient, the
/// longest input delay tried, the k-step horizon.
fn transient(settings: &DiscoverySettings, h: f64) -> usize {
    ((5.0 * settings.svf_time_constant_s / h).ceil() as usize)
        .max((settings.max_delay_s / h).ceil() as usize + 1)
        .max(settings.k_step)
}

/// The runs filtered for the fits ([`Prepared::new`]).
fn prepare<'a>(
    baseline: &'a Baseline,
    est: &'a [Record],
    settings: &DiscoverySettings,
    skip: usize,
    hac_lags: usize,
) -> Result<Prepared<'a>, DiscoveryError> {
    Prepared::new(baseline, est, settings.svf_time_constant_s, skip, hac_lags).ok_or_else(|| {
        DiscoveryError::invalid(
            "estimation_runs",
            "no samples left after the filter transient",
        )
    })
}
