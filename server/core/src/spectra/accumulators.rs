//! The sums of a multichannel Welch estimate: `Σ |X_c|²` per channel and
//! `Σ conj(X_i)·X_j` per requested pair, over segments.
//!
//! The FFT writes each segment's spectrum straight into a slot held here
//! (up to [`BATCH`] segments of every channel), and its PSD term is added
//! at once, while the spectrum is still in L1. The held segments are then
//! added to every pair's cross sum in one pass over bins in blocks of
//! [`BIN_BLOCK`]: a block of every channel's held spectra (~100 KB for a
//! 6 × 6 report) stays in L2 while the pairs read it, and each pair's sums
//! are read and written once per batch (the 36 sums of a 6 × 6 report at
//! `nperseg = 4096` take 1.2 MB, more than a core's L2). The first batch
//! stores its sums rather than adding them to zeros. Every sum runs over
//! the segments in order.

use realfft::num_complex::Complex;

#[cfg(target_arch = "x86_64")]
use super::cross_kernel::{GROUP, Held, cross_run};
use super::multichannel::MultiSpectra;
use crate::kernels::{has_avx2_fma, madd};

/// Segments whose spectra are held before they are added to the cross
/// spectra: each pass over the cross sums is paid by this many segments.
pub(super) const BATCH: usize = 4;

/// Bins per block of the cross-sum pass (even: a block's bins go in pairs
/// of two complex values per 4-lane register).
const BIN_BLOCK: usize = 128;

/// See the [module documentation](self).
pub(super) struct Accumulators {
    nf: usize,
    /// Held spectra, `[channel][slot][bin]`: channel c, slot s at
    /// `(c·BATCH + s)·nf`. Without pairs, one spectrum reused by every
    /// channel and segment.
    slots: Vec<Complex<f64>>,
    auto: Vec<f64>,
    /// Cross sums, `[pair][bin][re, im]`; unspecified until the first
    /// batch stores them (`summed`).
    cross: Vec<f64>,
    summed: bool,
    /// Absorbed parts' cross sums, still to be added (see `absorb`).
    held: Vec<Vec<f64>>,
    pairs: Vec<(usize, usize)>,
}

impl Accumulators {
    /// Zeroed sums for `n_channels` spectra of `nf` bins and `pairs`.
    pub(super) fn new(n_channels: usize, pairs: &[(usize, usize)], nf: usize) -> Self {
        let mut acc = Self::unzeroed(n_channels, pairs, nf);
        acc.zero();
        acc
    }

    /// [`Accumulators::new`] with its sums not yet zeroed: call
    /// [`Accumulators::zero`] before adding. The buffers come from the
    /// calling thread's kept ones; the zeroing can run on the thread that
    /// adds.
    pub(super) fn unzeroed(n_channels: usize, pairs: &[(usize, usize)], nf: usize) -> Self {
        let held_spectra = if pairs.is_empty() {
            nf
        } else {
            n_channels * BATCH * nf
        };
        Accumulators {
            nf,
            // Every held value is written (by the FFT) before it is read.
            slots: scratch::reused_complex(held_spectra),
            auto: scratch::reused(n_channels * nf),
            cross: scratch::reused(pairs.len() * 2 * nf),
            summed: false,
            held: Vec::new(),
            pairs: pairs.to_vec(),
        }
    }

    /// Unzeroed sums of the same shape (see [`Self::unzeroed`]).
    pub(super) fn sibling(&self) -> Self {
        let n_channels = self.auto.len() / self.nf.max(1);
        Self::unzeroed(n_channels, &self.pairs, self.nf)
    }

    /// Sets every sum to zero (the cross sums by storing the first batch).
    pub(super) fn zero(&mut self) {
        self.auto.fill(0.0);
        self.summed = false;
    }

    /// The slot for channel `c`'s spectrum of the batch's `slot`-th segment
    /// (`slot < BATCH`): written by the FFT, then [`Self::add_channel`].
    pub(super) fn slot_mut(&mut self, slot: usize, c: usize) -> &mut [Complex<f64>] {
        let off = self.slot_offset(slot, c);
        &mut self.slots[off..off + self.nf]
    }

