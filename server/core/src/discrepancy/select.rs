//! Hypothesis tests and forward selection.
//!
//! Each candidate is fitted as an augmentation of the current model
//! (equation error, baseline rows refitted) and scored three ways:
//! - the significance of its coefficients (Wald z from the HAC covariance;
//!   for a shape parameter, z = √LR of the profile),
//! - ΔBIC with the effective sample count N/κ of correlated residuals,
//! - the cross-validated free-run NRMSE fit (thesis eq. 1.13) on runs left
//!   out of the fit, against the same model without the candidate.
//!
//! Selection is greedy: the best cross-validated candidate among the
//! significant ones joins, until none improves the held-out fit. The
//! equation-error statistics only screen; held-out simulation decides, so
//! a term that fits noise in the equation but not the vessel never joins.

use std::collections::HashMap;
use std::rc::Rc;

use super::candidates::{Effect, Family, ShapeKind};
use super::data::Record;
use super::fit::{FitOut, Prepared, Spec, profile};
use crate::numbers::FIT_FLOOR;
use crate::validation::{PlausibleBand, nrmse_fit};

/// Thresholds of the selection.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Criteria {
    pub min_z: f64,
    pub max_delta_bic: f64,
    pub min_cv_gain: f64,
    pub min_force_share: f64,
    pub cv_candidates: usize,
    pub max_lag_s: f64,
    /// The longest delay searched, in log samples (at least one).
    pub max_delay_samples: f64,
    pub k_step: usize,
}

/// Ten values from `lo` to `hi`, evenly spaced in log.
fn log_grid(lo: f64, hi: f64) -> Vec<f64> {
    let k = 10;
    (0..k)
        .map(|i| lo * (hi / lo).powf(i as f64 / (k - 1) as f64))
        .collect()
}

/// A candidate fitted on top of the chosen terms.
#[derive(Debug, Clone)]
pub(crate) struct Scored {
    pub spec: Spec,
    pub fit: FitOut,
    pub shape_std: Option<f64>,
    pub delta_bic: f64,
    pub z: f64,
    pub cv_gain: Option<f64>,
    /// RMS of the force it explains over RMS of the command in its DOF
    /// (the largest over its rows; [`Prepared::force_share`]; `None` when
    /// not measured).
    pub force_share: Option<f64>,
}

impl Scored {
    /// Index of this candidate's spec in its fit (the last one).
    pub fn own(&self) -> usize {
        self.fit.theta.len() - 1
    }

    /// Passes the equation-error screen and is large enough to matter.
    pub fn significant(&self, c: &Criteria) -> bool {
        self.z >= c.min_z && self.delta_bic <= c.max_delta_bic && self.large_enough(c)
    }

    /// The force it explains is at least `min_force_share` of the command.
    pub fn large_enough(&self, c: &Criteria) -> bool {
        self.force_share.is_none_or(|s| s >= c.min_force_share)
    }
}

/// Shape grid of an actuator effect over the data of its DOF.
fn shape_grid(prep: &Prepared<'_>, effect: Effect, runs: &[usize], c: &Criteria) -> Vec<f64> {
    let h = prep.records[0].h;
    let row = effect
        .dof()
        .and_then(|d| prep.baseline.index_of(d))
        .unwrap_or(0);
    let quantiles = |qs: &[f64]| -> Vec<f64> {
        let v = prep.abs_tau_sorted(row, runs);
        let mut g: Vec<f64> = qs
            .iter()
            .filter_map(|q| v.get(((v.len() as f64 - 1.0) * q) as usize).copied())
            .filter(|x| *x > 0.0)
            .collect();
        g.dedup_by(|a, b| (*a - *b).abs() <= 1e-9 * b.abs());
        g
    };
    match effect.shape() {
        // Both from a fifth of a log sample (a 0.04 s lag or delay at
        // 10 Hz is 0.4 of one) to the longest, refined between neighbours:
        // a delay need not be whole samples.
        Some(ShapeKind::LagTime) => log_grid(0.2 * h, c.max_lag_s.max(h)),
        Some(ShapeKind::DelaySamples) => log_grid(0.2, c.max_delay_samples),
        Some(ShapeKind::SaturationLevel) => {
            // Quantiles of the command, and a log grid down to 2 % of its
            // largest value: under closed-loop control a hull that gets far
            // less thrust than commanded winds the controller up to its own
            // limit, so most commands sit far above the true τ_max.
            let mut g = quantiles(&[0.3, 0.4, 0.5, 0.6, 0.7, 0.75, 0.8, 0.85, 0.9, 0.95, 0.98]);
            if let Some(&top) = prep.abs_tau_sorted(row, runs).last().filter(|t| **t > 0.0) {
                let k = 12;
                g.extend((0..k).map(|i| top * 0.02f64.powf(1.0 - i as f64 / k as f64)));
            }
            g.sort_by(f64::total_cmp);
            g.dedup_by(|a, b| (*a - *b).abs() <= 0.02 * b.abs());
            g
        }
        Some(ShapeKind::DeadZoneWidth) => quantiles(&[0.02, 0.05, 0.1, 0.15, 0.2, 0.3]),
        None => vec![],
    }
}

