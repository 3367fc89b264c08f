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
//! [`super::welch`] / [`super::csd`] (same operations in the same order: bit
//! for bit, or to the rounding of fused multiply–adds on CPUs with AVX2 and
//! FMA), hence equal to scipy's to ~1e-12.

use std::ops::Range;

use realfft::num_complex::Complex;

use super::engine::SegmentFft;
use super::{Detrend, SpectraError, WelchConfig};
use crate::kernels::{has_avx2_fma, madd};

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
    require_finite(channels, blocks)?;
    compute(channels, blocks, pairs, cfg, n_segments)
}

/// [`multi_welch`] for channels the caller has already checked to be
/// finite inside the blocks (the quality report does so while computing
/// its statistics): skips that scan, one pass over every sample. A NaN
/// left in gives NaN spectra, never a panic.
pub(crate) fn multi_welch_finite(
    channels: &[&[f64]],
    blocks: &[Range<usize>],
    pairs: &[(usize, usize)],
    cfg: &WelchConfig,
) -> Result<MultiSpectra, SpectraError> {
    let n_segments = validate(channels, blocks, pairs, cfg)?;
    compute(channels, blocks, pairs, cfg, n_segments)
}

/// The estimate on validated inputs, over `n_segments ≥ 1` segments.
fn compute(
    channels: &[&[f64]],
    blocks: &[Range<usize>],
    pairs: &[(usize, usize)],
    cfg: &WelchConfig,
    n_segments: usize,
) -> Result<MultiSpectra, SpectraError> {
    // `SegmentFft` scales by its own segment count: give it a length that
    // holds exactly `n_segments` segments, nperseg + (n_segments − 1)·step.
    let step = cfg.step();
    let virtual_len = (n_segments - 1)
        .checked_mul(step)
        .and_then(|v| v.checked_add(cfg.nperseg))
        .ok_or_else(|| SpectraError::input("blocks", "too many segments"))?;
    // Constant detrend (the default) is done here with a vectorised mean,
    // the engine subtracts it while windowing; see `mean`.
    let own_mean = cfg.detrend == Detrend::Constant;
    let engine_cfg = if own_mean {
        cfg.clone().with_detrend(Detrend::None)
    } else {
        cfg.clone()
    };
    let mut engine = SegmentFft::new(&engine_cfg, virtual_len);
    debug_assert_eq!(engine.n_segments(), n_segments);

    let mut acc = Accumulators::new(channels.len(), pairs, cfg.n_freqs());
    let mut spec = engine.make_output();
    for block in blocks {
        for m in 0..cfg.n_segments(block.len()) {
            for (c, channel) in channels.iter().enumerate() {
                if own_mean {
                    let start = block.start + m * step;
                    let samples = &channel[start..start + cfg.nperseg];
                    engine.transform_offset(samples, mean(samples), &mut spec)?;
                } else {
                    engine.transform(&channel[block.clone()], m, &mut spec)?;
                }
                acc.add_channel(c, &spec);
            }
            acc.end_segment(pairs);
        }
    }
    acc.flush(pairs);
    let factors = engine.density_factors(cfg.fs);
    Ok(acc.finish(pairs, &factors, cfg.frequencies(), n_segments))
}

/// The mean of `x` (scipy's `detrend='constant'` removes it), summed with
/// eight partial sums so that it vectorises: the shared sequential
/// `detrend_in_place` costs about 40 % of a 4096-point FFT per segment.
/// Equal to that function's mean up to rounding.
fn mean(x: &[f64]) -> f64 {
    let mut acc = [0.0f64; 8];
    let chunks = x.chunks_exact(8);
    let tail: f64 = chunks.remainder().iter().sum();
    for ch in chunks {
        for (a, v) in acc.iter_mut().zip(ch) {
            *a += v;
        }
    }
    let sum = ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7]));
    (sum + tail) / x.len().max(1) as f64
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
    }
    Ok(())
}