    /// Where channel `c`'s spectrum in `slot` starts in `slots`.
    fn slot_offset(&self, slot: usize, c: usize) -> usize {
        if self.pairs.is_empty() {
            0
        } else {
            (c * BATCH + slot) * self.nf
        }
    }

    /// Adds `|X|²` of the spectrum in channel `c`'s `slot` to its PSD.
    pub(super) fn add_channel(&mut self, slot: usize, c: usize) {
        #[cfg(target_arch = "x86_64")]
        if has_avx2_fma() {
            // SAFETY: the CPU has the features the function is compiled for.
            return unsafe { self.add_channel_fma(slot, c) };
        }
        self.add_channel_body::<false>(slot, c)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn add_channel_fma(&mut self, slot: usize, c: usize) {
        self.add_channel_body::<true>(slot, c)
    }

    #[inline(always)]
    fn add_channel_body<const FMA: bool>(&mut self, slot: usize, c: usize) {
        let nf = self.nf;
        let off = self.slot_offset(slot, c);
        let spec = &self.slots[off..off + nf];
        let auto = &mut self.auto[c * nf..(c + 1) * nf];
        for (s, a) in spec.iter().zip(auto) {
            // Without FMA the same expression as `Complex::norm_sqr`
            // (bit-identical to `welch`).
            *a += madd::<FMA>(s.re, s.re, s.im * s.im);
        }
    }

    /// Adds the cross products of the segments held in slots `0..count`
    /// (in slot order) to every pair.
    pub(super) fn add_segments(&mut self, count: usize) {
        if self.pairs.is_empty() || count == 0 {
            return;
        }
        match count {
            1 => self.add::<1>(),
            2 => self.add::<2>(),
            3 => self.add::<3>(),
            _ => self.add::<BATCH>(),
        }
        self.summed = true;
    }

    fn add<const S: usize>(&mut self) {
        #[cfg(target_arch = "x86_64")]
        if has_avx2_fma() {
            // SAFETY: the CPU has the features the function is compiled for.
            return unsafe { self.add_avx2::<S>() };
        }
        self.add_body::<S>()
    }

    /// [`Self::add`] in plain arithmetic: the sums in the order of
    /// `csd`'s (bit-identical to one running sum over the segments).
    fn add_body<const S: usize>(&mut self) {
        let nf = self.nf;
        let slots = &self.slots[..];
        let store = !self.summed;
        let spec = |c: usize, s: usize| &slots[(c * BATCH + s) * nf..(c * BATCH + s + 1) * nf];
        for (sums, &(i, j)) in self.cross.chunks_exact_mut(2 * nf).zip(&self.pairs) {
            let x: [_; S] = std::array::from_fn(|s| spec(i, s));
            let y: [_; S] = std::array::from_fn(|s| spec(j, s));
            for (k, acc) in sums.chunks_exact_mut(2).enumerate() {
                let (mut re, mut im) = if store { (0.0, 0.0) } else { (acc[0], acc[1]) };
                for s in 0..S {
                    let (a, b) = (x[s][k], y[s][k]);
                    re += a.re * b.re + a.im * b.im;
                    im += a.re * b.im + -(a.im * b.re);
                }
                acc[0] = re;
                acc[1] = im;
            }
        }
    }

    /// [`Self::add`] in 4-lane registers, two bins per register as the FFT
    /// leaves them (re, im, re, im), for runs of up to [`GROUP`]
    /// consecutive pairs that share their first channel x (a 6 × 6
    /// report's pairs are input-major): x is loaded once for the run, and
    /// per pair `p = Σ_s x ⊙ y` and `q = Σ_s (−x_im, x_re) ⊙ y` over the
    /// segments, then `hadd(p, q) = (Re conj(x)y, Im conj(x)y)` of both
    /// bins is added to the sums. Bins in blocks of [`BIN_BLOCK`] (see the
    /// module documentation).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn add_avx2<const S: usize>(&mut self) {
        let nf = self.nf;
        let store = !self.summed;
        let pairs_len = nf / 2 * 2;
        let mut runs: Vec<(usize, usize)> = Vec::new();
        for (p, &(i, _)) in self.pairs.iter().enumerate() {
            match runs.last_mut() {
                Some((first, len)) if *len < GROUP && self.pairs[*first].0 == i => *len += 1,
                _ => runs.push((p, 1)),
            }
        }
        let held = Held {
            slots: &self.slots,
            nf,
            even: pairs_len,
        };
        for b0 in (0..pairs_len).step_by(BIN_BLOCK) {
            let bins = b0..(b0 + BIN_BLOCK).min(pairs_len);
            for &(first, len) in &runs {
                let sums = &mut self.cross[first * 2 * nf..(first + len) * 2 * nf];
                let pairs = &self.pairs[first..first + len];
                let i = pairs[0].0;
                let j = |g: usize| pairs[g.min(len - 1)].1;
                let bins = bins.clone();
                match len {
                    1 => cross_run::<S, 1>(&held, i, [j(0)], sums, bins, store),
                    2 => cross_run::<S, 2>(&held, i, [j(0), j(1)], sums, bins, store),
                    3 => cross_run::<S, 3>(&held, i, [j(0), j(1), j(2)], sums, bins, store),
                    _ => cross_run::<S, 4>(&held, i, [j(0), j(1), j(2), j(3)], sums, bins, store),
                }
            }
        }
        let spec = |c: usize, s: usize| held.spec(c, s);
        if pairs_len < nf {
            // The last bin of an odd count, in plain arithmetic.
            let k = nf - 1;
            for (sums, &(i, j)) in self.cross.chunks_exact_mut(2 * nf).zip(&self.pairs) {
                let (mut re, mut im) = if store {
                    (0.0, 0.0)
                } else {
                    (sums[2 * k], sums[2 * k + 1])
                };
                for s in 0..S {
                    let (a, b) = (spec(i, s)[k], spec(j, s)[k]);
                    re = a.im.mul_add(b.im, a.re.mul_add(b.re, re));
                    im = (-a.im).mul_add(b.re, a.re.mul_add(b.im, im));
                }
                sums[2 * k] = re;
                sums[2 * k + 1] = im;
            }
        }
    }

