//! The cross-sum pass of [`super::accumulators`] in 4-lane registers:
//! `Σ_s conj(X_i)·X_j` over a batch's held segments for runs of pairs that
//! share their first channel, two bins per register as the FFT leaves them
//! (re, im, re, im).

use realfft::num_complex::Complex;

use super::accumulators::BATCH;

/// Pairs of one run of the cross-sum pass (see
/// `super::accumulators::Accumulators::add_avx2`): x loaded once for this
/// many.
pub(super) const GROUP: usize = 4;

/// The held spectra as the cross-sum pass reads them.
pub(super) struct Held<'a> {
    pub slots: &'a [Complex<f64>],
    pub nf: usize,
    /// Bins read in pairs: the even count below `nf`.
    pub even: usize,
}

impl Held<'_> {
    /// Channel `c`'s spectrum in slot `s`, all `nf` bins.
    pub fn spec(&self, c: usize, s: usize) -> &[Complex<f64>] {
        let off = (c * BATCH + s) * self.nf;
        &self.slots[off..off + self.nf]
    }
}

/// Adds `Σ_s conj(X_i)·X_j` over the `S` held segments, at `bins` (even
/// bounds within `held.even`), to the sums of the `G` pairs `(i, js[g])`
/// (`sums`: G × `[bin][re, im]` of `nf` bins), or stores it (`store`).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
pub(super) fn cross_run<const S: usize, const G: usize>(
    held: &Held<'_>,
    i: usize,
    js: [usize; G],
    sums: &mut [f64],
    bins: std::ops::Range<usize>,
    store: bool,
) {
    use std::arch::x86_64::{
        _mm256_add_pd, _mm256_fmadd_pd, _mm256_hadd_pd, _mm256_loadu_pd, _mm256_permute_pd,
        _mm256_set_pd, _mm256_setzero_pd, _mm256_storeu_pd, _mm256_xor_pd,
    };
    let (nf, even) = (held.nf, held.even);
    assert!(bins.end <= even && sums.len() >= G * 2 * nf);
    let x: [&[Complex<f64>]; S] = std::array::from_fn(|s| &held.spec(i, s)[..even]);
    let y: [[&[Complex<f64>]; S]; G] =
        std::array::from_fn(|g| std::array::from_fn(|s| &held.spec(js[g], s)[..even]));
    // The sign bit of the even lanes: (x_im, x_re) → (−x_im, x_re).
    let negate_even = _mm256_set_pd(0.0, -0.0, 0.0, -0.0);
    let mut k = bins.start;
    while k + 1 < bins.end {
        // SAFETY: `k + 1 < bins.end ≤ even`, the length of every `x[s]` and
        // `y[g][s]` (complex values: two doubles each, `repr(C)`), and
        // `2k + 3 < 2nf`, within pair g's sums at `g·2nf` (asserted above).
        unsafe {
            let mut p = [_mm256_setzero_pd(); G];
            let mut q = [_mm256_setzero_pd(); G];
            for s in 0..S {
                let xv = _mm256_loadu_pd(x[s].as_ptr().add(k).cast::<f64>());
                let xs = _mm256_xor_pd(_mm256_permute_pd::<0b0101>(xv), negate_even);
                for g in 0..G {
                    let yv = _mm256_loadu_pd(y[g][s].as_ptr().add(k).cast::<f64>());
                    p[g] = _mm256_fmadd_pd(xv, yv, p[g]);
                    q[g] = _mm256_fmadd_pd(xs, yv, q[g]);
                }
            }
            for g in 0..G {
                let terms = _mm256_hadd_pd(p[g], q[g]);
                let dst = sums.as_mut_ptr().add(g * 2 * nf + 2 * k);
                let v = if store {
                    terms
                } else {
                    _mm256_add_pd(_mm256_loadu_pd(dst), terms)
                };
                _mm256_storeu_pd(dst, v);
            }
        }
        k += 2;
    }
}
