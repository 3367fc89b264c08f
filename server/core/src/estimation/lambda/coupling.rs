//! Proposing which DOFs to couple from the data: the coherence from each
//! γ_j to each ν_i (i ≠ j), median over the band where γ_j has power
//! (thesis sec. 2.6 and app. 7.2 look at the same spectra).
//!
//! With all DOFs excited at once, the ordinary coherence γ_j → ν_i is the
//! share of ν_i's *total* power explained by γ_j; ν_i is dominated by its
//! own input γ_i, so a real but moderate coupling hides below the
//! estimation floor. The decision therefore uses the *partial* coherence of
//! γ_j and ν_i given the other inputs (Bendat & Piersol, *Random Data*,
//! §7.3): the share of what the other inputs leave unexplained in ν_i that
//! γ_j explains, from the inverse P of the spectral matrix of
//! [γ_0 … γ_{n−1}, ν_i] per bin: |P_jν|² / (P_jj·P_νν). Both are reported.

use nalgebra::DMatrix;

use super::error::LambdaError;
use super::experiment::{Experiment, validate_runs};
use super::structure::CouplingMask;
use crate::spectra::{Complex, WelchConfig, multi_welch};

/// Bins count as "in the band" when the input PSD reaches this fraction of
/// its peak (DC excluded).
pub const BAND_FRACTION: f64 = 0.1;

/// Welch segments aimed for per run: the coherence of uncoupled signals
/// then averages ≈ 1/16 or less.
const SEGMENTS_PER_RUN: usize = 16;

/// Shortest run for a coherence estimate (samples).
pub const MIN_COHERENCE_SAMPLES: usize = 64;

/// The coherence evidence for one (output, input) pair.
#[derive(Debug, Clone, PartialEq)]
pub struct PairEvidence {
    /// Column index i of ν.
    pub output: usize,
    /// Column index j of γ (j ≠ i).
    pub input: usize,
    /// Median magnitude-squared (ordinary) coherence γ_j → ν_i over the
    /// band bins of all runs.
    pub median_coherence: f64,
    /// Median partial coherence of γ_j and ν_i given the other inputs over
    /// the same bins: the evidence the mask is decided on.
    pub median_partial_coherence: f64,
    /// Band bins pooled over the runs.
    pub n_bins: usize,
}

/// A proposed coupling structure and its evidence.
#[derive(Debug, Clone, PartialEq)]
pub struct CouplingProposal {
    /// Free entries: (i, j) free in A and B when the partial coherence
    /// γ_j → ν_i or γ_i → ν_j reaches the threshold, closed into blocks
    /// (connected groups of DOFs couple fully, which e^{hA} preserves).
    pub mask: CouplingMask,
    /// One entry per ordered pair i ≠ j.
    pub evidence: Vec<PairEvidence>,
    /// Expected partial coherence of uncoupled signals,
    /// 1/(segments per run − n + 1), averaged over the runs: a threshold
    /// well above it is meaningful.
    pub coherence_floor: f64,
}

/// Largest power of two ≤ n/[`SEGMENTS_PER_RUN`]·2 (50 % overlap), at
/// least 32 samples and at most n.
fn nperseg_for(n: usize) -> usize {
    let target = (2 * n / (SEGMENTS_PER_RUN + 1)).max(32);
    let pow2 = 1usize << (usize::BITS - 1 - target.leading_zeros());
    pow2.min(n)
}