    /// The cross sums, zeros when no batch was added.
    fn cross_sums(&mut self) -> &mut Vec<f64> {
        if !self.summed {
            self.cross.fill(0.0);
            self.summed = true;
        }
        &mut self.cross
    }

    /// Adds the sums of `other` (same channels, pairs and bins) to these,
    /// and keeps its buffers for the next call on this thread. The PSD
    /// sums are added at once; `other`'s cross sums (with what it absorbed
    /// added to them) are held apart and added where they are read
    /// ([`SummedSpectra::pair_sums`], [`Accumulators::finish`]): the pairs'
    /// own pass then does it on every thread, not one pass on one thread.
    pub(super) fn absorb(&mut self, mut other: Accumulators) {
        for (a, b) in self.auto.iter_mut().zip(&other.auto) {
            *a += b;
        }
        other.fold_held();
        other.cross_sums();
        self.held.push(std::mem::take(&mut other.cross));
        scratch::give_back(std::mem::take(&mut other.auto));
        scratch::give_back_complex(std::mem::take(&mut other.slots));
    }

    /// Adds the held cross sums to the cross sums, in the order they were
    /// absorbed.
    fn fold_held(&mut self) {
        let held = std::mem::take(&mut self.held);
        if held.is_empty() {
            return;
        }
        let cross = self.cross_sums();
        for held in held {
            par_zip(cross, &held, PARALLEL_VALUES / 2, |a, b| {
                for (a, b) in a.iter_mut().zip(b) {
                    *a += b;
                }
            });
            scratch::give_back(held);
        }
    }

