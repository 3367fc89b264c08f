//! Hot inner loops shared by the estimators and the quality report, with a
//! runtime path for CPUs with AVX2 and FMA (the build targets baseline
//! x86-64, whose SSE2 has two lanes and no fused multiply–add).
//!
//! Each kernel is one generic body compiled twice: plainly, and inside a
//! `#[target_feature(enable = "avx2,fma")]` function chosen at run time.
//! With FMA the sums differ from the plain ones by rounding only.

/// True when the CPU has AVX2 and FMA (cached by std after the first call).
#[inline]
pub fn has_avx2_fma() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Asks the cache line holding `x` into L2 (a hint, no effect on values).
#[inline(always)]
pub fn prefetch_line(x: &f64) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch never faults and reads nothing; SSE is baseline
    // on x86_64.
    unsafe {
        use std::arch::x86_64::{_MM_HINT_T1, _mm_prefetch};
        _mm_prefetch::<_MM_HINT_T1>((x as *const f64).cast());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = x;
}

/// The sum of eight partial sums, pairwise: the fold every eight-lane
/// accumulation here ends with (one order, so one rounding).
#[inline(always)]
pub fn fold8(a: [f64; 8]) -> f64 {
    ((a[0] + a[1]) + (a[2] + a[3])) + ((a[4] + a[5]) + (a[6] + a[7]))
}

/// `x·y + acc`, fused when `FMA`.
#[inline(always)]
pub fn madd<const FMA: bool>(x: f64, y: f64, acc: f64) -> f64 {
    if FMA { x.mul_add(y, acc) } else { x * y + acc }
}

/// out[q] += Σ_s a[s] · ys[q][s] for every q (each `ys[q]` at least as
/// long as `a`): several dot products sharing the loads of `a`.
pub fn dots(a: &[f64], ys: &[&[f64]], out: &mut [f64]) {
    debug_assert_eq!(ys.len(), out.len());
    debug_assert!(ys.iter().all(|y| y.len() >= a.len()));
    #[cfg(target_arch = "x86_64")]
    if has_avx2_fma() {
        // SAFETY: the CPU has the features the function is compiled for.
        return unsafe { dots_avx2_fma(a, ys, out) };
    }
    dots_body::<false>(a, ys, out)
}