/// The fits of the chosen terms alone on a set of rows (and their k-step
/// output errors), shared by the candidates of one step that act on the
/// same rows: each candidate is judged against them.
#[derive(Default)]
pub(crate) struct Nulls {
    fits: HashMap<Vec<usize>, Option<Rc<FitOut>>>,
    ksteps: HashMap<(Vec<usize>, usize), Option<Rc<KStep>>>,
}

/// A k-step output error: its sum of squares and the residual runs.
type KStep = (f64, Vec<Vec<f64>>);

impl Nulls {
    fn fit(
        &mut self,
        prep: &Prepared<'_>,
        chosen: &[Spec],
        rows: &[usize],
        runs: &[usize],
    ) -> Option<Rc<FitOut>> {
        self.fits
            .entry(rows.to_vec())
            .or_insert_with(|| prep.fit(chosen, rows, runs, false).map(Rc::new))
            .clone()
    }

    fn kstep(
        &mut self,
        prep: &Prepared<'_>,
        chosen: &[Spec],
        null: &FitOut,
        rows: &[usize],
        runs: &[usize],
        k: usize,
    ) -> Option<Rc<KStep>> {
        self.ksteps
            .entry((rows.to_vec(), k))
            .or_insert_with(|| prep.kstep_rows(chosen, null, rows, runs, k).map(Rc::new))
            .clone()
    }
}

/// Fits `effect` on top of `chosen` over `runs`, with its statistics
/// against `chosen` alone refitted on the same rows.
#[cfg(test)]
pub(crate) fn score(
    prep: &Prepared<'_>,
    chosen: &[Spec],
    effect: Effect,
    runs: &[usize],
    c: &Criteria,
) -> Option<Scored> {
    score_against(prep, chosen, effect, runs, c, &mut Nulls::default())
}

/// [`score`] with the fits of `chosen` alone taken from (or kept in)
/// `nulls`: the same `chosen` and `runs` for every call on one `nulls`.
pub(crate) fn score_against(
    prep: &Prepared<'_>,
    chosen: &[Spec],
    effect: Effect,
    runs: &[usize],
    c: &Criteria,
    nulls: &mut Nulls,
) -> Option<Scored> {
    let rows = effect.rows(&prep.baseline.dofs, &prep.baseline.d_bar);
    if rows.is_empty() {
        return None;
    }
    let null = nulls.fit(prep, chosen, &rows, runs)?;
    if effect.shape().is_some() {
        let grid = shape_grid(prep, effect, runs, c);
        if grid.is_empty() {
            return None;
        }
        let k = c.k_step.min(4);
        let p = profile(prep, chosen, effect, &rows, runs, &grid, k)?;
        // Output-error statistics against the chosen terms alone.
        let null_kstep = nulls.kstep(prep, chosen, &null, &rows, runs, k)?;
        let (s0, r0) = (null_kstep.0, &null_kstep.1);
        let kappa = super::fit::long_run_inflation(r0, prep.hac_lags.max(2 * k));
        let n_eff = (p.n as f64 / kappa).max(2.0);
        let lr = n_eff * (s0 / p.sse.max(f64::MIN_POSITIVE)).ln();
        // An optimum on the edge of the search range is a bound, not an
        // estimate (a saturation level at the smallest level tried, a delay
        // at the longest): such a hypothesis is not significant.
        let lr = if p.at_edge { 0.0 } else { lr };
        let spec = Spec {
            effect,
            shape: Some(p.value),
        };
        let force_share = prep.force_share(&null, &p.fit, &rows, runs);
        return Some(Scored {
            spec,
            fit: p.fit,
            shape_std: p.std,
            delta_bic: -lr + n_eff.ln(),
            z: lr.max(0.0).sqrt(),
            cv_gain: None,
            force_share,
        });
    }
    let spec = Spec {
        effect,
        shape: None,
    };
    let mut specs = chosen.to_vec();
    specs.push(spec);
    let fit = prep.fit(&specs, &rows, runs, true)?;
    let n_eff = (fit.n as f64 / prep.kappa).max(2.0);
    let k = effect.n_linear().max(1) as f64;
    let lr = n_eff * (null.sse / fit.sse.max(f64::MIN_POSITIVE)).ln();
    let delta_bic = -lr + k * n_eff.ln();
    let z = if effect.n_linear() > 0 {
        let s = fit.theta.len() - 1;
        let th = nalgebra::DVector::from_vec(fit.theta[s].clone());
        match fit.theta_cov(s).and_then(|cv| cv.try_inverse()) {
            Some(inv) => (th.transpose() * inv * &th)[(0, 0)].max(0.0).sqrt(),
            None => 0.0,
        }
    } else {
        lr.max(0.0).sqrt()
    };
    // Damping must dissipate: θ|ν_j|ν_i, θν_i³ put power θ|ν_j|ν_i², θν_i⁴
    // into the water only for θ ≥ 0. A negative one is the fit bending
    // another misfit, not a damping term.
    let dissipative = !matches!(
        effect.family(),
        Family::QuadraticDamping | Family::CubicDamping | Family::CrossDamping
    ) || fit
        .theta
        .last()
        .is_some_and(|t| t.iter().all(|x| *x >= 0.0));
    let plausible = !matches!(effect, Effect::CoriolisProduct { .. })
        || fit
            .theta
            .last()
            .is_some_and(|t| coriolis_product_plausible(t[0], &prep.baseline.m));
    let z = if dissipative && plausible { z } else { 0.0 };
    let force_share = prep.force_share(&null, &fit, &rows, runs);
    Some(Scored {
        spec,
        fit,
        shape_std: None,
        delta_bic,
        z,
        cv_gain: None,
        force_share,
    })
}