    /// The auto spectra: each channel's sums times the density `factors`.
    fn scaled_auto(&self, factors: &[f64]) -> Vec<Vec<f64>> {
        self.auto
            .chunks_exact(self.nf.max(1))
            .map(|c| c.iter().zip(factors).map(|(v, f)| v * f).collect())
            .collect()
    }

    /// [`Accumulators::finish`] with the cross sums left as they were
    /// summed, with the parts they are still to be added to and the
    /// density factors: see [`SummedSpectra::pair_sums`].
    pub(super) fn finish_sums(
        mut self,
        factors: &[f64],
        freqs: Vec<f64>,
        n_segments: usize,
    ) -> SummedSpectra {
        let auto = self.scaled_auto(factors);
        self.cross_sums();
        scratch::give_back(std::mem::take(&mut self.auto));
        scratch::give_back_complex(std::mem::take(&mut self.slots));
        SummedSpectra {
            freqs,
            auto,
            n_segments,
            cross: std::mem::take(&mut self.cross),
            held: std::mem::take(&mut self.held),
            factors: factors.to_vec(),
            nf: self.nf,
        }
    }

    /// The spectra: sums times the density `factors`.
    pub(super) fn finish(
        mut self,
        pairs: &[(usize, usize)],
        factors: &[f64],
        freqs: Vec<f64>,
        n_segments: usize,
    ) -> MultiSpectra {
        self.fold_held();
        let nf = self.nf;
        let auto = self.scaled_auto(factors);
        let cross = self
            .cross_sums()
            .chunks_exact(2 * nf.max(1))
            .map(|sums| {
                sums.chunks_exact(2)
                    .zip(factors)
                    .map(|(c, f)| Complex::new(c[0] * f, c[1] * f))
                    .collect()
            })
            .collect();
        scratch::give_back(std::mem::take(&mut self.auto));
        scratch::give_back(std::mem::take(&mut self.cross));
        scratch::give_back_complex(std::mem::take(&mut self.slots));
        MultiSpectra {
            freqs,
            auto,
            pairs: pairs.to_vec(),
            cross,
            n_segments,
        }
    }
}

/// Values from which a pass adding two parts' cross sums is spread over
/// the pool, in tasks of about this many: a 6 × 6 report's 1.2 MB of sums
/// take ~0.06 ms per pass on one core.
const PARALLEL_VALUES: usize = 1 << 16;

/// `f(a_chunk, b_chunk)` over matching chunks of `chunk` values of `a` and
/// `b`, on the pool when there are at least two chunks.
fn par_zip(a: &mut [f64], b: &[f64], chunk: usize, f: impl Fn(&mut [f64], &[f64]) + Sync) {
    if a.len() < 2 * chunk {
        return f(a, b);
    }
    use rayon::prelude::*;
    a.par_chunks_mut(chunk)
        .zip(b.par_chunks(chunk))
        .for_each(|(a, b)| f(a, b));
}

/// Welch spectra of several channels with the cross spectra left as
/// summed, as the quality report reads them: [`MultiSpectra`] without its
/// complex vectors. The sums' buffers are kept for the next call on the
/// thread that drops them.
pub(crate) struct SummedSpectra {
    /// Frequencies in Hz.
    pub freqs: Vec<f64>,
    /// One-sided PSD of each channel.
    pub auto: Vec<Vec<f64>>,
    /// Segments averaged.
    pub n_segments: usize,
    /// Cross sums, `[pair][bin][re, im]`, and the other parts' sums of the
    /// same shape, to be added in order, then scaled by `factors`.
    cross: Vec<f64>,
    held: Vec<Vec<f64>>,
    factors: Vec<f64>,
    nf: usize,
}

