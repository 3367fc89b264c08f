//! Sample auto- and cross-correlation functions of residual analysis
//! (Ljung 1999, sec. 16.6): biased (1/N) estimates of the de-meaned
//! sequences, normalized so that r(0) = 1. The biased form keeps the
//! sequence positive semi-definite and is the one the ±z/√N bounds refer to.
//!
//! Short problems are summed directly; long ones (N·L large) go through a
//! zero-padded real FFT, which gives the same numbers to rounding.

use realfft::RealFftPlanner;
use realfft::num_complex::Complex;

/// Above this many multiply-adds the FFT path is cheaper.
const DIRECT_WORK_LIMIT: usize = 2_000_000;

/// Normalized autocorrelation r(0..=max_lag) of `x`, r(0) = 1. `None` when
/// `x` has fewer than two samples, a non-finite value, or no variance.
/// Lags ≥ N are 0.
pub fn autocorrelation(x: &[f64], max_lag: usize) -> Option<Vec<f64>> {
    let d = demeaned(x)?;
    let cov = if d.len() * (max_lag + 1) <= DIRECT_WORK_LIMIT {
        lagged_products_direct(&d, &d, 0, max_lag as i64)
    } else {
        lagged_products_fft(&d, &d, 0, max_lag as i64)
    };
    let c0 = cov[0];
    Some(cov.iter().map(|c| c / c0).collect())
}

