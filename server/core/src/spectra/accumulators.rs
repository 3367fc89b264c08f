//! The sums of a multichannel Welch estimate: `Σ |X_c|²` per channel and
//! `Σ conj(X_i)·X_j` per requested pair, over segments.
//!
//! The spectra of up to [`BATCH`] segments are held split into real and
//! imaginary planes, so that the per-pair loops are plain element-wise
//! multiply–adds the compiler vectorises, then added to the cross sums in
//! one pass over them (the sums of a 6 × 6 report outgrow a core's L2
//! cache). Every sum still runs over the segments in order. (Adding pairs
//! that share a channel together, to load its values once, was slower:
//! the compiler spilled the wider kernel's registers.)

use realfft::num_complex::Complex;

use super::multichannel::MultiSpectra;
use crate::kernels::{has_avx2_fma, madd};

/// Segments whose spectra are held before they are added to the cross
/// spectra: the 36 cross sums of a 6 × 6 report at `nperseg = 4096` take
/// 1.2 MB, so each pass over them is paid by four segments, not one.
pub(super) const BATCH: usize = 4;

/// See the [module documentation](self).
pub(super) struct Accumulators {
    nf: usize,
    /// Held spectra, `[channel][slot][re | im][bin]`: channel c, slot s at
    /// `(c·BATCH + s)·2nf`, its imaginary plane `nf` further.
    planes: Vec<f64>,
    auto: Vec<f64>,
    /// Cross sums, `[pair][re | im][bin]`.
    cross: Vec<f64>,
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
        let slots = if pairs.is_empty() { 0 } else { BATCH };
        Accumulators {
            nf,
            // Every held value is written (`add_channel`) before it is read
            // (`add_segments`): never zeroed (1.6 MB for a 6 × 6 report).
            planes: scratch::reused(n_channels * slots * 2 * nf),
            auto: scratch::reused(n_channels * nf),
            cross: scratch::reused(pairs.len() * 2 * nf),
            held: Vec::new(),
            pairs: pairs.to_vec(),
        }
    }

    /// Sets every sum to zero.
    /// Unzeroed sums of the same shape (see [`Self::unzeroed`]).
    pub(super) fn sibling(&self) -> Self {
        let n_channels = self.auto.len() / self.nf.max(1);
        Self::unzeroed(n_channels, &self.pairs, self.nf)
    }

    pub(super) fn zero(&mut self) {
        self.auto.fill(0.0);
        self.cross.fill(0.0);
    }

    /// Adds `|X|²` of channel `c`'s spectrum to its PSD and, when there are
    /// pairs, holds the spectrum in slot `slot < BATCH`.
    pub(super) fn add_channel(&mut self, slot: usize, c: usize, spec: &[Complex<f64>]) {
        #[cfg(target_arch = "x86_64")]
        if has_avx2_fma() {
            // SAFETY: the CPU has the features the function is compiled for.
            return unsafe { self.add_channel_fma(slot, c, spec) };
        }
        self.add_channel_body::<false>(slot, c, spec)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn add_channel_fma(&mut self, slot: usize, c: usize, spec: &[Complex<f64>]) {
        self.add_channel_body::<true>(slot, c, spec)
    }

    #[inline(always)]
    fn add_channel_body<const FMA: bool>(&mut self, slot: usize, c: usize, spec: &[Complex<f64>]) {
        let nf = self.nf;
        let auto = &mut self.auto[c * nf..(c + 1) * nf];
        if self.planes.is_empty() {
            for (s, a) in spec.iter().zip(auto) {
                *a += madd::<FMA>(s.re, s.re, s.im * s.im);
            }
            return;
        }
        let off = (c * BATCH + slot) * 2 * nf;
        let (re, im) = self.planes[off..off + 2 * nf].split_at_mut(nf);
        for (((s, r), i), a) in spec.iter().zip(re).zip(im).zip(auto) {
            *r = s.re;
            *i = s.im;
            // Without FMA the same expression as `Complex::norm_sqr`
            // (bit-identical to `welch`).
            *a += madd::<FMA>(s.re, s.re, s.im * s.im);
        }
    }

    /// Adds the cross products of the segments held in slots `0..count`
    /// (in slot order) to every pair.
    pub(super) fn add_segments(&mut self, count: usize) {
        match count {
            0 => {}
            1 => self.add::<1>(),
            2 => self.add::<2>(),
            3 => self.add::<3>(),
            _ => self.add::<BATCH>(),
        }
    }

    fn add<const S: usize>(&mut self) {
        #[cfg(target_arch = "x86_64")]
        if has_avx2_fma() {
            // SAFETY: the CPU has the features the function is compiled for.
            return unsafe { self.add_fma::<S>() };
        }
        self.add_body::<false, S>()
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn add_fma<const S: usize>(&mut self) {
        self.add_body::<true, S>()
    }

    #[inline(always)]
    fn add_body<const FMA: bool, const S: usize>(&mut self) {
        let nf = self.nf;
        let planes = &self.planes[..];
        let plane = |c: usize, s: usize| {
            let off = (c * BATCH + s) * 2 * nf;
            planes[off..off + 2 * nf].split_at(nf)
        };
        for (sums, &(i, j)) in self.cross.chunks_exact_mut(2 * nf).zip(&self.pairs) {
            let x: [_; S] = std::array::from_fn(|s| plane(i, s));
            let y: [_; S] = std::array::from_fn(|s| plane(j, s));
            let (acc_re, acc_im) = sums.split_at_mut(nf);
            for k in 0..nf {
                let (mut re, mut im) = (acc_re[k], acc_im[k]);
                for s in 0..S {
                    let ((xr, xi), (yr, yi)) = (x[s], y[s]);
                    (re, im) = term::<FMA>(xr[k], xi[k], yr[k], yi[k], re, im);
                }
                acc_re[k] = re;
                acc_im[k] = im;
            }
        }
    }

    /// Adds the sums of `other` (same channels, pairs and bins) to these,
    /// and keeps its buffers for the next call on this thread. The PSD
    /// sums are added at once; `other`'s cross sums (with what it absorbed
    /// added to them) are held apart and added where they are read
    /// ([`PlaneSpectra::pair_sums`], [`Accumulators::finish`]): the pairs'
    /// own pass then does it on every thread, not one pass on one thread.
    pub(super) fn absorb(&mut self, mut other: Accumulators) {
        for (a, b) in self.auto.iter_mut().zip(&other.auto) {
            *a += b;
        }
        other.fold_held();
        self.held.push(other.cross);
        for buffer in [other.planes, other.auto] {
            scratch::give_back(buffer);
        }
    }

    /// Adds the held cross sums to the cross sums, in the order they were
    /// absorbed.
    fn fold_held(&mut self) {
        for held in std::mem::take(&mut self.held) {
            par_zip(&mut self.cross, &held, PARALLEL_VALUES / 2, |a, b| {
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

    /// [`Accumulators::finish`] with the cross sums left in their planes,
    /// with the parts they are still to be added to and the density
    /// factors: see [`PlaneSpectra::pair_sums`].
    pub(super) fn finish_planes(
        self,
        factors: &[f64],
        freqs: Vec<f64>,
        n_segments: usize,
    ) -> PlaneSpectra {
        let auto = self.scaled_auto(factors);
        for buffer in [self.planes, self.auto] {
            scratch::give_back(buffer);
        }
        PlaneSpectra {
            freqs,
            auto,
            n_segments,
            cross: self.cross,
            held: self.held,
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
            .cross
            .chunks_exact(2 * nf.max(1))
            .map(|sums| {
                let (r, i) = sums.split_at(nf.max(1));
                r.iter()
                    .zip(i)
                    .zip(factors)
                    .map(|((r, i), f)| Complex::new(r * f, i * f))
                    .collect()
            })
            .collect();
        for buffer in [self.planes, self.auto, self.cross] {
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

/// Welch spectra of several channels with the cross spectra in split
/// planes, as the quality report reads them: [`MultiSpectra`] without its
/// complex vectors. The planes' buffer is kept for the next call on the
/// thread that drops it.
pub(crate) struct PlaneSpectra {
    /// Frequencies in Hz.
    pub freqs: Vec<f64>,
    /// One-sided PSD of each channel.
    pub auto: Vec<Vec<f64>>,
    /// Segments averaged.
    pub n_segments: usize,
    /// Cross sums, `[pair][re | im][bin]`, and the other parts' sums of
    /// the same shape, to be added in order, then scaled by `factors`.
    cross: Vec<f64>,
    held: Vec<Vec<f64>>,
    factors: Vec<f64>,
    nf: usize,
}

impl PlaneSpectra {
    /// The sums of the `p`-th requested pair, `[re | im][bin]`: this
    /// part's first, then the held parts' (empty when out of range), and
    /// the density factors per bin. `P_ij = (Σ parts in order) · factor`,
    /// see [`cross_from_parts`].
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

/// `re, im` = (Σ `parts` in order) · `factors`, each part `[re | im][bin]`.
#[inline(always)]
pub(crate) fn cross_from_parts(
    parts: &[&[f64]],
    factors: &[f64],
    re: &mut Vec<f64>,
    im: &mut Vec<f64>,
) {
    let Some((first, rest)) = parts.split_first() else {
        re.clear();
        im.clear();
        return;
    };
    let nf = first.len() / 2;
    re.clear();
    im.clear();
    re.extend_from_slice(&first[..nf]);
    im.extend_from_slice(&first[nf..]);
    for part in rest {
        let (r, i) = part.split_at(nf);
        re.iter_mut().zip(r).for_each(|(a, b)| *a += b);
        im.iter_mut().zip(i).for_each(|(a, b)| *a += b);
    }
    for ((r, i), f) in re.iter_mut().zip(im.iter_mut()).zip(factors) {
        *r *= f;
        *i *= f;
    }
}

impl Drop for PlaneSpectra {
    fn drop(&mut self) {
        scratch::give_back(std::mem::take(&mut self.cross));
        for held in std::mem::take(&mut self.held) {
            scratch::give_back(held);
        }
    }
}

/// `(re, im) + conj(x)·y`.
#[inline(always)]
fn term<const FMA: bool>(xr: f64, xi: f64, yr: f64, yi: f64, re: f64, im: f64) -> (f64, f64) {
    if FMA {
        (
            madd::<true>(xi, yi, madd::<true>(xr, yr, re)),
            madd::<true>(-xi, yr, madd::<true>(xr, yi, im)),
        )
    } else {
        (re + (xr * yr + xi * yi), im + (xr * yi + -(xi * yr)))
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

    /// A buffer of `len` values, reusing a kept one when there is, with
    /// unspecified (finite or not) contents: for values written before
    /// they are read.
    pub(super) fn reused(len: usize) -> Vec<f64> {
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
                v.truncate(len);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;

    /// The cross sums are Σ conj(X_i)·X_j over the held segments, and the
    /// auto sums Σ |X_c|².
    #[test]
    fn sums_are_the_products_of_the_held_spectra() {
        let mut rng = SplitMix64::new(4);
        let (nf, count) = (13, 3);
        let pairs = [(0, 1), (1, 0)];
        let mut acc = Accumulators::new(2, &pairs, nf);
        let specs: Vec<Vec<Vec<Complex<f64>>>> = (0..count)
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
        for (slot, chans) in specs.iter().enumerate() {
            for (c, spec) in chans.iter().enumerate() {
                acc.add_channel(slot, c, spec);
            }
        }
        acc.add_segments(count);
        for (p, &(i, j)) in pairs.iter().enumerate() {
            for k in 0..nf {
                let want: Complex<f64> = specs.iter().map(|s| s[i][k].conj() * s[j][k]).sum();
                let got = Complex::new(acc.cross[p * 2 * nf + k], acc.cross[p * 2 * nf + nf + k]);
                assert!((got - want).norm() < 1e-12, "pair {p} bin {k}");
            }
        }
        for c in 0..2 {
            for k in 0..nf {
                let want: f64 = specs.iter().map(|s| s[c][k].norm_sqr()).sum();
                assert!((acc.auto[c * nf + k] - want).abs() < 1e-12);
            }
        }
    }
}
