//! Profile searches over a term's shape parameter (lag, delay, threshold)
//! on the k-step prediction error, with a standard deviation from the
//! curvature of its SSE and the residuals' long-run variance.

use super::*;

/// κ = 1 + 2 Σ_l (1 − l/(L+1)) ρ(l) of residual blocks (the factor by which
/// correlated residuals shrink the effective sample count), ≥ 1.
pub(crate) fn long_run_inflation(blocks: &[Vec<f64>], lags: usize) -> f64 {
    let mut r0 = 0.0;
    let mut rl = vec![0.0; lags + 1];
    for e in blocks {
        r0 += dot(e, e);
        for (l, acc) in rl.iter_mut().enumerate().skip(1) {
            if l < e.len() {
                *acc += dot(&e[l..], &e[..e.len() - l]);
            }
        }
    }
    if r0 <= 0.0 {
        return 1.0;
    }
    let k = 1.0
        + 2.0
            * (1..=lags)
                .map(|l| (1.0 - l as f64 / (lags as f64 + 1.0)) * rl[l] / r0)
                .sum::<f64>();
    k.max(1.0)
}

/// A profile search over a shape parameter on the k-step prediction error
/// of its row ([`Prepared::kstep_row`]): the grid minimum, refined by
/// golden section between its neighbours (every shape, a delay's fraction
/// of a sample included, is continuous), with a standard
/// deviation from the curvature of the SSE (Δχ² = 1 at ΔSSE = κσ²).
pub(crate) struct Profile {
    pub value: f64,
    pub fit: FitOut,
    pub std: Option<f64>,
    /// k-step prediction SSE of the row at the optimum.
    pub sse: f64,
    /// Predicted samples.
    pub n: usize,
    /// The optimum lies at an end of the grid, as close to it as the
    /// refinement resolves: a bound, not an estimate.
    pub at_edge: bool,
}

#[allow(clippy::too_many_arguments)]
pub(crate) fn profile(
    prep: &Prepared<'_>,
    chosen: &[Spec],
    effect: Effect,
    extra: &[usize],
    runs: &[usize],
    grid: &[f64],
    k: usize,
) -> Option<Profile> {
    extra.first()?;
    let specs_at = |v: f64| {
        let mut specs = chosen.to_vec();
        specs.push(Spec {
            effect,
            shape: Some(v),
        });
        specs
    };
    let lag = effect.shape() == Some(super::super::candidates::ShapeKind::LagTime);
    // A refitted row must stay a hull: M_rr > 0, D̄_rr ≥ 0, and a lag must
    // be the faster of the two poles. Lag T and the hull's M_rr/D̄_rr are
    // interchangeable in 1/((1+sT)(D̄ + sM)) — the data cannot tell them
    // apart — so the slow pole is the hull's and the fast one the
    // thruster's, as on every ROV and ship.
    let admissible = |f: &FitOut, v: f64| {
        f.rows.iter().enumerate().all(|(ri, &r)| {
            let (m, d) = prep.row_diagonal(f, ri, r);
            m.is_none_or(|m| m > 0.0)
                && d.is_none_or(|d| d >= 0.0)
                && !(lag && matches!((m, d), (Some(m), Some(d)) if d > 0.0 && m / d <= v))
        })
    };
    let shaped = prep.shape_profile(&specs_at(grid[0]), extra, runs);
    // θ alone at a point of the search; the optimum's fit in full.
    let theta_at = |v: f64| -> Option<FitOut> {
        match &shaped {
            Some(s) => s.at(v),
            None => prep.fit(&specs_at(v), extra, runs, false),
        }
        .filter(|f| admissible(f, v))
    };
    let eval = |v: f64| -> Option<FitOut> {
        prep.fit(&specs_at(v), extra, runs, false)
            .filter(|f| admissible(f, v))
    };
    let sse = |v: f64| {
        theta_at(v)
            .and_then(|f| prep.kstep_rows(&specs_at(v), &f, extra, runs, k))
            .map_or(f64::INFINITY, |x| x.0)
    };
    let values: Vec<f64> = grid.iter().map(|&g| sse(g)).collect();
    let (ib, _) = values
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(b.1))?;
    let mut best = grid[ib];
    let end = ib == 0 || ib + 1 == grid.len();
    let mut at_edge = end;
    if grid.len() >= 3 {
        // Golden section in log space (parameters are positive scales).
        let lo = grid[ib.saturating_sub(1)].ln();
        let hi = grid[(ib + 1).min(grid.len() - 1)].ln();
        let (mut a, mut b) = (lo, hi);
        let r = 0.618_033_988_749_895;
        let mut c = b - r * (b - a);
        let mut d = a + r * (b - a);
        let (mut fc, mut fd) = (sse(c.exp()), sse(d.exp()));
        for _ in 0..6 {
            if fc < fd {
                b = d;
                d = c;
                fd = fc;
                c = b - r * (b - a);
                fc = sse(c.exp());
            } else {
                a = c;
                c = d;
                fc = fd;
                d = a + r * (b - a);
                fd = sse(d.exp());
            }
        }
        let (cand, f_cand) = if fc < fd {
            (c.exp(), fc)
        } else {
            (d.exp(), fd)
        };
        if f_cand < values[ib] {
            best = cand;
            // Refined away from an end by more than the final bracket:
            // the minimum is inside the range after all.
            at_edge = end && (best.ln() - grid[ib].ln()).abs() <= (b - a).abs();
        }
    }
    let fit = eval(best)?;
    let (s0, resid) = prep.kstep_rows(&specs_at(best), &fit, extra, runs, k)?;
    let delta = 0.03 * best.abs().max(1e-9);
    let (sm, sp) = (sse(best - delta), sse(best + delta));
    // The curvature from three points of one kind of fit.
    let sc = match &shaped {
        Some(s) if !s.exact => sse(best),
        _ => s0,
    };
    let curv = (sp - 2.0 * sc + sm) / (delta * delta);
    let n: usize = resid.iter().map(Vec::len).sum();
    let kappa = long_run_inflation(&resid, prep.hac_lags.max(2 * k));
    let sigma2 = s0 / n.max(1) as f64;
    let std = (curv > 0.0 && sm.is_finite() && sp.is_finite())
        .then(|| (2.0 * sigma2 * kappa / curv).sqrt());
    Some(Profile {
        value: best,
        fit,
        std,
        sse: s0,
        n,
        at_edge,
    })
}
