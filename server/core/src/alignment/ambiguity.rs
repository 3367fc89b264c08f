//! Which other offsets fit about as well as the best one.
//!
//! The local standard error of the refinement (`refine.rs`) says how sharp
//! the chosen peak is, not whether it is the right peak: a shared channel
//! that barely moves (a static run holding depth, noise and a slow drift),
//! or moves periodically, correlates almost as well at many offsets, and
//! the highest of them is then a matter of chance — tens of seconds off
//! with a tiny local error. This module finds the offsets that the data
//! cannot tell apart from the best one.
//!
//! Test: a likelihood ratio on common samples, standardized as for
//! non-nested models (Vuong 1989). The *reference* is the shorter record
//! over its overlap at the best integer lag `m₀`; at every other lag `m`,
//! the reference samples that pair at both lags are compared. With `J(m)`
//! the mean square of the reference after removing its line and the best
//! gain times its partner at lag `m` (`(1 − ρ²)` times the detrended
//! variance, `ρ` Pearson over those samples, at its best sub-sample shift
//! by a parabola through the neighbouring lags), and `J₀` the same for the
//! residual at `m₀` over those samples,
//!
//! `z(m) = ½·ln(J(m) / J₀) · √(n/τ)`,
//!
//! the mean per-sample Gaussian log-likelihood ratio of `m₀` over `m`
//! divided by its standard error when both lags fit equally well: the two
//! residuals then differ by their partners' independent noise, each
//! per-sample difference has unit variance, and `τ` — the integrated
//! autocorrelation time of the residual at `m₀` (Geyer's initial positive
//! sequence) — counts coloured residuals (a sensor's own slow wander,
//! interpolation) as fewer independent samples. `m` is *plausible* while
//! `z(m) < 3`. A lag whose common samples are under a quarter of the
//! reference (a short overlap at the edge of the search) is plausible when
//! its evidence `ρ·√(overlap / shorter record)` is at least half the peak's.
//! Comparing on common samples matters: a periodic channel fits every
//! period equally well per sample, and the longest overlap must not win for
//! being long. The plain likelihood ratio `n/(2τ)·ln(J/J₀)` would not do:
//! between two periods its noise grows like `√n`, and a clean periodic run
//! would confidently pick a wrong period.
//!
//! The set of plausible lags is a confidence set for the true lag; the
//! reported standard deviation is widened so that ±2σ around the estimate
//! covers it (`calibrate.rs`). Its shape gives the reason in words:
//! separate clusters (ambiguous, e.g. periodic), one cluster around the
//! peak (broad peak), or much of the search range (flat).

use super::xcorr::{Correlation, Prefix, analyze_peak, normalized_xcorr, raw_xcorr};

/// Fewest reference samples for the test.
const MIN_REFERENCE: usize = 64;
/// Share of the reference a lag must pair at both lags to be tested.
const MIN_COMMON_SHARE: f64 = 0.25;
/// Standardized log-likelihood ratio below which a lag stays plausible.
const Z_PLAUSIBLE: f64 = 3.0;
/// Evidence ratio at which an untestable (short-overlap) lag stays plausible.
const UNTESTABLE_EVIDENCE: f64 = 0.5;
/// Share of the admissible lags beyond which the correlation is called flat.
const FLAT_SHARE: f64 = 0.2;
/// Competing offsets reported, best first.
pub(crate) const MAX_ALTERNATIVES: usize = 5;

/// What the test found.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Plausible {
    /// Lags outside the peak's window that fit about as well as the peak,
    /// in increasing order.
    pub lags: Vec<i64>,
    /// Number of admissible lags.
    pub admissible: usize,
    /// Plausible local maxima of the correlation, highest correlation first
    /// (at most [`MAX_ALTERNATIVES`]).
    pub alternatives: Vec<i64>,
    /// Groups of plausible lags separated by more than the window.
    pub clusters: usize,
    /// One of the clusters touches the peak's window (a broad peak).
    pub touches_peak: bool,
}

