//! Proposing which DOFs to couple from the data: the coherence from each
//! γ_j to each ν_i (i ≠ j), median over the band where γ_j has power
//! (thesis sec. 2.6 and app. 7.2 look at the same spectra).
//!
//! With all DOFs excited at once by independent signals, the coherence
//! γ_j → ν_i is the share of ν_i's power explained linearly by γ_j, so it is
//! near its estimation floor (≈ 1/segments) unless γ_j reaches ν_i through
//! M⁻¹ or D̄ coupling.

use nalgebra::DMatrix;

use super::error::LambdaError;
use super::experiment::{Experiment, validate_runs};
use super::structure::CouplingMask;
use crate::spectra::{WelchConfig, multi_welch};

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
    /// Median magnitude-squared coherence γ_j → ν_i over the band bins of
    /// all runs.
    pub median_coherence: f64,
    /// Band bins pooled over the runs.
    pub n_bins: usize,
}

/// A proposed coupling structure and its evidence.
#[derive(Debug, Clone, PartialEq)]
pub struct CouplingProposal {
    /// Free entries: (i, j) free in A and B when the coherence
    /// γ_j → ν_i or γ_i → ν_j reaches the threshold, closed into blocks
    /// (connected groups of DOFs couple fully, which e^{hA} preserves).
    pub mask: CouplingMask,
    /// One entry per ordered pair i ≠ j.
    pub evidence: Vec<PairEvidence>,
    /// Expected coherence of uncoupled signals, 1/(segments per run),
    /// averaged over the runs: a threshold well above it is meaningful.
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
        return Err(LambdaError::shape("runs", "no run, or runs without columns"));
    }
    let h = validate_runs("runs", runs, n, MIN_COHERENCE_SAMPLES)?;
    let pairs: Vec<(usize, usize)> = (0..n)
        .flat_map(|i| (0..n).filter(move |&j| j != i).map(move |j| (j, n + i)))
        .collect();
    let mut pooled: Vec<Vec<f64>> = vec![Vec::new(); pairs.len()];
    let mut floor = 0.0;
    for (r, run) in runs.iter().enumerate() {
        let len = run.len();
        let cfg = WelchConfig::hann(1.0 / h, nperseg_for(len));
        let channels: Vec<&[f64]> = (0..n)
            .map(|j| &run.gamma.as_slice()[j * len..(j + 1) * len])
            .chain((0..n).map(|i| &run.nu.as_slice()[i * len..(i + 1) * len]))
            .collect();
        let spectra = multi_welch(&channels, &[0..len], &pairs, &cfg)
            .map_err(|e| LambdaError::invalid(format!("runs[{r}]"), e.to_string()))?;
        floor += 1.0 / spectra.n_segments.max(1) as f64 / runs.len() as f64;
        for (p, &(j, _)) in pairs.iter().enumerate() {
            let psd = &spectra.auto[j];
            let peak = psd.iter().skip(1).copied().fold(0.0, f64::max);
            if peak <= 0.0 {
                continue;
            }
            let coh = spectra.coherence(p);
            pooled[p].extend(
                (1..psd.len())
                    .filter(|&k| psd[k] >= BAND_FRACTION * peak)
                    .map(|k| coh[k]),
            );
        }
    }
    let mut evidence = Vec::with_capacity(pairs.len());
    let mut pattern = DMatrix::from_element(n, n, false);
    for (p, &(j, ni)) in pairs.iter().enumerate() {
        let i = ni - n;
        let values = &mut pooled[p];
        values.sort_by(f64::total_cmp);
        let median = match values.len() {
            0 => 0.0,
            m if m % 2 == 1 => values[m / 2],
            m => 0.5 * (values[m / 2 - 1] + values[m / 2]),
        };
        if median >= threshold {
            pattern[(i, j)] = true;
            pattern[(j, i)] = true;
        }
        evidence.push(PairEvidence {
            output: i,
            input: j,
            median_coherence: median,
            n_bins: values.len(),
        });
    }
    let blocks = CouplingMask::from_pattern(&pattern).blocks();
    Ok(CouplingProposal {
        mask: CouplingMask::from_pattern(&blocks),
        evidence,
        coherence_floor: floor,
    })
}