/// Sums over segments. The spectra of the current segment (and the
/// previous one, until they are added) are kept split into real and
/// imaginary planes (`[slot][channel][bin]`, contiguous) so the per-pair
/// loops are plain element-wise multiply-adds that the compiler vectorises.
///
/// The cross accumulators (36 pairs × 2049 bins × 16 B = 1.2 MB) outgrow
/// a core's L2 cache, so reading and writing them is what bounds the
/// accumulation: segments are added two at a time, halving that traffic.
/// Every sum still runs over the segments in order (`(acc + s₁) + s₂`),
/// exactly as [`super::csd`] does. (Wider batches were slower: more
/// streams, larger buffers.)
struct Accumulators {
    nf: usize,
    n_channels: usize,
    /// Segments stored in `re`/`im` and not yet added to the pairs (0..=2).
    held: usize,
    re: Vec<f64>,
    im: Vec<f64>,
    auto: Vec<f64>,
    cross_re: Vec<f64>,
    cross_im: Vec<f64>,
}

impl Accumulators {
    fn new(n_channels: usize, pairs: &[(usize, usize)], nf: usize) -> Self {
        let slots = if pairs.is_empty() { 1 } else { 2 };
        Accumulators {
            nf,
            n_channels,
            held: 0,
            re: scratch::zeroed(slots * n_channels * nf),
            im: scratch::zeroed(slots * n_channels * nf),
            auto: scratch::zeroed(n_channels * nf),
            cross_re: scratch::zeroed(pairs.len() * nf),
            cross_im: scratch::zeroed(pairs.len() * nf),
        }
    }

