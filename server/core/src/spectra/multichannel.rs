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

use super::accumulators::{Accumulators, PlaneSpectra};
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
/// accumulators' split planes (no copy into complex vectors). A large
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
) -> Result<PlaneSpectra, SpectraError> {
    let n_segments = validate(channels, blocks, pairs, cfg)?;
    let (acc, factors) = compute(channels, blocks, pairs, cfg, (n_segments, share), false)?;
    Ok(acc.finish_planes(&factors, cfg.frequencies(), n_segments))
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
        // Inside a segment of a later batch, in a block's tail that no
        // segment reads, and with the other detrends: still found.
        let long: Vec<f64> = (0..400).map(|i| (i as f64 * 0.37).sin()).collect();
        for (at, block_end) in [(0, 400), (130, 400), (391, 400), (399, 400)] {
            for bad_value in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                let mut y = long.clone();
                y[at] = bad_value;
                for detrend in [Detrend::Constant, Detrend::Linear, Detrend::None] {
                    let cfg = WelchConfig::hann(1.0, 16).with_detrend(detrend);
                    // 400 samples: 48 segments cover 0..392, 392..400 is a tail.
                    match multi_welch(&[&long, &y], &[0..block_end], &[(0, 1)], &cfg) {
                        Err(SpectraError::NonFinite { field, index, .. }) => {
                            assert_eq!((field.as_str(), index), ("channels[1]", at))
                        }
                        other => panic!("{at} {bad_value} {detrend:?}: {other:?}"),
                    }
                }
            }
        }
    }

    #[test]
    fn out_of_range_pair_index_gives_empty_vectors() {
        let x = vec![1.0; 64];
        let s = multi_welch(&[&x], &whole(64), &[(0, 0)], &WelchConfig::hann(1.0, 16)).unwrap();
        assert!(s.coherence(1).is_empty() && s.h1(7).is_empty());
        assert_eq!(s.coherence(0).len(), 9);
    }
}