impl SummedSpectra {
    /// The sums of the `p`-th requested pair, `[bin][re, im]`: this part's
    /// first, then the held parts' (empty when out of range), and the
    /// density factors per bin. `P_ij = (Σ parts in order) · factor`, see
    /// [`cross_from_parts`].
    pub(crate) fn pair_sums(&self, p: usize) -> (Vec<&[f64]>, &[f64]) {
        let span = p * 2 * self.nf..(p + 1) * 2 * self.nf;
        let parts = std::iter::once(&self.cross)
            .chain(&self.held)
            .filter_map(|c| c.get(span.clone()))
            .collect();
        (parts, &self.factors)
    }

    /// `(Re P_ij, Im P_ij)` of the `p`-th requested pair into `re` and
    /// `im` (resized to the bins; emptied when out of range): the parts'
    /// sums added in order, times the density factor, the values
    /// [`Accumulators::finish`] gives.
    #[cfg(test)]
    pub(crate) fn cross_into(&self, p: usize, re: &mut Vec<f64>, im: &mut Vec<f64>) {
        let (parts, factors) = self.pair_sums(p);
        cross_from_parts(&parts, factors, re, im);
    }
}

/// `re, im` = (Σ `parts` in order) · `factors`, each part `[bin][re, im]`.
#[inline(always)]
pub(crate) fn cross_from_parts(
    parts: &[&[f64]],
    factors: &[f64],
    re: &mut Vec<f64>,
    im: &mut Vec<f64>,
) {
    re.clear();
    im.clear();
    let Some((first, rest)) = parts.split_first() else {
        return;
    };
    re.extend(first.chunks_exact(2).map(|c| c[0]));
    im.extend(first.chunks_exact(2).map(|c| c[1]));
    for part in rest {
        for ((r, i), c) in re.iter_mut().zip(im.iter_mut()).zip(part.chunks_exact(2)) {
            *r += c[0];
            *i += c[1];
        }
    }
    for ((r, i), f) in re.iter_mut().zip(im.iter_mut()).zip(factors) {
        *r *= f;
        *i *= f;
    }
}

impl Drop for SummedSpectra {
    fn drop(&mut self) {
        scratch::give_back(std::mem::take(&mut self.cross));
        for held in std::mem::take(&mut self.held) {
            scratch::give_back(held);
        }
    }
}

/// Accumulator buffers kept per thread between calls. A report's spectra
/// need about 3 MB of buffers; allocated afresh, each call would fault
/// those pages in from the kernel again (a third of the time of a 1-hour
/// report).
mod scratch {
    use std::cell::RefCell;

    use realfft::num_complex::Complex;

    /// Buffers kept per thread, of each kind.
    const KEPT: usize = 8;

    thread_local! {
        static FREE: RefCell<Vec<Vec<f64>>> = const { RefCell::new(Vec::new()) };
        static FREE_COMPLEX: RefCell<Vec<Vec<Complex<f64>>>> = const { RefCell::new(Vec::new()) };
    }

    /// A buffer of `len` values from `free`, reusing a kept one when there
    /// is (the smallest that holds `len`, else the largest), with
    /// unspecified (finite or not) contents: for values written before
    /// they are read.
    fn take<T: Copy + Default>(free: &mut Vec<Vec<T>>, len: usize) -> Vec<T> {
        let best = free
            .iter()
            .enumerate()
            .filter(|(_, v)| v.capacity() >= len)
            .min_by_key(|(_, v)| v.capacity())
            .or_else(|| free.iter().enumerate().max_by_key(|(_, v)| v.capacity()))
            .map(|(i, _)| i);
        match best.map(|i| free.swap_remove(i)) {
            Some(mut v) => {
                v.truncate(len);
                v.resize(len, T::default());
                v
            }
            None => vec![T::default(); len],
        }
    }

    fn keep<T>(free: &mut Vec<Vec<T>>, buffer: Vec<T>) {
        if free.len() < KEPT && buffer.capacity() > 0 {
            free.push(buffer);
        }
    }

    /// A buffer of `len` values (see `take`).
    pub(super) fn reused(len: usize) -> Vec<f64> {
        FREE.with(|f| take(&mut f.borrow_mut(), len))
    }

