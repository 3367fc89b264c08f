//! Order of persistence of excitation.
//!
//! A signal u is persistently exciting (PE) of order n when the covariance of
//! its n-sample regressor φ(t) = [u(t), u(t−1), …, u(t−n+1)]ᵀ is nonsingular
//! (Ljung, *System Identification*, 2nd ed., Def. 13.2; Söderström & Stoica
//! §5.4). It is the input-side identifiability condition: an FIR or ARX
//! model with n input parameters can only be estimated consistently from an
//! input that is PE of order ≥ n. Classical values: white noise is PE of any
//! order, a sinusoid of order 2, a constant of order 1, and a periodic signal
//! of period M of order equal to the number of nonzero DFT lines of one
//! period (at most M) — so an m-sequence of period 2ⁿ − 1 played one sample
//! per chip is PE of order exactly 2ⁿ − 1.
//!
//! The finite-data estimate used here is the *sample* covariance of the
//! regressors over the samples where all lags are available, not a Toeplitz
//! matrix of the zero-padded (biased) autocorrelation: the latter is positive
//! definite for every nonzero finite record and would report full order for
//! any signal.

use nalgebra::{DMatrix, SymmetricEigen};

use super::SignalError;

/// Default relative tolerance for [`pe_order`]: singular values below
/// 10⁻⁹·σ_max count as zero. Well above rounding noise (~10⁻¹⁵) and well
/// below any genuinely excited direction in a usable record.
pub const DEFAULT_PE_TOL: f64 = 1e-9;

/// Largest `max_order` accepted by [`pe_order`] (the covariance matrix is
/// `max_order × max_order`, and its eigen-decomposition is cubic in it).
pub const MAX_PE_ORDER: usize = 1024;

/// Numerical order of persistence of excitation of `u`, capped at
/// `max_order`.
///
/// `u` is the input *about the operating point* (the deviation from the trim
/// value): a constant offset left in `u` counts as one excited direction.
/// With n = `max_order` and N = `u.len()`, the regressors
/// φ(t) = [u(t), …, u(t−n+1)]ᵀ for t = n−1..N−1 give the sample covariance
/// R_n = (1/(N−n+1)) Σ φ(t)φ(t)ᵀ, and the result is its numerical rank: the
/// number of singular values above `rel_tol`·σ_max (0 for an all-zero
/// signal). Because the rank of an n × n matrix is at most n, a return value
/// of `max_order` means "PE of order at least `max_order`".
///
/// The result is invariant to scaling `u` (it is normalised by max |u|
/// first, which also prevents overflow).
///
/// # Errors
/// `max_order` zero or above [`MAX_PE_ORDER`]; `rel_tol` negative, not
/// finite, or ≥ 1; a non-finite sample in `u`; fewer than 2·`max_order`
/// samples (too few regressors for the covariance to mean anything).
pub fn pe_order(u: &[f64], max_order: usize, rel_tol: f64) -> Result<usize, SignalError> {
    let n = max_order;
    if n == 0 || n > MAX_PE_ORDER {
        return Err(SignalError::invalid(
            "max_order",
            format!("must be in 1..={MAX_PE_ORDER}, got {n}"),
        ));
    }
    if !(rel_tol.is_finite() && (0.0..1.0).contains(&rel_tol)) {
        return Err(SignalError::invalid(
            "rel_tol",
            format!("must be a finite number in [0, 1), got {rel_tol}"),
        ));
    }
    let len = u.len();
    if len < 2 * n {
        return Err(SignalError::insufficient(
            "u",
            format!(
                "{len} samples cannot test PE order {n}: at least 2·max_order = {} are needed",
                2 * n
            ),
        ));
    }
    if let Some(i) = u.iter().position(|v| !v.is_finite()) {
        return Err(SignalError::invalid(
            "u",
            format!("sample {i} is not finite ({})", u[i]),
        ));
    }

    let scale = u.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    if scale == 0.0 {
        return Ok(0);
    }
    let u: Vec<f64> = u.iter().map(|v| v / scale).collect();
    let r = regressor_covariance(&u, n);

    let eig = SymmetricEigen::try_new(r, f64::EPSILON, 1000 * n.max(10)).ok_or_else(|| {
        SignalError::invalid(
            "u",
            "eigen-decomposition of the regressor covariance did not converge",
        )
    })?;
    // R_n is symmetric positive semi-definite, so its singular values are the
    // absolute values of its eigenvalues (tiny negatives are rounding).
    let sigma: Vec<f64> = eig.eigenvalues.iter().map(|l| l.abs()).collect();
    let sigma_max = sigma.iter().fold(0.0_f64, |m, &s| m.max(s));
    if sigma_max == 0.0 {
        return Ok(0);
    }
    Ok(sigma.iter().filter(|&&s| s > rel_tol * sigma_max).count())
}

