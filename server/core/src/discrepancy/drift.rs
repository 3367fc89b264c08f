//! Is a fitted current constant, or does it wander? The chosen model is
//! refitted window by window on the estimation runs (M and D̄ held at the
//! whole-data fit, the terms' coefficients free); the spread of the
//! window currents V_c,w is tested against their own (HAC) covariances
//! (χ² with 2(W − 1) degrees of freedom). Disagreeing windows are a
//! drifting current only if windows further apart differ more: for window
//! means of a random walk V̇_c = w, E[w²] = σ², over windows of length T,
//! Var(V̄_{w+k} − V̄_w) = σ²(kT − T/3) per axis (2.5× from k = 1 to 2);
//! σ is fitted to that variogram. Scatter that does not grow follows the
//! manoeuvres: the current is then reported as uncertain, not drifting.
//!
//! What a DP or MPC designer takes from it: a constant V_c for the model,
//! and σ as the process noise of a current state in the observer.

use nalgebra::{Matrix2, Vector2};
use serde::{Deserialize, Serialize};

use super::candidates::Effect;
use super::data::{Baseline, Record};
use super::fit::{Prepared, Spec};
use super::model::AugmentedModel;
use crate::numbers::{p_value as p_text, sig3};
use crate::validation::distributions::chi_square_sf;

/// One window's current.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct WindowCurrent {
    /// Run name.
    pub run: String,
    /// Window start and end in the run (s).
    pub t_s: [f64; 2],
    /// V_c north, east (m/s).
    pub ned: [f64; 2],
    /// Their standard deviations (m/s).
    pub std: [f64; 2],
}

/// Whether the current varies over the runs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct CurrentDrift {
    /// Window length (s).
    pub window_s: f64,
    /// The window currents.
    pub windows: Vec<WindowCurrent>,
    /// χ² of their spread about the weighted mean.
    pub chi2: f64,
    /// Its degrees of freedom, 2(W − 1).
    pub dof: usize,
    /// P(χ² ≥ observed) for a constant current.
    pub p_value: f64,
    /// The window currents disagree (p below the test level).
    pub varies: bool,
    /// They disagree as a drifting current does: windows further apart in
    /// a run differ more.
    pub drifts: bool,
    /// Random-walk intensity σ (m/s per √s) fitted to the within-run
    /// variogram, when it drifts.
    pub sigma_mps_per_sqrt_s: Option<f64>,
    /// In words.
    pub text: String,
}

/// Test level: a constant current is rejected below this p-value.
const LEVEL: f64 = 1e-3;