impl Plausible {
    /// How the plausible set looks, in words (`None` when it is empty).
    pub(crate) fn shape(&self) -> Option<Shape> {
        if self.lags.is_empty() {
            None
        } else if self.lags.len() as f64 > FLAT_SHARE * self.admissible as f64 {
            Some(Shape::Flat)
        } else if self.clusters == 1 && self.touches_peak {
            Some(Shape::Broad)
        } else {
            Some(Shape::Ambiguous)
        }
    }
}

/// The shape of the set of offsets that fit as well as the best.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Shape {
    /// Separate offsets fit about as well (periodic or repetitive channel).
    Ambiguous,
    /// The peak is wider than the refinement window.
    Broad,
    /// Much of the search range fits as well.
    Flat,
}

/// Integrated autocorrelation time `1 + 2Σρ_k` of `r`, summed by Geyer's
/// initial positive (monotone) sequence; at least 1, at most `len/4`.
pub(crate) fn autocorrelation_time(r: &[f64]) -> f64 {
    let n = r.len();
    if n < 8 {
        return 1.0;
    }
    let raw = raw_xcorr(r, r);
    let c0 = raw[0];
    if c0 <= 0.0 || !c0.is_finite() {
        return 1.0;
    }
    let rho = |k: usize| raw[k] / c0;
    let (mut sum, mut prev) = (0.0, f64::INFINITY);
    let mut j = 0;
    while 2 * j + 1 < n / 2 {
        let pair = (rho(2 * j) + rho(2 * j + 1)).min(prev);
        if pair <= 0.0 {
            break;
        }
        sum += pair;
        prev = pair;
        j += 1;
    }
    (2.0 * sum - 1.0).clamp(1.0, n as f64 / 4.0)
}

