//! Multichannel Welch: every auto-spectrum and any set of cross spectra of
//! many channels from one FFT per channel and segment, over the valid blocks
//! of a record.
//!
//! Computing the 36 cross spectra of 6 inputs × 6 outputs pair by pair costs
//! 72 FFTs per segment (2 per pair); here it costs 12 (one per channel),
//! reused for the 12 auto-spectra and the 36 products `conj(X_i)·X_j`.
//!
//! Segments are taken inside each block exactly as
//! `scipy.signal.welch(x[block])` would take them (starts at
//! `block.start + m·(nperseg − noverlap)`, trailing samples that do not fill
//! a segment ignored), and the mean runs over all segments of all blocks.
//! With a single block covering the record, every spectrum is the one of
//! [`super::welch`] / [`super::csd`] to rounding (the constant detrend is
//! removed partly in the frequency domain, see
//! [`SegmentFft::transform_centred`]; sums of products are fused
//! multiply–adds on CPUs with AVX2 and FMA), hence equal to scipy's to
//! ~1e-12.

use std::ops::Range;

use realfft::num_complex::Complex;

use super::accumulators::{Accumulators, SummedSpectra};
use super::batches::{batches, parts, run_parts};
use super::engine::SegmentFft;
use super::{Detrend, SpectraError, WelchConfig};

/// Borrowed `(P_ij, P_ii, P_jj)` of one pair.
type PairParts<'a> = (&'a [Complex<f64>], &'a [f64], &'a [f64]);

/// Welch spectra of several channels: one auto-spectrum per channel and one
/// cross spectrum per requested pair, all on the same frequency grid and
/// averaged over the same `n_segments` segments.
#[derive(Debug, Clone, PartialEq)]
pub struct MultiSpectra {
    /// Frequencies in Hz, `k · fs / nperseg` for `k = 0..=nperseg/2`.
    pub freqs: Vec<f64>,
    /// One-sided PSD of each channel (units² / Hz), in channel order.
    pub auto: Vec<Vec<f64>>,
    /// The requested `(i, j)` channel pairs, in request order.
    pub pairs: Vec<(usize, usize)>,
    /// One-sided cross spectral density `P_ij` of each pair (scipy's
    /// `csd(x_i, x_j)`: `conj(X_i)·X_j`), in the order of `pairs`.
    pub cross: Vec<Vec<Complex<f64>>>,
    /// Number of segments averaged (over all blocks).
    pub n_segments: usize,
}

impl MultiSpectra {
    /// Magnitude-squared coherence `|P_ij|² / (P_ii · P_jj)` of pair
    /// `pair_index` (scipy's `coherence(x_i, x_j)`), with 0 where a PSD is 0
    /// (scipy: NaN). An out-of-range `pair_index` gives an empty vector.
    ///
    /// `|P_ij|²` is formed as `re² + im²` (no `hypot`), so values may differ
    /// from [`super::coherence`] in the last bit or two.
    pub fn coherence(&self, pair_index: usize) -> Vec<f64> {
        let Some((pxy, pxx, pyy)) = self.pair_parts(pair_index) else {
            return Vec::new();
        };
        pxy.iter()
            .zip(pxx.iter().zip(pyy))
            .map(|(pxy, (&pxx, &pyy))| {
                if pxx == 0.0 || pyy == 0.0 {
                    0.0
                } else {
                    pxy.norm_sqr() / pxx / pyy
                }
            })
            .collect()
    }

    /// H1 frequency-response estimate `P_ij / P_ii` from channel `i` to
    /// channel `j` of pair `pair_index`, with 0 where `P_ii` is 0. An
    /// out-of-range `pair_index` gives an empty vector.
    pub fn h1(&self, pair_index: usize) -> Vec<Complex<f64>> {
        let Some((pxy, pxx, _)) = self.pair_parts(pair_index) else {
            return Vec::new();
        };
        pxy.iter()
            .zip(pxx)
            .map(|(pxy, &pxx)| {
                if pxx == 0.0 {
                    Complex::new(0.0, 0.0)
                } else {
                    pxy / pxx
                }
            })
            .collect()
    }

    /// `(P_ij, P_ii, P_jj)` of a pair, if it exists.
    fn pair_parts(&self, pair_index: usize) -> Option<PairParts<'_>> {
        let &(i, j) = self.pairs.get(pair_index)?;
        Some((
            self.cross.get(pair_index)?,
            self.auto.get(i)?,
            self.auto.get(j)?,
        ))
    }
}

