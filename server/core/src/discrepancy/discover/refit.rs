//! Fitting chosen terms into a model, and judging a fit's change against noise.

use super::{prepare, transient};
use crate::discrepancy::data::Record;
use crate::discrepancy::error::DiscoveryError;
use crate::discrepancy::fit::{Prepared, Spec};
use crate::discrepancy::locate::{Predictions, channel_fits, predict};
use crate::discrepancy::model::{AugmentedModel, ModelTerm};

use super::DiscoverySettings;

/// The model of the terms `chosen` fitted on every run of `prep`: three
/// fits — the touched rows' couplings held, free, or every row refitted (a
/// baseline that absorbed the effect through its couplings in other rows
/// gives it back) — of which the one that harms the estimation runs' fits
/// least, then gains most, is kept; a fit whose M is not positive definite
/// is not a vessel and is taken only when no fit is. `base_model` when
/// nothing can be fitted.
pub(crate) fn fit_chosen(
    prep: &Prepared<'_>,
    base_model: &AugmentedModel,
    est: &[Record],
    chosen: &[Spec],
    shape_std: &[Option<f64>],
    k: usize,
) -> AugmentedModel {
    let n = prep.baseline.n();
    let runs: Vec<usize> = (0..est.len()).collect();
    let all_rows: Vec<usize> = (0..n).collect();
    let fit_variant = |v: usize, hac: bool| match v {
        0 => prep.fit_for_model(chosen, &runs, hac),
        1 => prep.fit(chosen, &[], &runs, hac),
        _ => prep.fit(chosen, &all_rows, &runs, hac),
    };
    let fitted: Vec<&Record> = est.iter().collect();
    let base_on_fitted: Vec<Predictions> =
        fitted.iter().map(|r| predict(base_model, r, k)).collect();
    let mut best: Option<(usize, (bool, f64, f64))> = None;
    // A variant that frees nothing more than an earlier one (the chosen
    // terms touch every row) is the same fit: judged once.
    let mut judged: Vec<FitKey> = Vec::new();
    for v in 0..3 {
        let Some(f) = fit_variant(v, false) else {
            continue;
        };
        let key = (
            f.rows.clone(),
            f.base.clone(),
            f.theta.clone(),
            f.loads.clone(),
        );
        if judged.contains(&key) {
            continue;
        }
        judged.push(key);
        let candidate = prep.model(chosen, &f, &[]);
        let (harm, gain) = change_score(&base_on_fitted, &candidate, &fitted, k);
        let score = (candidate.inertia_positive(), harm, gain);
        if best.is_none_or(|(_, b)| score > b) {
            best = Some((v, score));
        }
    }
    best.and_then(|(v, _)| fit_variant(v, true))
        .map_or_else(|| base_model.clone(), |f| prep.model(chosen, &f, shape_std))
}

/// What makes a fit's model: its rows, their M and D̄ entries, the terms'
/// coefficients and the constant loads.
type FitKey = (
    Vec<usize>,
    Vec<(Vec<f64>, Vec<f64>)>,
    Vec<Vec<f64>>,
    Vec<Option<f64>>,
);

/// The terms of `start` and `terms` refitted on `estimation_runs` with the
/// coefficients of `held` fixed: a force the campaign shares (a current, a
/// pull fixed in NED), estimated once for it, enters each grid speed's
/// model at that value, and M, D̄ and the speed's other terms are fitted
/// around it as [`discover_from`] fits its chosen terms. A run too short or
/// malformed is left out (as `discover_from` sets it aside).
///
/// # Errors
/// [`DiscoveryError::Invalid`] for a malformed start model or settings, or
/// when no run is usable.
pub fn refit_holding(
    start: &AugmentedModel,
    estimation_runs: &[Record],
    settings: &DiscoverySettings,
    terms: &[ModelTerm],
    held: &[ModelTerm],
) -> Result<AugmentedModel, DiscoveryError> {
    let baseline = &start.baseline();
    baseline.validate()?;
    settings.validate()?;
    let n = baseline.n();
    let h = estimation_runs
        .iter()
        .map(|r| r.h)
        .find(|h| h.is_finite() && *h > 0.0)
        .ok_or_else(|| DiscoveryError::invalid("estimation_runs", "at least one run is needed"))?;
    let skip = transient(settings, h);
    let min_len = skip + settings.k_step + 64;
    let est: Vec<Record> = estimation_runs
        .iter()
        .enumerate()
        .filter(|(i, r)| {
            r.validate(n, min_len, &format!("estimation_runs[{i}]"))
                .is_ok()
                && (r.h - h).abs() <= 1e-9 * h
        })
        .map(|(_, r)| r.clone())
        .collect();
    if est.is_empty() {
        return Err(DiscoveryError::invalid(
            "estimation_runs",
            "no run long enough to refit on",
        ));
    }
    let hac_lags = ((settings.hac_window_s / h).ceil() as usize).max(1);
    let prep = prepare(baseline, &est, settings, skip, hac_lags)?.holding(held.to_vec());
    // The start's terms, then the others; a held effect once.
    let mut all: Vec<&ModelTerm> = Vec::new();
    for t in start.terms.iter().chain(terms).chain(held) {
        if !all.iter().any(|a| a.effect == t.effect) {
            all.push(t);
        }
    }
    let chosen: Vec<Spec> = all
        .iter()
        .map(|t| Spec {
            effect: t.effect,
            shape: t.shape,
        })
        .collect();
    let shape_std: Vec<Option<f64>> = all.iter().map(|t| t.shape_std).collect();
    Ok(fit_chosen(
        &prep,
        start,
        &est,
        &chosen,
        &shape_std,
        settings.k_step,
    ))
}

/// A change of an NRMSE fit (1 − NRMSE) below this is noise.
pub const FIT_NOISE: f64 = 0.005;

/// The change of one fit from `before` to `after`: positive when better;
/// −∞ when a fit the baseline had is lost. Fits below 0 (worse than the
/// record's mean) count as 0: two predictions that both miss are not ranked
/// by how badly.
pub fn fit_gain(before: Option<f64>, after: Option<f64>) -> f64 {
    match (before, after) {
        (Some(b), Some(a)) => a.max(0.0) - b.max(0.0),
        (Some(_), None) => f64::NEG_INFINITY,
        (None, _) => 0.0,
    }
}

/// How a model changes the channels' fits (1-step, k-step, free run; fits
/// below 0 count as 0) from the base model's predictions `before` on `runs`:
/// (the worst loss beyond
/// noise, 0 if none; the summed change). The kept model is the one of its
/// two fits (couplings free or held, see `Prepared::fit_for_model`) that
/// harms the untouched channels least, then gains most — judged on the
/// estimation runs, so the held-out runs stay an independent test.
fn change_score(
    before: &[Predictions],
    model: &AugmentedModel,
    runs: &[&Record],
    k: usize,
) -> (f64, f64) {
    let after: Vec<Predictions> = runs.iter().map(|r| predict(model, r, k)).collect();
    let (mut worst, mut total) = (0.0_f64, 0.0);
    for i in 0..model.dofs.len() {
        let (b, a) = (channel_fits(runs, before, i), channel_fits(runs, &after, i));
        for (x, y) in [
            (b.one_step, a.one_step),
            (b.k_step, a.k_step),
            (b.free_run, a.free_run),
        ] {
            // A lost fit counts as the largest possible loss of a fit ≤ 1.
            let d = fit_gain(x, y).max(-1.0);
            if d < -FIT_NOISE {
                worst = worst.min(d);
            }
            total += d;
        }
    }
    (worst, total)
}