    /// A buffer of `len` complex values (see `take`).
    pub(super) fn reused_complex(len: usize) -> Vec<Complex<f64>> {
        FREE_COMPLEX.with(|f| take(&mut f.borrow_mut(), len))
    }

    /// Keeps `buffer` for the next call on this thread.
    pub(super) fn give_back(buffer: Vec<f64>) {
        FREE.with(|f| keep(&mut f.borrow_mut(), buffer));
    }

    /// Keeps `buffer` for the next call on this thread.
    pub(super) fn give_back_complex(buffer: Vec<Complex<f64>>) {
        FREE_COMPLEX.with(|f| keep(&mut f.borrow_mut(), buffer));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;

    /// The cross sums are Σ conj(X_i)·X_j over the held segments of every
    /// batch (the first stored, the next added), and the auto sums
    /// Σ |X_c|²: at an odd and an even bin count, over more than one bin
    /// block.
    #[test]
    fn sums_are_the_products_of_the_held_spectra() {
        let mut rng = SplitMix64::new(4);
        for nf in [13, 2 * BIN_BLOCK + 6, 2 * BIN_BLOCK + 7] {
            let pairs = [(0, 1), (1, 0), (1, 1)];
            let mut acc = Accumulators::new(2, &pairs, nf);
            // The plain-arithmetic pass (CPUs without AVX2 and FMA).
            let mut plain = Accumulators::new(2, &pairs, nf);
            let specs: Vec<Vec<Vec<Complex<f64>>>> = (0..BATCH + 2)
                .map(|_| {
                    (0..2)
                        .map(|_| {
                            (0..nf)
                                .map(|_| Complex::new(rng.normal(), rng.normal()))
                                .collect()
                        })
                        .collect()
                })
                .collect();
            for batch in specs.chunks(BATCH) {
                for (slot, chans) in batch.iter().enumerate() {
                    for (c, spec) in chans.iter().enumerate() {
                        acc.slot_mut(slot, c).copy_from_slice(spec);
                        acc.add_channel(slot, c);
                        plain.slot_mut(slot, c).copy_from_slice(spec);
                        plain.add_channel(slot, c);
                    }
                }
                acc.add_segments(batch.len());
                match batch.len() {
                    1 => plain.add_body::<1>(),
                    2 => plain.add_body::<2>(),
                    3 => plain.add_body::<3>(),
                    _ => plain.add_body::<BATCH>(),
                }
                plain.summed = true;
            }
            let plain = plain.finish(&pairs, &vec![1.0; nf], vec![0.0; nf], specs.len());
            let got = acc.finish(&pairs, &vec![1.0; nf], vec![0.0; nf], specs.len());
            for (p, &(i, j)) in pairs.iter().enumerate() {
                for k in 0..nf {
                    let want: Complex<f64> = specs.iter().map(|s| s[i][k].conj() * s[j][k]).sum();
                    let d = got.cross[p][k] - want;
                    assert!(d.norm() < 1e-12, "nf {nf} pair {p} bin {k}");
                    let d = plain.cross[p][k] - want;
                    assert!(d.norm() < 1e-12, "plain: nf {nf} pair {p} bin {k}");
                }
            }
            for c in 0..2 {
                for k in 0..nf {
                    let want: f64 = specs.iter().map(|s| s[c][k].norm_sqr()).sum();
                    assert!((got.auto[c][k] - want).abs() < 1e-12);
                }
            }
        }
    }

    /// With no segment added, the cross sums are zeros (never the
    /// unspecified contents of a reused buffer).
    #[test]
    fn sums_without_segments_are_zero() {
        let mut acc = Accumulators::new(2, &[(0, 1)], 5);
        acc.cross.fill(f64::NAN);
        let got = acc.finish(&[(0, 1)], &[1.0; 5], vec![0.0; 5], 0);
        assert!(got.cross[0].iter().all(|c| c.re == 0.0 && c.im == 0.0));
    }
}