/// Lags of `corr` (over detrended grid records `a`, `b`; lag `m` pairs
/// `a[k]` with `b[k − m]`) that fit about as well as the peak lag `m0`,
/// outside `m0 ± window`. `None` when the overlap at `m0` is too short for
/// the test (fewer than 64 samples).
pub(crate) fn plausible_lags(
    a: &[f64],
    b: &[f64],
    corr: &Correlation,
    m0: i64,
    window: i64,
) -> Option<Plausible> {
    let (na, nb) = (a.len() as i64, b.len() as i64);
    let n_lags = corr.rho.len();
    let hi = corr.lo + n_lags as i64 - 1;
    let i0 = usize::try_from(m0 - corr.lo).ok().filter(|&i| i < n_lags)?;
    // The reference: the shorter record over its overlap at m0. Reference
    // sample i pairs with `other[i + q(m)]` at lag m.
    let a_ref = na <= nb;
    let (k_lo, k_hi) = (m0.max(0), na.min(nb + m0));
    let len = (k_hi - k_lo).max(0) as usize;
    if len < MIN_REFERENCE {
        return None;
    }
    let (reference, other, s_lo, sign) = if a_ref {
        (&a[k_lo as usize..k_hi as usize], b, k_lo, -1)
    } else {
        (
            &b[(k_lo - m0) as usize..(k_hi - m0) as usize],
            a,
            k_lo - m0,
            1,
        )
    };
    let q = |m: i64| s_lo + sign * m;
    // normalized_xcorr(x, y) pairs x[i] with y[i − L]: L = −q(m).
    let (l_lo, l_hi) = if a_ref {
        (corr.lo - s_lo, hi - s_lo)
    } else {
        (-s_lo - hi, -s_lo - corr.lo)
    };
    let common = normalized_xcorr(reference, other, l_lo, l_hi);
    let n_other = other.len() as i64;

    // Residual at m0: the reference less its line and the best gain times
    // its partner (all reference samples pair at m0).
    let q0 = q(m0);
    let partner: Vec<f64> = (0..len as i64).map(|i| other[(i + q0) as usize]).collect();
    let (x, u) = (detrended(reference), detrended(&partner));
    let uu: f64 = u.iter().map(|v| v * v).sum();
    let gain = if uu > 0.0 {
        x.iter().zip(&u).map(|(p, v)| p * v).sum::<f64>() / uu
    } else {
        0.0
    };
    let r0: Vec<f64> = x.iter().zip(&u).map(|(p, v)| p - gain * v).collect();
    let tau = autocorrelation_time(&r0);
    let mut r0_sq = Vec::with_capacity(len + 1);
    r0_sq.push(0.0);
    for v in &r0 {
        r0_sq.push(r0_sq[r0_sq.len() - 1] + v * v);
    }
    let prefix = Prefix::new(reference);
    let min_common = (MIN_COMMON_SHARE * len as f64).max(16.0) as i64;
    let (z_peak, threshold) = (corr.z[i0], Z_PLAUSIBLE);
    // Unexplained share 1 − ρ² at lag m, at its best sub-sample shift (a
    // parabola through the neighbours): a lag is judged at its best, not
    // at the grid's rounding of it, which on a clean periodic channel
    // would decide between periods.
    let unexplained = |m: i64| {
        let at = |m: i64| {
            let l = -q(m) - l_lo;
            usize::try_from(l)
                .ok()
                .and_then(|l| common.rho.get(l))
                .map(|r| 1.0 - r.max(0.0).powi(2))
        };
        let y0 = at(m).unwrap_or(1.0);
        match (at(m - 1), at(m + 1)) {
            // Only a minimum within half a lag: otherwise a neighbour is
            // lower and judged in its own right.
            (Some(ym), Some(yp)) if ym >= y0 && yp >= y0 && ym + yp - 2.0 * y0 > 0.0 => {
                (y0 - (yp - ym).powi(2) / (8.0 * (ym + yp - 2.0 * y0))).clamp(0.0, y0)
            }
            _ => y0,
        }
    };
    // The residual at m0 is on the grid too: scale it to its best shift.
    let u0 = 1.0 - common.rho[(-q0 - l_lo) as usize].max(0.0).powi(2);
    let best0 = if u0 > 0.0 { unexplained(m0) / u0 } else { 1.0 };

    let plausible = |i: usize| -> bool {
        let m = corr.lo + i as i64;
        let qm = q(m);
        let (c_lo, c_hi) = ((-qm).max(0), (len as i64).min(n_other - qm));
        let n = c_hi - c_lo;
        if n < min_common {
            return corr.z[i] >= UNTESTABLE_EVIDENCE * z_peak;
        }
        let (s0, s1, sq) = prefix.window(c_lo as usize, n as usize);
        let nf = n as f64;
        let sc = nf * (nf * nf - 1.0) / 12.0;
        let var = (sq - s0 * s0 / nf - s1 * s1 / sc).max(0.0);
        let j_m = var * unexplained(m);
        let j_0 = best0 * (r0_sq[c_hi as usize] - r0_sq[c_lo as usize]);
        if j_m <= j_0 {
            return true;
        }
        if j_0 <= 0.0 {
            return false;
        }
        0.5 * (j_m / j_0).ln() * (nf / tau).sqrt() < threshold
    };
    let lags: Vec<i64> = (0..n_lags)
        .filter(|&i| (i as i64 - i0 as i64).abs() > window && plausible(i))
        .map(|i| corr.lo + i as i64)
        .collect();
    let mut clusters = 0;
    let mut touches_peak = false;
    let mut prev: Option<i64> = None;
    for &m in &lags {
        if prev.is_none_or(|p| m - p > window) {
            clusters += 1;
        }
        prev = Some(m);
        touches_peak |= (m - m0).abs() <= 2 * window + 1;
    }
    let mut maxima: Vec<i64> = lags
        .iter()
        .copied()
        .filter(|&m| {
            // Interior local maxima: an edge of the search is no peak.
            let i = (m - corr.lo) as usize;
            i > 0
                && i + 1 < n_lags
                && corr.rho[i - 1] <= corr.rho[i]
                && corr.rho[i + 1] < corr.rho[i]
        })
        .collect();
    maxima.sort_by(|x, y| {
        let (i, j) = ((x - corr.lo) as usize, (y - corr.lo) as usize);
        corr.rho[j].total_cmp(&corr.rho[i])
    });
    maxima.truncate(MAX_ALTERNATIVES);
    Some(Plausible {
        lags,
        admissible: n_lags,
        alternatives: maxima,
        clusters,
        touches_peak,
    })
}