/// out[k] += Σ_s a[s] · b[s + k] for k < out.len(); b holds
/// a.len() + out.len() − 1 samples (lagged cross-products).
pub fn lagged_dots(a: &[f64], b: &[f64], out: &mut [f64]) {
    debug_assert_eq!(b.len() + 1, a.len() + out.len());
    let ys: Vec<&[f64]> = (0..out.len()).map(|k| &b[k..k + a.len()]).collect();
    dots(a, &ys, out)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn dots_avx2_fma(a: &[f64], ys: &[&[f64]], out: &mut [f64]) {
    let nq = out.len();
    let full = a.len() / LANES * LANES;
    for q0 in (0..nq).step_by(GROUP) {
        let g = GROUP.min(nq - q0);
        let (ys, out) = (&ys[q0..q0 + g], &mut out[q0..q0 + g]);
        match g {
            4 => group_avx2::<4>(a, ys, out, full),
            3 => group_avx2::<3>(a, ys, out, full),
            2 => group_avx2::<2>(a, ys, out, full),
            _ => group_avx2::<1>(a, ys, out, full),
        }
    }
}

/// [`group`] with FMA in explicit 4-lane registers: the same eight
/// partial sums per product (lane k sums the samples `k mod 8`), the same
/// fold, so the same values bit for bit. (The compiler's own
/// vectorisation of `group` shuffled the accumulators between registers.)
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn group_avx2<const G: usize>(a: &[f64], ys: &[&[f64]], out: &mut [f64], full: usize) {
    use std::arch::x86_64::{
        __m256d, _mm256_fmadd_pd, _mm256_loadu_pd, _mm256_setzero_pd, _mm256_storeu_pd,
    };
    let (a, tail) = a.split_at(full);
    let yq: [&[f64]; G] = std::array::from_fn(|q| &ys[q][..full]);
    let mut lo: [__m256d; G] = [_mm256_setzero_pd(); G];
    let mut hi: [__m256d; G] = [_mm256_setzero_pd(); G];
    let mut s = 0;
    while s < full {
        // SAFETY: `s + LANES <= full`, the length of `a` and of every `yq`.
        unsafe {
            let a0 = _mm256_loadu_pd(a.as_ptr().add(s));
            let a1 = _mm256_loadu_pd(a.as_ptr().add(s + 4));
            for q in 0..G {
                let y = yq[q].as_ptr().add(s);
                lo[q] = _mm256_fmadd_pd(a0, _mm256_loadu_pd(y), lo[q]);
                hi[q] = _mm256_fmadd_pd(a1, _mm256_loadu_pd(y.add(4)), hi[q]);
            }
        }
        s += LANES;
    }
    for q in 0..G {
        let mut accq = [0.0f64; LANES];
        // SAFETY: `accq` holds 8 doubles, stored as two runs of 4.
        unsafe {
            _mm256_storeu_pd(accq.as_mut_ptr(), lo[q]);
            _mm256_storeu_pd(accq.as_mut_ptr().add(4), hi[q]);
        }
        let mut sum = fold8(accq);
        for (x, y) in tail.iter().zip(&ys[q][full..]) {
            sum = x.mul_add(*y, sum);
        }
        out[q] += sum;
    }
}

/// Lanes of one accumulator; products sharing one load of `a`.
const LANES: usize = 8;
const GROUP: usize = 4;

#[inline(always)]
fn dots_body<const FMA: bool>(a: &[f64], ys: &[&[f64]], out: &mut [f64]) {
    let nq = out.len();
    let n = a.len();
    let full = n / LANES * LANES;
    for q0 in (0..nq).step_by(GROUP) {
        let g = GROUP.min(nq - q0);
        match g {
            4 => group::<FMA, 4>(a, &ys[q0..q0 + 4], &mut out[q0..q0 + 4], full),
            3 => group::<FMA, 3>(a, &ys[q0..q0 + 3], &mut out[q0..q0 + 3], full),
            2 => group::<FMA, 2>(a, &ys[q0..q0 + 2], &mut out[q0..q0 + 2], full),
            _ => group::<FMA, 1>(a, &ys[q0..q0 + 1], &mut out[q0..q0 + 1], full),
        }
    }
}

/// G dot products at once over the first `full` (a multiple of LANES)
/// samples in LANES partial sums each, then the remainder.
#[inline(always)]
fn group<const FMA: bool, const G: usize>(a: &[f64], ys: &[&[f64]], out: &mut [f64], full: usize) {
    let yq: [&[f64]; G] = std::array::from_fn(|q| &ys[q][..full]);
    let mut acc = [[0.0f64; LANES]; G];
    for (s, av) in a[..full].chunks_exact(LANES).enumerate() {
        for (accq, y) in acc.iter_mut().zip(&yq) {
            let yv = &y[s * LANES..(s + 1) * LANES];
            for ((c, &x), &y) in accq.iter_mut().zip(av).zip(yv) {
                *c = madd::<FMA>(x, y, *c);
            }
        }
    }
    for (q, accq) in acc.iter().enumerate() {
        let mut sum = fold8(*accq);
        for (x, y) in a[full..].iter().zip(&ys[q][full..]) {
            sum = madd::<FMA>(*x, *y, sum);
        }
        out[q] += sum;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;

    #[test]
    fn avx2_kernel_equals_the_generic_fused_body_bit_for_bit() {
        if !has_avx2_fma() {
            return;
        }
        let mut rng = SplitMix64::new(9);
        for (len, nq) in [
            (0usize, 1usize),
            (7, 3),
            (8, 4),
            (61, 5),
            (2048, 9),
            (300, 13),
        ] {
            let a: Vec<f64> = (0..len).map(|_| rng.normal()).collect();
            let ys: Vec<Vec<f64>> = (0..nq)
                .map(|_| (0..len + 2).map(|_| rng.normal()).collect())
                .collect();
            let refs: Vec<&[f64]> = ys.iter().map(Vec::as_slice).collect();
            let mut fast = vec![0.5; nq];
            let mut generic = vec![0.5; nq];
            dots(&a, &refs, &mut fast);
            dots_body::<true>(&a, &refs, &mut generic);
            assert_eq!(fast, generic, "len {len}, {nq} products");
        }
    }

    #[test]
    fn lagged_dots_match_the_plain_sums() {
        let mut rng = SplitMix64::new(5);
        for (len, nd) in [(0usize, 3usize), (5, 1), (37, 39), (1024, 39), (9, 9)] {
            let a: Vec<f64> = (0..len).map(|_| rng.normal()).collect();
            let b: Vec<f64> = (0..len + nd - 1).map(|_| rng.normal()).collect();
            let mut out = vec![1.0; nd];
            lagged_dots(&a, &b, &mut out);
            let mut plain = vec![1.0; nd];
            let ys: Vec<&[f64]> = (0..nd).map(|k| &b[k..k + len]).collect();
            dots_body::<false>(&a, &ys, &mut plain);
            for (k, (o, p)) in out.iter().zip(&plain).enumerate() {
                assert!(
                    (o - p).abs() < 1e-12 * (1.0 + p.abs()),
                    "plain: len {len} k {k}"
                );
                let want = 1.0 + (0..len).map(|s| a[s] * b[s + k]).sum::<f64>();
                assert!(
                    (o - want).abs() < 1e-12 * (1.0 + want.abs()),
                    "len {len} k {k}"
                );
            }
        }
    }
}