/// Welch auto- and cross-spectra of `channels` over the sample ranges
/// `blocks`, with one real FFT per channel and segment.
///
/// `channels` are equally long signals sampled at `cfg.fs`; `blocks` are the
/// ranges of valid samples (e.g. [`crate::timeseries::UniformRecord::valid`]);
/// samples outside them are never read, so they may hold NaN. `pairs` lists
/// the cross spectra wanted, `(i, j)` giving scipy's `csd(channels[i],
/// channels[j])`. Segments are placed within each block as scipy would place
/// them in that block alone; blocks shorter than `nperseg` contribute none.
/// All segments of all blocks are averaged with equal weight.
///
/// Cost: `n_segments × channels.len()` real FFTs of length `nperseg`, plus
/// `O(n_segments × (channels + pairs) × nperseg)` multiply-adds. One FFT plan
/// and a fixed set of buffers serve the whole call (nothing is allocated per
/// segment).
///
/// # Errors
/// [`SpectraError`] naming `fs`, `nperseg` or `noverlap` for an invalid
/// configuration, `nperseg` when no block is long enough for one segment,
/// `channels` when there is none, `channels[i]` when its length differs
/// from `channels[0]` or (as [`SpectraError::NonFinite`]) it holds a NaN or
/// infinite sample inside a block, `blocks[i]` for a range outside the
/// signals or reversed, `blocks` when there is no block, and `pairs[i]` for
/// a channel index out of range.
pub fn multi_welch(
    channels: &[&[f64]],
    blocks: &[Range<usize>],
    pairs: &[(usize, usize)],
    cfg: &WelchConfig,
) -> Result<MultiSpectra, SpectraError> {
    let n_segments = validate(channels, blocks, pairs, cfg)?;
    if cfg.detrend == Detrend::Constant {
        // The segments' sums flag their non-finite samples (see `compute`);
        // only the samples no segment reads are scanned here.
        let uncovered: Vec<Range<usize>> = blocks
            .iter()
            .map(|b| b.start + covered(cfg, b.len()).min(b.len())..b.end)
            .collect();
        require_finite(channels, &uncovered)?;
        let (acc, factors) = compute(channels, blocks, pairs, cfg, (n_segments, (1, 2)), true)?;
        Ok(acc.finish(pairs, &factors, cfg.frequencies(), n_segments))
    } else {
        require_finite(channels, blocks)?;
        let (acc, factors) = compute(channels, blocks, pairs, cfg, (n_segments, (1, 2)), false)?;
        Ok(acc.finish(pairs, &factors, cfg.frequencies(), n_segments))
    }
}

/// Samples at the start of a block of `len` that its segments read.
fn covered(cfg: &WelchConfig, len: usize) -> usize {
    match cfg.n_segments(len) {
        0 => 0,
        m => (m - 1) * cfg.step() + cfg.nperseg,
    }
}

/// [`multi_welch`] for channels the caller has already checked to be
/// finite inside the blocks (the quality report does so while computing
/// its statistics): skips that scan, one pass over every sample. A NaN
/// left in gives NaN spectra, never a panic. The cross spectra stay in the
/// accumulators as summed (no copy into complex vectors). A large
/// estimate's first part, on the calling thread, holds `share` of the
/// segments (a caller whose other thread starts with other work gives it
/// more than half); with `(1, 2)` the values are those of [`multi_welch`]
/// bit for bit, with another share they differ by rounding only.
pub(crate) fn multi_welch_finite(
    channels: &[&[f64]],
    blocks: &[Range<usize>],
    pairs: &[(usize, usize)],
    cfg: &WelchConfig,
    share: (usize, usize),
) -> Result<SummedSpectra, SpectraError> {
    let n_segments = validate(channels, blocks, pairs, cfg)?;
    let (acc, factors) = compute(channels, blocks, pairs, cfg, (n_segments, share), false)?;
    Ok(acc.finish_sums(&factors, cfg.frequencies(), n_segments))
}

/// The sums of the estimate on validated inputs, over `n_segments ≥ 1`
/// segments, and the density factors that scale them; with `check_finite`
/// (constant detrend only), a non-finite sample inside a segment is a
/// [`SpectraError::NonFinite`].
///
/// Large estimates are split at a batch boundary near the middle of the
/// segments: each half is summed on its own thread (see [`crate::par`])
/// and the two sums are then added. The split depends on the input sizes
/// only, so the result is the same with one core or two; it differs from
/// one running sum over all segments by rounding (≤ a few ulp of the sums).
fn compute(
    channels: &[&[f64]],
    blocks: &[Range<usize>],
    pairs: &[(usize, usize)],
    cfg: &WelchConfig,
    (n_segments, share): (usize, (usize, usize)),
    check_finite: bool,
) -> Result<(Accumulators, Vec<f64>), SpectraError> {
    // `SegmentFft` scales by its own segment count: give it a length that
    // holds exactly `n_segments` segments, nperseg + (n_segments − 1)·step.
    let step = cfg.step();
    let virtual_len = (n_segments - 1)
        .checked_mul(step)
        .and_then(|v| v.checked_add(cfg.nperseg))
        .ok_or_else(|| SpectraError::input("blocks", "too many segments"))?;
    // Constant detrend (the default) is done here: the engine removes each
    // segment's mean while windowing, reading every sample once (see
    // `SegmentFft::transform_centred`).
    let own_mean = cfg.detrend == Detrend::Constant;
    let engine_cfg = if own_mean {
        cfg.clone().with_detrend(Detrend::None)
    } else {
        cfg.clone()
    };
    let engine = SegmentFft::new(&engine_cfg, virtual_len);
    debug_assert_eq!(engine.n_segments(), n_segments);

    let work = n_segments
        .saturating_mul(channels.len())
        .saturating_mul(cfg.nperseg);
    let parts = parts(work);
    let cut = (parts >= 2).then(|| (n_segments * share.0 + share.1 / 2) / share.1);
    let batches = batches(blocks, cfg, cut);
    let nf = cfg.n_freqs();
    let mut acc = Accumulators::new(channels.len(), pairs, nf);
    let factors = engine.density_factors(cfg.fs);
    run_parts(
        &engine,
        &mut acc,
        &batches,
        parts,
        share,
        channels,
        cfg,
        own_mean,
        check_finite,
    )?;
    Ok((acc, factors))
}