/// Whether a Coriolis product's coefficient can be one: the coefficients
/// of C(ν)ν (Fossen 2011, eq. 6.43) are sums and differences of two entries
/// of M, so |θ| ≤ 2·max|M_ij|. A larger one is the fit leaning on a product
/// nearly collinear with a velocity at the grid speed (u·q ≈ u₀·q), not a
/// Coriolis force.
pub(crate) fn coriolis_product_plausible(theta: f64, m: &nalgebra::DMatrix<f64>) -> bool {
    let largest = m.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
    theta.is_finite() && theta.abs() <= 2.0 * largest
}

/// Free-run NRMSE fits of `model` on `rec` for the channels `rows`. A run
/// that diverges (leaves validation's plausible band, see
/// [`crate::validation::divergence`]) or fits worse than
/// [`FIT_FLOOR`] scores the floor: how far beyond it says nothing, and an
/// unbounded −1e55 would make any candidate that tames it look like the
/// best gain.
pub(crate) fn free_run_fits(
    model: &super::model::AugmentedModel,
    rec: &Record,
    rows: &[usize],
) -> Vec<f64> {
    let sim = model.simulate(rec);
    rows.iter()
        .map(|&r| {
            let (y, yhat) = (rec.nu.column(r), sim.column(r));
            let band = PlausibleBand::of(y.as_slice());
            if !yhat.iter().all(|v| band.contains(*v)) {
                return FIT_FLOOR;
            }
            nrmse_fit(y.as_slice(), yhat.as_slice()).map_or(0.0, |f| f.max(FIT_FLOOR))
        })
        .collect()
}

/// Held-out gain in free-run fit of adding `cand` to `chosen`
/// (leave-one-run-out over `runs`): the sum over all channels of the fit
/// gained, averaged over folds — a term that helps several DOFs at once
/// counts for all of them. Both models are refitted on each training set.
pub(crate) fn cv_gain(
    prep: &Prepared<'_>,
    chosen: &[Spec],
    cand: &Scored,
    runs: &[usize],
) -> Option<f64> {
    let rows = prep.rows_of(&[cand.spec], &[]);
    let all_rows = prep.rows_of(chosen, &rows);
    let channels: Vec<usize> = (0..prep.baseline.n()).collect();
    let mut with = chosen.to_vec();
    with.push(cand.spec);
    let mut gains = Vec::new();
    for &held in runs {
        let train: Vec<usize> = runs.iter().copied().filter(|&r| r != held).collect();
        let f0 = prep.fit(chosen, &all_rows, &train, false)?;
        let f1 = prep.fit(&with, &all_rows, &train, false)?;
        let m0 = prep.model(chosen, &f0, &[]);
        let m1 = prep.model(&with, &f1, &[]);
        let rec = &prep.records[held];
        let a = free_run_fits(&m0, rec, &channels);
        let b = free_run_fits(&m1, rec, &channels);
        // A free run that diverges has a fit of −∞: below −1 (twice the
        // error of the mean) every fit counts as −1, so a gain is finite.
        let floor = |x: &f64| if x.is_finite() { x.max(-1.0) } else { -1.0 };
        let g = b
            .iter()
            .zip(&a)
            .map(|(b, a)| floor(b) - floor(a))
            .sum::<f64>();
        gains.push(g);
    }
    (!gains.is_empty()).then(|| gains.iter().sum::<f64>() / gains.len() as f64)
}