    /// Stores channel `c`'s spectrum of the current segment and adds `|X|²`
    /// to its PSD.
    fn add_channel(&mut self, c: usize, spec: &[Complex<f64>]) {
        #[cfg(target_arch = "x86_64")]
        if has_avx2_fma() {
            // SAFETY: the CPU has the features the function is compiled for.
            return unsafe { self.add_channel_fma(c, spec) };
        }
        self.add_channel_body::<false>(c, spec)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn add_channel_fma(&mut self, c: usize, spec: &[Complex<f64>]) {
        self.add_channel_body::<true>(c, spec)
    }

    #[inline(always)]
    fn add_channel_body<const FMA: bool>(&mut self, c: usize, spec: &[Complex<f64>]) {
        let nf = self.nf;
        let off = (self.held * self.n_channels + c) * nf;
        let re = &mut self.re[off..off + nf];
        let im = &mut self.im[off..off + nf];
        let auto = &mut self.auto[c * nf..(c + 1) * nf];
        for (((s, r), i), a) in spec.iter().zip(re).zip(im).zip(auto) {
            *r = s.re;
            *i = s.im;
            // Without FMA the same expression as `Complex::norm_sqr`
            // (bit-identical to `welch`).
            *a += madd::<FMA>(s.re, s.re, s.im * s.im);
        }
    }

    /// Closes the current segment; adds the held pair of segments to the
    /// cross spectra once there are two.
    fn end_segment(&mut self, pairs: &[(usize, usize)]) {
        self.held += 1;
        if pairs.is_empty() {
            self.held = 0;
        } else if self.held == 2 {
            self.add_two(pairs);
            self.held = 0;
        }
    }

    /// Adds a last odd segment, if one is held.
    fn flush(&mut self, pairs: &[(usize, usize)]) {
        if self.held == 1 {
            self.add_one(pairs);
        }
        self.held = 0;
    }

    /// Channel `c`'s real and imaginary planes in slot `slot`.
    fn planes(&self, slot: usize, c: usize) -> (&[f64], &[f64]) {
        let off = (slot * self.n_channels + c) * self.nf;
        (&self.re[off..off + self.nf], &self.im[off..off + self.nf])
    }

    /// Adds `conj(X_i)·X_j` of the segment in slot 0 to every pair.
    fn add_one(&mut self, pairs: &[(usize, usize)]) {
        #[cfg(target_arch = "x86_64")]
        if has_avx2_fma() {
            // SAFETY: the CPU has the features the function is compiled for.
            return unsafe { self.add_one_fma(pairs) };
        }
        self.add_one_body::<false>(pairs)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn add_one_fma(&mut self, pairs: &[(usize, usize)]) {
        self.add_one_body::<true>(pairs)
    }

    #[inline(always)]
    fn add_one_body<const FMA: bool>(&mut self, pairs: &[(usize, usize)]) {
        let nf = self.nf;
        let mut cross_re = std::mem::take(&mut self.cross_re);
        let mut cross_im = std::mem::take(&mut self.cross_im);
        for (p, &(i, j)) in pairs.iter().enumerate() {
            let ((xr, xi), (yr, yi)) = (self.planes(0, i), self.planes(0, j));
            let acc_re = &mut cross_re[p * nf..(p + 1) * nf];
            let acc_im = &mut cross_im[p * nf..(p + 1) * nf];
            for k in 0..nf {
                // conj(x)·y; without FMA rounded as num_complex's `x.conj() * y`.
                acc_re[k] += madd::<FMA>(xr[k], yr[k], xi[k] * yi[k]);
                acc_im[k] += madd::<FMA>(xr[k], yi[k], -(xi[k] * yr[k]));
            }
        }
        self.cross_re = cross_re;
        self.cross_im = cross_im;
    }

    /// Adds `conj(X_i)·X_j` of the segments in slots 0 then 1 to every
    /// pair, in one pass over the accumulators.
    fn add_two(&mut self, pairs: &[(usize, usize)]) {
        #[cfg(target_arch = "x86_64")]
        if has_avx2_fma() {
            // SAFETY: the CPU has the features the function is compiled for.
            return unsafe { self.add_two_fma(pairs) };
        }
        self.add_two_body::<false>(pairs)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn add_two_fma(&mut self, pairs: &[(usize, usize)]) {
        self.add_two_body::<true>(pairs)
    }

    #[inline(always)]
    fn add_two_body<const FMA: bool>(&mut self, pairs: &[(usize, usize)]) {
        let nf = self.nf;
        let mut cross_re = std::mem::take(&mut self.cross_re);
        let mut cross_im = std::mem::take(&mut self.cross_im);
        for (p, &(i, j)) in pairs.iter().enumerate() {
            let ((xr, xi), (yr, yi)) = (self.planes(0, i), self.planes(0, j));
            let ((ur, ui), (vr, vi)) = (self.planes(1, i), self.planes(1, j));
            let acc_re = &mut cross_re[p * nf..(p + 1) * nf];
            let acc_im = &mut cross_im[p * nf..(p + 1) * nf];
            for k in 0..nf {
                let re = acc_re[k] + madd::<FMA>(xr[k], yr[k], xi[k] * yi[k]);
                acc_re[k] = re + madd::<FMA>(ur[k], vr[k], ui[k] * vi[k]);
                let im = acc_im[k] + madd::<FMA>(xr[k], yi[k], -(xi[k] * yr[k]));
                acc_im[k] = im + madd::<FMA>(ur[k], vi[k], -(ui[k] * vr[k]));
            }
        }
        self.cross_re = cross_re;
        self.cross_im = cross_im;
    }

    fn finish(
        self,
        pairs: &[(usize, usize)],
        factors: &[f64],
        freqs: Vec<f64>,
        n_segments: usize,
    ) -> MultiSpectra {
        let nf = self.nf;
        let auto = self
            .auto
            .chunks_exact(nf.max(1))
            .map(|c| c.iter().zip(factors).map(|(v, f)| v * f).collect())
            .collect();
        let cross = self
            .cross_re
            .chunks_exact(nf.max(1))
            .zip(self.cross_im.chunks_exact(nf.max(1)))
            .map(|(r, i)| {
                r.iter()
                    .zip(i)
                    .zip(factors)
                    .map(|((r, i), f)| Complex::new(r * f, i * f))
                    .collect()
            })
            .collect();
        for buffer in [self.re, self.im, self.auto, self.cross_re, self.cross_im] {
            scratch::give_back(buffer);
        }
        MultiSpectra {
            freqs,
            auto,
            pairs: pairs.to_vec(),
            cross,
            n_segments,
        }
    }
}

#[cfg(test)]
#[allow(clippy::single_range_in_vec_init)] // vectors of blocks
mod tests {
    use super::super::test_support::{Gaussian, assert_rel_close, cross_fixture, welch_fixture};
    use super::super::{coherence, cross_spectra, csd, welch};
    use super::*;

    fn whole(n: usize) -> Vec<Range<usize>> {
        vec![0..n]
    }

    #[test]
    fn one_block_matches_scipy_cross_fixtures() {
        let fx = cross_fixture();
        for case in &fx.cases {
            let name = &case.params.name;
            let (x, y) = (&fx.signals[&case.x], &fx.signals[&case.y]);
            let cfg = case.params.config();
            let s = multi_welch(&[x, y], &whole(x.len()), &[(0, 1), (1, 0)], &cfg).unwrap();
            assert_eq!(s.n_segments, cfg.n_segments(x.len()));
            assert_rel_close(&s.freqs, &case.freqs, 1e-12, &format!("{name} freqs"));
            assert_rel_close(&s.auto[0], &case.pxx, 1e-12, &format!("{name} pxx"));
            assert_rel_close(&s.auto[1], &case.pyy, 1e-12, &format!("{name} pyy"));
            let scale = case
                .pxy_re
                .iter()
                .zip(&case.pxy_im)
                .fold(0.0f64, |m, (r, i)| m.max(r.hypot(*i)));
            for (k, p) in s.cross[0].iter().enumerate() {
                let err = (p - Complex::new(case.pxy_re[k], case.pxy_im[k])).norm();
                assert!(err <= 1e-12 * scale, "{name} pxy[{k}]: err {err:e}");
                // The reversed pair is the conjugate (to the rounding of the
                // fused multiply–adds on CPUs that have them).
                let mirror = (s.cross[1][k] - p.conj()).norm();
                assert!(mirror <= 1e-15 * scale, "{name} pyx[{k}]: {mirror:e}");
            }
            assert_rel_close(
                &s.coherence(0),
                &case.coherence,
                1e-12,
                &format!("{name} coherence"),
            );
            let h1 = s.h1(0);
            let hscale = h1.iter().fold(0.0f64, |m, h| m.max(h.norm()));
            for (k, h) in h1.iter().enumerate() {
                let err = (h - Complex::new(case.h1_re[k], case.h1_im[k])).norm();
                assert!(err <= 1e-12 * hscale, "{name} h1[{k}]: err {err:e}");
            }
        }
    }

    #[test]
    fn one_block_matches_scipy_welch_fixtures() {
        let fx = welch_fixture();
        for case in &fx.cases {
            let x = &fx.signals[&case.x];
            let cfg = case.params.config();
            let s = multi_welch(&[x], &whole(x.len()), &[], &cfg).unwrap();
            assert_rel_close(&s.auto[0], &case.pxx, 1e-12, &case.params.name);
            assert!(s.cross.is_empty());
        }
    }

    /// Asserts `|a − e| ≤ tol · max|e|` for complex vectors.
    fn assert_complex_close(a: &[Complex<f64>], e: &[Complex<f64>], tol: f64, what: &str) {
        assert_eq!(a.len(), e.len(), "{what}");
        let scale = e.iter().fold(0.0f64, |m, v| m.max(v.norm()));
        for (k, (x, y)) in a.iter().zip(e).enumerate() {
            assert!((x - y).norm() <= tol * scale, "{what}[{k}]: {x} vs {y}");
        }
    }

    #[test]
    fn one_block_matches_single_channel_functions() {
        // Linear and no detrend go through the shared engine unchanged: bit
        // for bit without fused multiply–adds. Constant detrend uses the
        // vectorised mean: equal to the rounding of the mean.
        let mut g = Gaussian::new(31);
        let n = 5000;
        let chans: Vec<Vec<f64>> = (0..4)
            .map(|c| {
                (0..n)
                    .map(|i| g.sample() + (c as f64) * 3.0 + 0.001 * i as f64)
                    .collect()
            })
            .collect();
        let refs: Vec<&[f64]> = chans.iter().map(Vec::as_slice).collect();
        let pairs = [(0, 1), (0, 3), (2, 1), (3, 3)];
        for cfg in [
            WelchConfig::hann(10.0, 256),
            WelchConfig::hann(2.0, 333).with_detrend(Detrend::Linear),
            WelchConfig::hann(1.0, 100)
                .with_noverlap(0)
                .with_detrend(Detrend::None),
        ] {
            let exact = cfg.detrend != Detrend::Constant && !crate::kernels::has_avx2_fma();
            let s = multi_welch(&refs, &whole(n), &pairs, &cfg).unwrap();
            for (c, x) in refs.iter().enumerate() {
                let w = welch(x, &cfg).unwrap().values;
                if exact {
                    assert_eq!(s.auto[c], w);
                } else {
                    assert_rel_close(&s.auto[c], &w, 1e-13, "auto");
                }
            }
            for (p, &(i, j)) in pairs.iter().enumerate() {
                let cs = cross_spectra(refs[i], refs[j], &cfg).unwrap();
                let c = csd(refs[i], refs[j], &cfg).unwrap().values;
                if exact {
                    assert_eq!(s.cross[p], c);
                    assert_eq!(s.h1(p), cs.h1().values);
                } else {
                    assert_complex_close(&s.cross[p], &c, 1e-13, "csd");
                    assert_complex_close(&s.h1(p), &cs.h1().values, 1e-12, "h1");
                }
                assert_rel_close(
                    &s.coherence(p),
                    &coherence(refs[i], refs[j], &cfg).unwrap().values,
                    1e-12,
                    "coherence",
                );
            }
            assert_eq!(s.freqs, cfg.frequencies());
        }
    }

    #[test]
    fn kernels_match_their_plain_versions() {
        let x: Vec<f64> = (0..37).map(|i| 1e6 + (i as f64 * 0.7).sin()).collect();
        let plain = x.iter().sum::<f64>() / 37.0;
        assert!((mean(&x) - plain).abs() < 1e-9);
        assert_eq!(mean(&[]), 0.0);
        assert!(all_finite(&x) && all_finite(&[]));
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            for at in [0, 7, 8, 36] {
                let mut y = x.clone();
                y[at] = bad;
                assert!(!all_finite(&y), "{bad} at {at}");
            }
        }
    }

    #[test]
    fn blocks_average_segments_as_scipy_per_block() {
        // Two blocks separated by a gap of NaNs: the result is the
        // segment-weighted mean of scipy's estimate on each block alone.
        let mut g = Gaussian::new(5);
        let n = 3000;
        let mut x = g.vec(n, 1.0);
        let mut y: Vec<f64> = x.iter().map(|v| 0.5 * v + 0.2 * g.sample()).collect();
        for i in 1100..1400 {
            x[i] = f64::NAN;
            y[i] = f64::INFINITY;
        }
        let blocks = vec![0..1100, 1400..2999, 2999..3000];
        let cfg = WelchConfig::hann(4.0, 128).with_detrend(Detrend::Linear);
        let s = multi_welch(&[&x, &y], &blocks, &[(0, 1)], &cfg).unwrap();
        let (a, b) = (&blocks[0], &blocks[1]);
        let (na, nb) = (cfg.n_segments(a.len()), cfg.n_segments(b.len()));
        assert_eq!(s.n_segments, na + nb);
        let ca = cross_spectra(&x[a.clone()], &y[a.clone()], &cfg).unwrap();
        let cb = cross_spectra(&x[b.clone()], &y[b.clone()], &cfg).unwrap();
        let w = |p: f64, q: f64| (na as f64 * p + nb as f64 * q) / (na + nb) as f64;
        let pxx: Vec<f64> = ca.pxx.iter().zip(&cb.pxx).map(|(p, q)| w(*p, *q)).collect();
        let pyy: Vec<f64> = ca.pyy.iter().zip(&cb.pyy).map(|(p, q)| w(*p, *q)).collect();
        assert_rel_close(&s.auto[0], &pxx, 1e-12, "pxx");
        assert_rel_close(&s.auto[1], &pyy, 1e-12, "pyy");
        let scale = s.cross[0].iter().fold(0.0f64, |m, p| m.max(p.norm()));
        for k in 0..pxx.len() {
            let e = Complex::new(w(ca.pxy[k].re, cb.pxy[k].re), w(ca.pxy[k].im, cb.pxy[k].im));
            assert!((s.cross[0][k] - e).norm() <= 1e-12 * scale, "bin {k}");
        }
    }

    #[test]
    fn errors_name_the_offending_input() {
        let x = vec![0.5; 100];
        let y = vec![0.5; 99];
        let cfg = WelchConfig::hann(1.0, 16);
        let field = |r: Result<MultiSpectra, SpectraError>| r.unwrap_err().field().to_owned();
        assert_eq!(field(multi_welch(&[], &whole(100), &[], &cfg)), "channels");
        assert_eq!(
            field(multi_welch(&[&x, &y], &whole(100), &[], &cfg)),
            "channels[1]"
        );
        assert_eq!(field(multi_welch(&[&x], &[], &[], &cfg)), "blocks");
        assert_eq!(
            field(multi_welch(&[&x], &[0..10, 50..101], &[], &cfg)),
            "blocks[1]"
        );
        #[allow(clippy::reversed_empty_ranges)]
        let reversed = [20..10];
        assert_eq!(field(multi_welch(&[&x], &reversed, &[], &cfg)), "blocks[0]");
        assert_eq!(
            field(multi_welch(&[&x], &whole(100), &[(0, 0), (0, 1)], &cfg)),
            "pairs[1]"
        );
        assert_eq!(
            field(multi_welch(&[&x], &[0..15, 20..35], &[], &cfg)),
            "nperseg"
        );
        assert_eq!(
            field(multi_welch(
                &[&x],
                &whole(100),
                &[],
                &WelchConfig::hann(0.0, 16)
            )),
            "fs"
        );
        assert_eq!(
            field(multi_welch(
                &[&x],
                &whole(100),
                &[],
                &WelchConfig::hann(1.0, 16).with_noverlap(16)
            )),
            "noverlap"
        );
        let mut bad = x.clone();
        bad[42] = f64::NAN;
        match multi_welch(&[&x, &bad], &[0..40, 41..100], &[], &cfg).unwrap_err() {
            SpectraError::NonFinite { field, index, .. } => {
                assert_eq!((field.as_str(), index), ("channels[1]", 42))
            }
            e => panic!("{e:?}"),
        }
        // Outside the blocks a NaN is never read.
        assert!(multi_welch(&[&x, &bad], &[0..40, 43..100], &[(0, 1)], &cfg).is_ok());
    }

    #[test]
    fn out_of_range_pair_index_gives_empty_vectors() {
        let x = vec![1.0; 64];
        let s = multi_welch(&[&x], &whole(64), &[(0, 0)], &WelchConfig::hann(1.0, 16)).unwrap();
        assert!(s.coherence(1).is_empty() && s.h1(7).is_empty());
        assert_eq!(s.coherence(0).len(), 9);
    }
}

/// Accumulator buffers kept per thread between calls. A report's spectra
/// need about 2 MB of zeroed sums; allocated afresh, each call would fault
/// those pages in from the kernel again (a third of the time of a 1-hour
/// report), reused they are only zeroed.
mod scratch {
    use std::cell::RefCell;

    /// Buffers kept per thread.
    const KEPT: usize = 8;

    thread_local! {
        static FREE: RefCell<Vec<Vec<f64>>> = const { RefCell::new(Vec::new()) };
    }

    /// A zeroed buffer of `len` values, reusing a kept one when there is.
    pub(super) fn zeroed(len: usize) -> Vec<f64> {
        let kept = FREE.with(|f| {
            let mut f = f.borrow_mut();
            // The smallest kept buffer that holds `len`, else the largest.
            let best = f
                .iter()
                .enumerate()
                .filter(|(_, v)| v.capacity() >= len)
                .min_by_key(|(_, v)| v.capacity())
                .or_else(|| f.iter().enumerate().max_by_key(|(_, v)| v.capacity()))
                .map(|(i, _)| i);
            best.map(|i| f.swap_remove(i))
        });
        match kept {
            Some(mut v) => {
                v.clear();
                v.resize(len, 0.0);
                v
            }
            None => vec![0.0; len],
        }
    }

    /// Keeps `buffer` for the next call on this thread.
    pub(super) fn give_back(buffer: Vec<f64>) {
        FREE.with(|f| {
            let mut f = f.borrow_mut();
            if f.len() < KEPT {
                f.push(buffer);
            }
        });
    }
}