/// Proposes a coupling mask from the coherence between DOFs.
///
/// # Errors
/// As the runs' validation (`runs[i].…`), a run shorter than
/// [`MIN_COHERENCE_SAMPLES`], `threshold` outside (0, 1).
pub fn propose_coupling(
    runs: &[Experiment],
    threshold: f64,
) -> Result<CouplingProposal, LambdaError> {
    if !(threshold > 0.0 && threshold < 1.0) {
        return Err(LambdaError::invalid(
            "threshold",
            format!("must lie in (0, 1), got {threshold}"),
        ));
    }
    let n = runs.first().map_or(0, |r| r.nu.ncols());
    if n == 0 {
        return Err(LambdaError::shape(
            "runs",
            "no run, or runs without columns",
        ));
    }
    let q = runs.first().map_or(0, |r| r.exogenous.ncols());
    let h = validate_runs("runs", runs, n, q, MIN_COHERENCE_SAMPLES)?;
    // Channels [γ_0 … γ_{n−1}, ν_0 … ν_{n−1}]; every input–input pair and
    // every input–output pair.
    let mut pairs: Vec<(usize, usize)> = Vec::new();
    for j in 0..n {
        for k in j + 1..n {
            pairs.push((j, k));
        }
    }
    let io_base = pairs.len();
    let io = |j: usize, i: usize| io_base + i * n + j;
    for i in 0..n {
        for j in 0..n {
            pairs.push((j, n + i));
        }
    }
    let mut ordinary: Vec<Vec<f64>> = vec![Vec::new(); n * n];
    let mut partial: Vec<Vec<f64>> = vec![Vec::new(); n * n];
    let mut floor = 0.0;
    for (r, run) in runs.iter().enumerate() {
        let len = run.len();
        let cfg = WelchConfig::hann(1.0 / h, nperseg_for(len));
        let channels: Vec<&[f64]> = (0..n)
            .map(|j| &run.gamma.as_slice()[j * len..(j + 1) * len])
            .chain((0..n).map(|i| &run.nu.as_slice()[i * len..(i + 1) * len]))
            .collect();
        let block = std::iter::once(0..len).collect::<Vec<_>>();
        let sp = multi_welch(&channels, &block, &pairs, &cfg)
            .map_err(|e| LambdaError::invalid(format!("runs[{r}]"), e.to_string()))?;
        let dof_left = sp.n_segments.saturating_sub(n - 1).max(1);
        floor += 1.0 / dof_left as f64 / runs.len() as f64;
        let peaks: Vec<f64> = (0..n)
            .map(|j| sp.auto[j].iter().skip(1).copied().fold(0.0, f64::max))
            .collect();
        let in_band =
            |j: usize, k: usize| peaks[j] > 0.0 && sp.auto[j][k] >= BAND_FRACTION * peaks[j];
        // Spectral matrix entry (a, b) of [γ, ν_i], a ≤ b in channel order.
        let entry = |a: usize, b: usize, i: usize, k: usize| -> Complex<f64> {
            let (lo, hi, conj) = if a <= b { (a, b, false) } else { (b, a, true) };
            let v = if lo == hi {
                Complex::new(
                    if lo == n {
                        sp.auto[n + i][k]
                    } else {
                        sp.auto[lo][k]
                    },
                    0.0,
                )
            } else if hi == n {
                sp.cross[io(lo, i)][k]
            } else {
                sp.cross[lo * n - lo * (lo + 1) / 2 + (hi - lo - 1)][k]
            };
            if conj { v.conj() } else { v }
        };
        for i in 0..n {
            for k in 1..sp.freqs.len() {
                if !(0..n).any(|j| j != i && in_band(j, k)) {
                    continue;
                }
                let s_mat: Vec<Vec<Complex<f64>>> = (0..=n)
                    .map(|a| (0..=n).map(|b| entry(a, b, i, k)).collect())
                    .collect();
                let inv = invert(s_mat);
                for j in (0..n).filter(|&j| j != i && in_band(j, k)) {
                    let coh = sp.coherence(io(j, i))[k];
                    ordinary[i * n + j].push(coh);
                    if let Some(p) = &inv {
                        let denom = p[j][j].re * p[n][n].re;
                        if denom > 0.0 {
                            partial[i * n + j].push(p[j][n].norm_sqr() / denom);
                        }
                    }
                }
            }
        }
    }
    let median = |values: &mut Vec<f64>| {
        values.sort_by(f64::total_cmp);
        match values.len() {
            0 => 0.0,
            m if m % 2 == 1 => values[m / 2],
            m => 0.5 * (values[m / 2 - 1] + values[m / 2]),
        }
    };
    let mut evidence = Vec::with_capacity(n * (n - 1));
    let mut pattern = DMatrix::from_element(n, n, false);
    for i in 0..n {
        for j in (0..n).filter(|&j| j != i) {
            let pc = median(&mut partial[i * n + j]);
            if pc >= threshold {
                pattern[(i, j)] = true;
                pattern[(j, i)] = true;
            }
            evidence.push(PairEvidence {
                output: i,
                input: j,
                median_coherence: median(&mut ordinary[i * n + j]),
                median_partial_coherence: pc,
                n_bins: partial[i * n + j].len(),
            });
        }
    }
    let blocks = CouplingMask::from_pattern(&pattern).blocks();
    Ok(CouplingProposal {
        mask: CouplingMask::from_pattern(&blocks),
        evidence,
        coherence_floor: floor,
    })
}

/// Inverse of a small complex matrix by Gauss–Jordan elimination with
/// partial pivoting; `None` when (numerically) singular.
fn invert(mut a: Vec<Vec<Complex<f64>>>) -> Option<Vec<Vec<Complex<f64>>>> {
    let n = a.len();
    let scale = (0..n).map(|i| a[i][i].norm()).fold(0.0, f64::max);
    if scale <= 0.0 || !scale.is_finite() {
        return None;
    }
    let mut inv: Vec<Vec<Complex<f64>>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| Complex::new(f64::from(u8::from(i == j)), 0.0))
                .collect()
        })
        .collect();
    for c in 0..n {
        let p = (c..n).max_by(|&x, &y| a[x][c].norm().total_cmp(&a[y][c].norm()))?;
        if a[p][c].norm() <= 1e-13 * scale {
            return None;
        }
        a.swap(c, p);
        inv.swap(c, p);
        let d = a[c][c].inv();
        for j in 0..n {
            a[c][j] *= d;
            inv[c][j] *= d;
        }
        for r in 0..n {
            if r != c {
                let f = a[r][c];
                if f != Complex::new(0.0, 0.0) {
                    for j in 0..n {
                        let (acj, icj) = (a[c][j], inv[c][j]);
                        a[r][j] -= f * acj;
                        inv[r][j] -= f * icj;
                    }
                }
            }
        }
    }
    Some(inv)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    #[allow(clippy::needless_range_loop)]
    fn complex_inverse_is_an_inverse() {
        let a = vec![
            vec![Complex::new(2.0, 0.0), Complex::new(0.5, 1.0)],
            vec![Complex::new(0.5, -1.0), Complex::new(3.0, 0.0)],
        ];
        let inv = invert(a.clone()).unwrap();
        for i in 0..2 {
            for j in 0..2 {
                let s: Complex<f64> = (0..2).map(|k| a[i][k] * inv[k][j]).sum();
                let e = if i == j { 1.0 } else { 0.0 };
                assert!((s - Complex::new(e, 0.0)).norm() < 1e-14);
            }
        }
        assert!(invert(vec![vec![Complex::new(0.0, 0.0)]]).is_none());
    }
}