/// One step of forward selection: every candidate scored, the top ones
/// cross-validated.
pub(crate) struct Step {
    pub scored: Vec<Scored>,
    /// Index into `scored` of the winner, if one passed.
    pub winner: Option<usize>,
}

pub(crate) fn step(
    prep: &Prepared<'_>,
    chosen: &[Spec],
    library: &[Effect],
    runs: &[usize],
    c: &Criteria,
) -> Step {
    let taken: Vec<Effect> = chosen.iter().map(|s| s.effect).collect();
    let mut nulls = Nulls::default();
    let mut scored: Vec<Scored> = library
        .iter()
        .filter(|e| !taken.contains(e) && !conflicts(e, &taken))
        .filter_map(|&e| score_against(prep, chosen, e, runs, c, &mut nulls))
        .collect();
    scored.sort_by(|a, b| a.delta_bic.total_cmp(&b.delta_bic));
    let mut evaluated = 0;
    for s in scored.iter_mut() {
        if evaluated >= c.cv_candidates {
            break;
        }
        if s.significant(c) {
            s.cv_gain = cv_gain(prep, chosen, s, runs);
            evaluated += 1;
        }
    }
    let winner = scored
        .iter()
        .enumerate()
        .filter(|(_, s)| s.cv_gain.is_some_and(|g| g >= c.min_cv_gain))
        .max_by(|a, b| {
            a.1.cv_gain
                .unwrap_or(0.0)
                .total_cmp(&b.1.cv_gain.unwrap_or(0.0))
        })
        .map(|(i, _)| i);
    Step { scored, winner }
}

/// Candidates that re-describe a chosen term: a second actuator effect of
/// the same kind, or C(ν) from M next to its own products.
fn conflicts(e: &Effect, taken: &[Effect]) -> bool {
    taken.iter().any(|t| match (t, e) {
        (Effect::CoriolisFromM, Effect::CoriolisProduct { .. })
        | (Effect::CoriolisProduct { .. }, Effect::CoriolisFromM)
        | (Effect::CommonInputDelay, Effect::InputDelay { .. })
        | (Effect::InputDelay { .. }, Effect::CommonInputDelay)
        | (Effect::CommonActuatorLag, Effect::ActuatorLag { .. })
        | (Effect::ActuatorLag { .. }, Effect::CommonActuatorLag) => true,
        _ => t.shape().is_some() && e.shape() == t.shape() && t.dof() == e.dof(),
    })
}

#[cfg(test)]
mod tests {
    use super::coriolis_product_plausible;
    use crate::discrepancy::candidates::coriolis_force;
    use crate::planning::Dof;
    use nalgebra::DMatrix;

    #[test]
    fn a_coriolis_product_is_plausible_up_to_twice_the_largest_inertia() {
        // The v·r coefficient in surge of a coupled M is −M_22 (plus
        // couplings): within the bound; a hundredfold one is not.
        let dofs = Dof::ALL.to_vec();
        let m = DMatrix::from_fn(6, 6, |i, j| {
            if i == j {
                [300.0, 450.0, 500.0, 40.0, 60.0, 80.0][i]
            } else if (i, j) == (0, 4) || (i, j) == (4, 0) {
                25.0
            } else {
                0.0
            }
        });
        let f = |nu: [f64; 6]| coriolis_force(&dofs, &m, &nu)[0];
        let mut vr = [0.0; 6];
        vr[1] = 1.0;
        vr[5] = 1.0;
        let (mut v, mut r) = ([0.0; 6], [0.0; 6]);
        v[1] = 1.0;
        r[5] = 1.0;
        let coef = f(vr) - f(v) - f(r);
        assert!((coef + 450.0).abs() < 1e-9, "{coef}");
        assert!(coriolis_product_plausible(coef, &m));
        assert!(coriolis_product_plausible(-1000.0, &m));
        assert!(!coriolis_product_plausible(30_477.0, &m));
        assert!(!coriolis_product_plausible(f64::NAN, &m));
    }
}