/// Normalized cross-correlation of a residual `e` and an input `u` for the
/// lags τ = −max_lag..=max_lag (entry `max_lag + τ`):
/// r_eu(τ) = Σ_t (e(t+τ) − ē)(u(t) − ū) / (N σ_e σ_u).
/// A positive τ is the residual *after* the input: the input at t shows in
/// the residual at t + τ. `None` when the lengths differ, a sequence is
/// shorter than two samples, non-finite or constant.
pub fn cross_correlation(e: &[f64], u: &[f64], max_lag: usize) -> Option<Vec<f64>> {
    if e.len() != u.len() {
        return None;
    }
    let de = demeaned(e)?;
    let du = demeaned(u)?;
    let n = de.len();
    let scale = (dot(&de, &de) * dot(&du, &du)).sqrt();
    let lag = max_lag as i64;
    let raw = if n * (2 * max_lag + 1) <= DIRECT_WORK_LIMIT {
        lagged_products_direct(&de, &du, -lag, lag)
    } else {
        lagged_products_fft(&de, &du, -lag, lag)
    };
    Some(raw.iter().map(|c| c / scale).collect())
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn demeaned(x: &[f64]) -> Option<Vec<f64>> {
    if x.len() < 2 || x.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let mean = x.iter().sum::<f64>() / x.len() as f64;
    let d: Vec<f64> = x.iter().map(|v| v - mean).collect();
    (dot(&d, &d) > 0.0).then_some(d)
}

/// c(τ) = Σ_t a(t+τ) b(t) for τ = lo..=hi (unnormalized), by direct sums.
fn lagged_products_direct(a: &[f64], b: &[f64], lo: i64, hi: i64) -> Vec<f64> {
    let n = a.len() as i64;
    (lo..=hi)
        .map(|tau| {
            if tau.abs() >= n {
                return 0.0;
            }
            if tau >= 0 {
                dot(&a[tau as usize..], &b[..(n - tau) as usize])
            } else {
                dot(&a[..(n + tau) as usize], &b[(-tau) as usize..])
            }
        })
        .collect()
}

/// The same products by FFT: c = IFFT(A · conj(B)) on a grid long enough
/// that no lag wraps around.
fn lagged_products_fft(a: &[f64], b: &[f64], lo: i64, hi: i64) -> Vec<f64> {
    let n = a.len();
    let reach = lo.unsigned_abs().max(hi.unsigned_abs()) as usize;
    let len = (n + reach.min(n)).next_power_of_two();
    let mut planner = RealFftPlanner::<f64>::new();
    let fwd = planner.plan_fft_forward(len);
    let inv = planner.plan_fft_inverse(len);
    let spectrum = |x: &[f64]| {
        let mut buf = vec![0.0; len];
        buf[..n].copy_from_slice(x);
        let mut out = fwd.make_output_vec();
        // Lengths are the plan's own, so the transform cannot fail.
        fwd.process(&mut buf, &mut out).ok();
        out
    };
    let fa = spectrum(a);
    let fb = spectrum(b);
    let mut prod: Vec<Complex<f64>> = fa.iter().zip(&fb).map(|(x, y)| x * y.conj()).collect();
    // The inverse of a real signal's spectrum has real DC and Nyquist bins.
    prod[0].im = 0.0;
    if let Some(last) = prod.last_mut() {
        last.im = 0.0;
    }
    let mut c = inv.make_output_vec();
    inv.process(&mut prod, &mut c).ok();
    let norm = 1.0 / len as f64;
    (lo..=hi)
        .map(|tau| {
            if tau.unsigned_abs() as usize >= n {
                0.0
            } else if tau >= 0 {
                c[tau as usize] * norm
            } else {
                c[len - (-tau) as usize] * norm
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;

    #[test]
    fn autocorrelation_of_a_known_sequence() {
        // x = [1, −1, 1, −1]: mean 0, c(0) = 4, c(1) = −3, c(2) = 2, c(3) = −1.
        let r = autocorrelation(&[1.0, -1.0, 1.0, -1.0], 5).unwrap();
        let want = [1.0, -0.75, 0.5, -0.25, 0.0, 0.0];
        for (a, b) in r.iter().zip(want) {
            assert!((a - b).abs() < 1e-15);
        }
        assert!(autocorrelation(&[2.0, 2.0, 2.0], 2).is_none());
        assert!(autocorrelation(&[1.0, f64::NAN, 0.0], 2).is_none());
        assert!(autocorrelation(&[1.0], 2).is_none());
    }

    #[test]
    fn cross_correlation_finds_a_delay_with_the_right_sign() {
        // e(t) = u(t − 3): the input shows in the residual three samples
        // later, so the peak is at τ = +3 with r ≈ 1.
        let mut rng = SplitMix64::new(3);
        let u: Vec<f64> = (0..2000).map(|_| rng.normal()).collect();
        let e: Vec<f64> = (0..2000)
            .map(|t| if t >= 3 { u[t - 3] } else { 0.0 })
            .collect();
        let r = cross_correlation(&e, &u, 10).unwrap();
        let (imax, rmax) = r
            .iter()
            .enumerate()
            .fold((0, 0.0), |m, (i, &v)| if v > m.1 { (i, v) } else { m });
        assert_eq!(imax as i64 - 10, 3);
        assert!(rmax > 0.99);
        assert!(cross_correlation(&e[..10], &u, 3).is_none());
    }

    #[test]
    fn fft_and_direct_sums_agree() {
        let mut rng = SplitMix64::new(11);
        let a: Vec<f64> = (0..1537).map(|_| rng.normal()).collect();
        let b: Vec<f64> = (0..1537).map(|_| rng.normal() + 0.3).collect();
        for (lo, hi) in [(0i64, 40i64), (-60, 60), (-1600, 1600)] {
            let d = lagged_products_direct(&a, &b, lo, hi);
            let f = lagged_products_fft(&a, &b, lo, hi);
            let scale = d.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for (x, y) in d.iter().zip(&f) {
                assert!((x - y).abs() < 1e-10 * scale, "{x} vs {y}");
            }
        }
    }

    #[test]
    fn cross_correlation_is_numpys_correlate_over_n_sigma_sigma() {
        // de = [−1, 0, 1], du = [1, 0, −1]; numpy.correlate(de, du, "full")
        // = [1, 0, −2, 0, 1] for τ = −2..2, and N σ_e σ_u = √2·√2 = 2.
        let r = cross_correlation(&[1.0, 2.0, 3.0], &[1.0, 0.0, -1.0], 2).unwrap();
        for (a, b) in r.iter().zip([0.5, 0.0, -1.0, 0.0, 0.5]) {
            assert!((a - b).abs() < 1e-15, "{r:?}");
        }
    }

    #[test]
    fn independent_white_sequences_stay_inside_the_99_percent_band() {
        // z₀.₉₉₅/√N bounds r_eu(τ) of independent white e and u at 99 %.
        use crate::validation::residuals::input_residual_correlation;
        let n = 4000;
        let mut rng = SplitMix64::new(29);
        let e: Vec<f64> = (0..n).map(|_| rng.normal()).collect();
        let u: Vec<f64> = (0..n).map(|_| rng.normal()).collect();
        let c = input_residual_correlation(&e, &u, "tau_X", 100, 0.99).unwrap();
        let z = 2.5758293035489;
        assert!(
            (c.bound - z / (n as f64).sqrt()).abs() < 0.05 * c.bound,
            "{}",
            c.bound
        );
        // About 1 % of the 201 lags fall outside; far fewer than 5 %.
        assert!(c.lags_outside.len() <= 10, "{:?}", c.lags_outside);
        assert!(!c.leak);
    }
}