/// The window test of a current among `chosen`, on the estimation runs
/// `est` cut into windows of `window_s`; `None` without a current term or
/// with fewer than two windows.
pub(crate) fn current_drift(
    model: &AugmentedModel,
    est: &[Record],
    chosen: &[Spec],
    svf_t: f64,
    skip: usize,
    hac_lags: usize,
    window_s: f64,
) -> Option<CurrentDrift> {
    let si = chosen.iter().position(|s| s.effect == Effect::Current)?;
    let h = est.first()?.h;
    let len = (window_s / h).round() as usize;
    if len <= skip + 64 {
        return None;
    }
    // Windows of each run, as separate records (the filter restarts in each).
    let mut windows = Vec::new();
    let mut spans = Vec::new();
    for (ri, rec) in est.iter().enumerate() {
        let count = rec.len() / len;
        for w in 0..count {
            let a = w * len;
            windows.push(rec.slice(a, a + len, format!("{} @{}", rec.name, a)));
            spans.push((ri, a));
        }
    }
    if windows.len() < 2 {
        return None;
    }
    // M and D̄ held at the whole-data fit: a 30 s window at one speed cannot
    // tell a current from a damping error (τ ≈ D̄(u − u_c) under speed hold).
    let held = Baseline {
        dofs: model.dofs.clone(),
        m: model.m.clone(),
        d_bar: model.d_bar.clone(),
        restoring: model.restoring,
        coriolis: model.coriolis.clone(),
        quadratic: model.quadratic.clone(),
    };
    let prep = Prepared::new(&held, &windows, svf_t, skip, hac_lags)?.frozen();
    let mut est_w: Vec<(usize, usize, Vector2<f64>, Matrix2<f64>)> = Vec::new();
    for (wi, &(ri, a)) in spans.iter().enumerate() {
        let Some(f) = prep.fit(chosen, &[], &[wi], true) else {
            continue;
        };
        let (Some(th), Some(cov)) = (f.theta.get(si), f.theta_cov(si)) else {
            continue;
        };
        let c = Matrix2::new(cov[(0, 0)], cov[(0, 1)], cov[(1, 0)], cov[(1, 1)]);
        if c.determinant() > 0.0 && th.iter().all(|x| x.is_finite()) {
            est_w.push((ri, a, Vector2::new(th[0], th[1]), c));
        }
    }
    if est_w.len() < 2 {
        return None;
    }
    // Weighted mean and the χ² of the spread about it.
    let mut wsum = Matrix2::zeros();
    let mut wv = Vector2::zeros();
    for (_, _, v, c) in &est_w {
        let w = c.try_inverse()?;
        wsum += w;
        wv += w * v;
    }
    let mean = wsum.try_inverse()? * wv;
    let chi2: f64 = est_w
        .iter()
        .map(|(_, _, v, c)| {
            let d = v - mean;
            (d.transpose() * c.try_inverse().unwrap_or_else(Matrix2::zeros) * d)[(0, 0)]
        })
        .sum();
    let dof = 2 * (est_w.len() - 1);
    let p_value = chi_square_sf(chi2, dof as f64);
    let varies = p_value < LEVEL;
    // Variogram of the window currents within runs: a random walk makes
    // windows k apart differ by E|Δ|² = 2σ²(kT − T/3) (two axes), growing
    // with k; scatter from a model error follows the manoeuvres instead
    // and does not grow.
    let t = len as f64 * h;
    let mut gamma = [(0.0, 0usize); 4];
    for (i, a) in est_w.iter().enumerate() {
        for b in &est_w[i + 1..] {
            if a.0 != b.0 {
                continue;
            }
            let k = (b.1 - a.1) / len;
            if (1..=3).contains(&k) {
                let e = (b.2 - a.2).norm_squared() - (a.3.trace() + b.3.trace());
                gamma[k].0 += e;
                gamma[k].1 += 1;
            }
        }
    }
    let g = |k: usize| (gamma[k].1 > 0).then(|| gamma[k].0 / gamma[k].1 as f64);
    // Von Neumann ratio of the window currents within runs: Σ|ΔV|² over
    // Σ|V − V̄_run|², ≈ 2 for scatter that forgets from window to window,
    // far below for a path that wanders.
    let (mut num, mut den) = (0.0, 0.0);
    let (mut blocks, mut in_blocks) = (0usize, 0usize);
    let mut i = 0;
    while i < est_w.len() {
        let run = est_w[i].0;
        let j = est_w[i..]
            .iter()
            .position(|e| e.0 != run)
            .map_or(est_w.len(), |p| i + p);
        let block = &est_w[i..j];
        if block.len() >= 3 {
            let m = block.iter().map(|e| e.2).sum::<Vector2<f64>>() / block.len() as f64;
            den += block.iter().map(|e| (e.2 - m).norm_squared()).sum::<f64>();
            num += block
                .windows(2)
                .map(|p| (p[1].2 - p[0].2).norm_squared())
                .sum::<f64>();
            blocks += 1;
            in_blocks += block.len();
        }
        i = j;
    }
    let von_neumann = (den > 0.0).then(|| num / den);
    // Under scatter the ratio has mean 2 and variance 4(n − 2)/((n + 1)(n − 1))
    // for n windows of one axis; two axes and several runs pool it down.
    // A drifting current lies below at the 1 % level (z < −2.33).
    let z = von_neumann.map(|r| {
        let n = in_blocks as f64 / blocks.max(1) as f64;
        let var = 4.0 * (n - 2.0) / ((n + 1.0) * (n - 1.0)) / (2.0 * blocks.max(1) as f64);
        (r - 2.0) / var.sqrt()
    });
    let drifts = varies && z.is_some_and(|z| z < -2.326);
    let sigma = drifts
        .then(|| {
            let (mut num, mut den) = (0.0, 0.0);
            for k in 1..=3 {
                if let Some(gk) = g(k) {
                    let x = 2.0 * (k as f64 - 1.0 / 3.0) * t;
                    num += gk * x;
                    den += x * x;
                }
            }
            (den > 0.0).then(|| num / den)
        })
        .flatten()
        .filter(|s2| *s2 > 0.0)
        .map(f64::sqrt);
    let (lo, hi) = est_w.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), e| {
        let s = e.2.norm();
        (lo.min(s), hi.max(s))
    });
    let spread = format!(
        "over {} windows of {:.0} s its speed ranges {}–{} m/s (χ² = {} on {} degrees of freedom, {})",
        est_w.len(),
        t,
        sig3(lo),
        sig3(hi),
        sig3(chi2),
        dof,
        p_text(p_value)
    );
    // The von Neumann clause, when the runs hold enough windows for it.
    let ratio = |z_words: &str| match (von_neumann, z) {
        (Some(r), Some(z)) => format!("von Neumann ratio {}, z = {}{z_words}", sig3(r), sig3(z)),
        _ => "too few windows per run for a von Neumann ratio".to_owned(),
    };
    let text = if drifts {
        format!(
            "The current is not constant: {spread}, and it wanders ({}){}; the model keeps its mean, and an observer should carry the current as a state.",
            ratio(""),
            sigma.map_or(String::new(), |s| format!(
                ", as a random walk of σ = {} m/s per √s",
                sig3(s)
            )),
        )
    } else if varies {
        format!(
            "The window currents disagree but do not drift ({spread}; neighbouring windows differ as much as any two, {}): the disagreement follows the manoeuvres, so the current's size is uncertain beyond its std — the runs cannot separate it from a damping error, or other physics is missing. A deciding run: the same manoeuvre at four headings.",
            ratio(", where a drifting current lies far below 2")
        )
    } else {
        format!(
            "The current is steady: {} windows of {:.0} s agree with one value (χ² = {} on {} degrees of freedom, {}).",
            est_w.len(),
            t,
            sig3(chi2),
            dof,
            p_text(p_value)
        )
    };
    Some(CurrentDrift {
        window_s: t,
        windows: est_w
            .iter()
            .map(|(ri, a, v, c)| WindowCurrent {
                run: est[*ri].name.clone(),
                t_s: [*a as f64 * h, (*a + len) as f64 * h],
                ned: [v[0], v[1]],
                std: [c[(0, 0)].max(0.0).sqrt(), c[(1, 1)].max(0.0).sqrt()],
            })
            .collect(),
        chi2,
        dof,
        p_value,
        varies,
        drifts,
        sigma_mps_per_sqrt_s: sigma,
        text,
    })
}