/// Whether `b` negated has one clear best lag: a sign-flipped shared
/// channel (depth vs. height) is declared only then, not for a slow drift
/// that happens to anti-correlate somewhere.
pub(crate) fn clear_anti_peak(a: &[f64], b: &[f64], corr: &Correlation, window: i64) -> bool {
    let negated = Correlation {
        lo: corr.lo,
        rho: corr.rho.iter().map(|r| -r).collect(),
        z: corr.z.iter().map(|z| -z).collect(),
    };
    let Some(peak) = analyze_peak(&negated) else {
        return false;
    };
    let minus_b: Vec<f64> = b.iter().map(|v| -v).collect();
    !peak.at_edge
        && plausible_lags(a, &minus_b, &negated, peak.lag, window)
            .is_some_and(|p| p.lags.is_empty())
}

/// `x` less its least-squares line over the index.
fn detrended(x: &[f64]) -> Vec<f64> {
    let mut y = x.to_vec();
    super::grid::detrend_linear(&mut y);
    y
}

#[cfg(test)]
mod tests {
    use super::*;

    fn noise(seed: u64, n: usize) -> Vec<f64> {
        let mut s = seed;
        (0..n)
            .map(|_| {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            })
            .collect()
    }

    fn peak(c: &Correlation) -> i64 {
        let (i, _) = c
            .rho
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))
            .unwrap();
        c.lo + i as i64
    }

    #[test]
    fn a_broadband_shared_signal_has_one_plausible_offset() {
        let s = noise(1, 3000);
        let (e1, e2) = (noise(2, 3000), noise(3, 3000));
        let a: Vec<f64> = (200..2800).map(|k| s[k] + 0.1 * e1[k]).collect();
        let b: Vec<f64> = (0..2900).map(|k| s[k] + 0.1 * e2[k]).collect();
        let c = normalized_xcorr(&a, &b, -2000, 2000);
        let m0 = peak(&c);
        assert_eq!(m0, -200);
        let p = plausible_lags(&a, &b, &c, m0, 2).unwrap();
        assert!(p.lags.is_empty(), "{:?}", &p.lags[..p.lags.len().min(10)]);
        assert_eq!(p.shape(), None);
    }

    #[test]
    fn a_periodic_signal_is_ambiguous_and_noise_is_flat() {
        // One sinusoid, independent noise in each record.
        let wave = |k: usize| (k as f64 * 0.05).sin();
        let per: Vec<f64> = noise(4, 3000)
            .iter()
            .enumerate()
            .map(|(k, e)| wave(k) + 0.05 * e)
            .collect();
        let other: Vec<f64> = noise(5, 3000)
            .iter()
            .enumerate()
            .map(|(k, e)| wave(k) + 0.05 * e)
            .collect();
        let c = normalized_xcorr(&per[..2500], &other, -2000, 1500);
        let m0 = peak(&c);
        let p = plausible_lags(&per[..2500], &other, &c, m0, 2).unwrap();
        assert!(!p.alternatives.is_empty());
        // A period is 2π/0.05 ≈ 125.7 samples: alternatives sit on periods.
        for m in &p.alternatives {
            let periods = (m - m0) as f64 / 125.66;
            assert!((periods - periods.round()).abs() < 0.05, "{m} vs {m0}");
        }
        assert!(matches!(p.shape(), Some(Shape::Ambiguous | Shape::Flat)));

        let (a, b) = (noise(6, 2000), noise(7, 2000));
        let c = normalized_xcorr(&a, &b, -1500, 1500);
        let p = plausible_lags(&a, &b, &c, peak(&c), 2).unwrap();
        assert_eq!(p.shape(), Some(Shape::Flat), "{} lags", p.lags.len());
    }

    #[test]
    fn too_short_an_overlap_is_not_tested() {
        let (a, b) = (noise(8, 50), noise(9, 50));
        let c = normalized_xcorr(&a, &b, -25, 25);
        assert_eq!(plausible_lags(&a, &b, &c, peak(&c), 2), None);
    }
}