/// True when every sample is finite: `v · 0` is 0 for a finite `v` and NaN
/// otherwise, and the (vectorised) partial sums carry a NaN through.
fn all_finite(x: &[f64]) -> bool {
    let mut acc = [0.0f64; 8];
    let chunks = x.chunks_exact(8);
    let tail: f64 = chunks.remainder().iter().map(|v| v * 0.0).sum();
    for ch in chunks {
        for (a, v) in acc.iter_mut().zip(ch) {
            *a += v * 0.0;
        }
    }
    acc.iter().sum::<f64>() + tail == 0.0
}

/// Checks the inputs (all but finiteness) and returns the total number of
/// segments (≥ 1).
fn validate(
    channels: &[&[f64]],
    blocks: &[Range<usize>],
    pairs: &[(usize, usize)],
    cfg: &WelchConfig,
) -> Result<usize, SpectraError> {
    // Parameters only: no signal is too short for `usize::MAX`.
    cfg.validate(usize::MAX)?;
    let Some(first) = channels.first() else {
        return Err(SpectraError::input("channels", "no channel given"));
    };
    let n = first.len();
    for (i, c) in channels.iter().enumerate() {
        if c.len() != n {
            return Err(SpectraError::input(
                &format!("channels[{i}]"),
                format!(
                    "length {} differs from the length {n} of channels[0]",
                    c.len()
                ),
            ));
        }
    }
    if blocks.is_empty() {
        return Err(SpectraError::input("blocks", "no block of valid samples"));
    }
    for (i, b) in blocks.iter().enumerate() {
        if b.start > b.end || b.end > n {
            return Err(SpectraError::input(
                &format!("blocks[{i}]"),
                format!(
                    "range {}..{} is not within the {n} samples of the channels",
                    b.start, b.end
                ),
            ));
        }
    }
    for (i, &(a, b)) in pairs.iter().enumerate() {
        if a >= channels.len() || b >= channels.len() {
            return Err(SpectraError::input(
                &format!("pairs[{i}]"),
                format!(
                    "channel index ({a}, {b}) out of range for {} channels",
                    channels.len()
                ),
            ));
        }
    }
    let total = blocks
        .iter()
        .fold(0usize, |t, b| t.saturating_add(cfg.n_segments(b.len())));
    if total == 0 {
        let longest = blocks.iter().map(|b| b.len()).max().unwrap_or(0);
        return Err(SpectraError::parameter(
            "nperseg",
            format!(
                "segment length {} exceeds every block of valid samples (longest {longest})",
                cfg.nperseg
            ),
        ));
    }
    Ok(total)
}

/// Checks that every sample inside the blocks is finite.
fn require_finite(channels: &[&[f64]], blocks: &[Range<usize>]) -> Result<(), SpectraError> {
    for (i, c) in channels.iter().enumerate() {
        require_finite_channel(i, c, blocks)?;
    }
    Ok(())
}

/// Checks that every sample of channel `i` inside the blocks is finite.
pub(super) fn require_finite_channel(
    i: usize,
    c: &[f64],
    blocks: &[Range<usize>],
) -> Result<(), SpectraError> {
    for b in blocks {
        if all_finite(&c[b.clone()]) {
            continue;
        }
        if let Some(k) = c[b.clone()].iter().position(|v| !v.is_finite()) {
            let index = b.start + k;
            let field = format!("channels[{i}]");
            return Err(SpectraError::NonFinite {
                message: format!("{field}[{index}] = {} is not finite", c[index]),
                field,
                index,
            });
        }
    }
    Ok(())
}

#[cfg(test)]
#[allow(clippy::single_range_in_vec_init)] // vectors of blocks
mod tests;