/// Sample covariance R(i, j) = (1/(N−n+1)) Σ_{t=n−1}^{N−1} u(t−i)·u(t−j).
///
/// Computed in O(N·n + n²) instead of O(N·n²): the first row is summed
/// directly, and shifting both lags by one shifts the summation window by
/// one sample, so R(i+1, j+1) = R(i, j) + u(n−2−i)u(n−2−j) − u(N−1−i)u(N−1−j)
/// (before normalisation).
fn regressor_covariance(u: &[f64], n: usize) -> DMatrix<f64> {
    let len = u.len();
    let mut s = DMatrix::<f64>::zeros(n, n);
    // First row: s[0][j] = Σ_{t ≥ n−1} u[t]·u[t−j], as lagged dot products
    // (out[k] = Σ_s u[n−1+s]·u[s+k], k = n−1−j).
    let mut first = vec![0.0; n];
    crate::kernels::lagged_dots(&u[n - 1..], u, &mut first);
    for (k, v) in first.into_iter().enumerate() {
        s[(0, n - 1 - k)] = v;
    }
    for i in 0..n - 1 {
        for j in i..n - 1 {
            s[(i + 1, j + 1)] =
                s[(i, j)] + u[n - 2 - i] * u[n - 2 - j] - u[len - 1 - i] * u[len - 1 - j];
        }
    }
    // Mirror the upper triangle and normalise.
    let count = (len - n + 1) as f64;
    for i in 0..n {
        for j in i..n {
            let v = s[(i, j)] / count;
            s[(i, j)] = v;
            s[(j, i)] = v;
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::signals::{PrbsSpec, SquareSpec, mls, prbs, random_binary, square};
    use std::f64::consts::PI;

    /// Direct O(N·n²) covariance, to check the recurrence.
    fn covariance_direct(u: &[f64], n: usize) -> DMatrix<f64> {
        let mut r = DMatrix::<f64>::zeros(n, n);
        for t in n - 1..u.len() {
            for i in 0..n {
                for j in 0..n {
                    r[(i, j)] += u[t - i] * u[t - j];
                }
            }
        }
        r / (u.len() - n + 1) as f64
    }

    #[test]
    fn covariance_recurrence_matches_direct_sum() {
        let u: Vec<f64> = (0..300)
            .map(|t| ((t * t) % 17) as f64 - 8.0 + (t as f64 * 0.3).sin())
            .collect();
        for n in [1, 2, 7, 40] {
            let a = regressor_covariance(&u, n);
            let b = covariance_direct(&u, n);
            assert!((a - &b).amax() < 1e-10 * b.amax(), "n = {n}");
        }
    }

    /// m-sequence of order n at one sample per chip over many periods is PE
    /// of order exactly 2ⁿ − 1 (not the cap of 64, which the zero-padded
    /// autocorrelation would report).
    #[test]
    fn prbs_one_sample_per_chip_is_pe_of_order_period() {
        for (order, expected) in [(3u32, 7usize), (4, 15), (5, 31)] {
            let m = (1usize << order) - 1;
            // ≥ 3 periods and ≥ 2·64 samples.
            let periods = (3 * m).max(2 * 64 + m).div_ceil(m);
            let spec = PrbsSpec {
                order,
                clock_period_s: 1.0,
                amplitude: 1.0,
                offset: 0.0,
                seed: 11,
            };
            let u = prbs(&spec, 1.0, (periods * m) as f64).unwrap();
            assert_eq!(
                pe_order(&u, 64, DEFAULT_PE_TOL),
                Ok(expected),
                "order {order}"
            );
            // Same from the raw ±1 chips, scaled and for another seed.
            let chips = mls(order, 2).unwrap();
            let u: Vec<f64> = (0..periods * m)
                .map(|t| 3.5 * f64::from(chips[t % m]))
                .collect();
            assert_eq!(
                pe_order(&u, 64, DEFAULT_PE_TOL),
                Ok(expected),
                "order {order}"
            );
        }
    }

    /// A ±1 square wave of period 2h samples has nonzero DFT lines only at
    /// the h odd harmonics, so its PE order is exactly h.
    #[test]
    fn square_wave_half_period_h_is_pe_of_order_h() {
        for h in [3usize, 5, 8] {
            let spec = SquareSpec {
                period_s: (2 * h) as f64,
                amplitude: 1.0,
                offset: 0.0,
                phase_s: 0.0,
            };
            let u = square(&spec, 1.0, (40 * h) as f64).unwrap();
            assert_eq!(pe_order(&u, 20, DEFAULT_PE_TOL), Ok(h), "h = {h}");
        }
    }

    #[test]
    fn sinusoid_is_pe_of_order_two() {
        let u: Vec<f64> = (0..2000)
            .map(|t| 0.8 * (2.0 * PI * 0.0731 * t as f64 + 0.4).sin())
            .collect();
        assert_eq!(pe_order(&u, 10, DEFAULT_PE_TOL), Ok(2));
        // Two sinusoids at distinct frequencies: 4.
        let u: Vec<f64> = (0..2000)
            .map(|t| {
                (2.0 * PI * 0.0731 * t as f64).sin() + 0.5 * (2.0 * PI * 0.21 * t as f64).cos()
            })
            .collect();
        assert_eq!(pe_order(&u, 10, DEFAULT_PE_TOL), Ok(4));
    }

    #[test]
    fn constant_is_order_one_and_zero_is_order_zero() {
        assert_eq!(pe_order(&[0.7; 100], 10, DEFAULT_PE_TOL), Ok(1));
        assert_eq!(pe_order(&[-1e200; 100], 10, DEFAULT_PE_TOL), Ok(1));
        assert_eq!(pe_order(&[0.0; 100], 10, DEFAULT_PE_TOL), Ok(0));
    }

    #[test]
    fn random_binary_reaches_the_cap() {
        let u = random_binary(1.0, 1.0, 0.0, 2024, 1.0, 5000.0).unwrap();
        assert_eq!(pe_order(&u, 20, DEFAULT_PE_TOL), Ok(20));
        // A long-period PRBS (63) is also capped at max_order.
        let chips = mls(6, 0).unwrap();
        let u: Vec<f64> = (0..630).map(|t| f64::from(chips[t % 63])).collect();
        assert_eq!(pe_order(&u, 20, DEFAULT_PE_TOL), Ok(20));
    }

    #[test]
    fn pe_order_rejects_bad_input() {
        let u = vec![1.0; 50];
        let field = |r: Result<usize, SignalError>| r.unwrap_err().field().to_owned();
        assert_eq!(field(pe_order(&u, 0, DEFAULT_PE_TOL)), "max_order");
        assert_eq!(
            field(pe_order(&vec![1.0; 5000], MAX_PE_ORDER + 1, DEFAULT_PE_TOL)),
            "max_order"
        );
        assert!(matches!(
            pe_order(&u, 26, DEFAULT_PE_TOL),
            Err(SignalError::InsufficientData { .. })
        ));
        assert!(pe_order(&u, 25, DEFAULT_PE_TOL).is_ok());
        assert_eq!(field(pe_order(&u, 5, -1e-3)), "rel_tol");
        assert_eq!(field(pe_order(&u, 5, 1.0)), "rel_tol");
        assert_eq!(field(pe_order(&u, 5, f64::NAN)), "rel_tol");
        let mut bad = u.clone();
        bad[17] = f64::NAN;
        let e = pe_order(&bad, 5, DEFAULT_PE_TOL).unwrap_err();
        assert_eq!(e.field(), "u");
        assert!(e.message().contains("17"), "{e}");
        assert_eq!(field(pe_order(&[], 1, DEFAULT_PE_TOL)), "u");
    }
}
