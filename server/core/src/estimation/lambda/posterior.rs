//! Per-row Gaussian posterior of [A_λ B_λ] from the shared statistics: the
//! end state of the constant-parameter Kalman filter, computed in
//! information form, with the measurement-noise variance either given or
//! estimated from the residuals.

use nalgebra::{DMatrix, DVector};

use super::error::LambdaError;
use super::statistics::RegressionStats;

/// Posterior of one output row (entries of the full 2n regressor order;
/// fixed entries are 0 in `theta` and in `cov`).
#[derive(Debug, Clone)]
pub(crate) struct RowPosterior {
    /// θ_i = [A_λ row i, B_λ row i].
    pub theta: DVector<f64>,
    /// Posterior covariance of θ_i (2n × 2n).
    pub cov: DMatrix<f64>,
    /// Measurement-noise variance R_i used.
    pub noise_variance: f64,
    /// Residual variance Σ(y − φᵀθ)² / (N − runs − free parameters).
    pub residual_variance: f64,
}

/// Residual degrees of freedom of a row with `n_free` parameters.
pub(crate) fn residual_dof(stats: &RegressionStats, n_free: usize) -> f64 {
    stats.n_samples as f64 - stats.n_nuisance as f64 - n_free as f64
}

/// Σ(y_i − φᵀθ)² from the statistics.
pub(crate) fn rss(
    stats: &RegressionStats,
    i: usize,
    free: &[usize],
    theta_s: &DVector<f64>,
) -> f64 {
    let mut v = stats.yy[i];
    for (a, &ja) in free.iter().enumerate() {
        v -= 2.0 * theta_s[a] * stats.cross[(ja, i)];
        for (b, &jb) in free.iter().enumerate() {
            v += theta_s[a] * stats.gram[(ja, jb)] * theta_s[b];
        }
    }
    v.max(0.0)
}

/// Solves (P₀⁻¹ + G/R)θ = P₀⁻¹θ₀ + c/R on the free set, Jacobi-scaled
/// before the Cholesky factorization (regressors in m/s and in N differ by
/// orders of magnitude). Returns θ_S and the covariance (P₀⁻¹ + G/R)⁻¹.
fn solve(
    stats: &RegressionStats,
    i: usize,
    free: &[usize],
    theta0: &DVector<f64>,
    p0: &DVector<f64>,
    r: f64,
) -> Option<(DVector<f64>, DMatrix<f64>)> {
    let k = free.len();
    let mut lam = DMatrix::from_fn(k, k, |a, b| stats.gram[(free[a], free[b])] / r);
    let mut eta = DVector::from_fn(k, |a, _| stats.cross[(free[a], i)] / r);
    for (a, &j) in free.iter().enumerate() {
        lam[(a, a)] += 1.0 / p0[j];
        eta[a] += theta0[j] / p0[j];
    }
    let d = DVector::from_fn(k, |a, _| 1.0 / lam[(a, a)].sqrt());
    let scaled = DMatrix::from_fn(k, k, |a, b| lam[(a, b)] * d[a] * d[b]);
    let chol = scaled.cholesky()?;
    let inv_scaled = chol.inverse();
    let cov = DMatrix::from_fn(k, k, |a, b| inv_scaled[(a, b)] * d[a] * d[b]);
    let theta = &cov * eta;
    theta
        .iter()
        .chain(cov.iter())
        .all(|v| v.is_finite())
        .then_some((theta, cov))
}

/// Replaces the posterior covariance of `post` (free set `free`, prior
/// variances `p0`) by the sandwich Λ⁻¹(P₀⁻¹ + Ω/R²)Λ⁻¹, keeping it when the
/// result is not a valid covariance (a non-positive diagonal).
pub(crate) fn apply_sandwich(
    post: &mut RowPosterior,
    free: &[usize],
    p0: &DVector<f64>,
    omega: &DMatrix<f64>,
) {
    let k = free.len();
    let lam_inv = DMatrix::from_fn(k, k, |a, b| post.cov[(free[a], free[b])]);
    let r = post.noise_variance;
    let mut middle = omega / (r * r);
    for (a, &j) in free.iter().enumerate() {
        middle[(a, a)] += 1.0 / p0[j];
    }
    let s = &lam_inv * middle * &lam_inv;
    if (0..k).all(|a| s[(a, a)] > 0.0 && s[(a, a)].is_finite()) {
        for (a, &ja) in free.iter().enumerate() {
            for (b, &jb) in free.iter().enumerate() {
                post.cov[(ja, jb)] = 0.5 * (s[(a, b)] + s[(b, a)]);
            }
        }
    }
}

/// Fixed-point iterations of R ← RSS(θ(R))/dof when R is estimated.
const NOISE_ITERATIONS: usize = 50;

/// The posterior of row `i` with free regressors `free`, prior mean
/// `theta0` and prior variances `p0` (both in the full 2n order), and the
/// noise variance `noise` (estimated from the residuals when `None`).
///
/// # Errors
/// [`LambdaError::Singular`] naming `runs` when the posterior information
/// is not positive definite (no excitation and a degenerate prior).
pub(crate) fn row_posterior(
    stats: &RegressionStats,
    i: usize,
    free: &[usize],
    theta0: &DVector<f64>,
    p0: &DVector<f64>,
    noise: Option<f64>,
) -> Result<RowPosterior, LambdaError> {
    let dof = residual_dof(stats, free.len()).max(1.0);
    let fail = || {
        LambdaError::singular(
            "runs",
            format!(
                "the information on output row {i} is not positive definite: the runs do not excite its regressors"
            ),
        )
    };
    // Noise variance: start from the output's mean square (an upper bound,
    // so the prior is not over-ruled early) and iterate to the residual
    // variance of the posterior; the floor keeps noise-free data solvable.
    let floor = 1e-30 * (stats.yy[i] / stats.n_samples.max(1) as f64).max(f64::MIN_POSITIVE);
    let mut r = match noise {
        Some(r) => r,
        None => (stats.yy[i] / dof).max(floor),
    };
    let mut post = solve(stats, i, free, theta0, p0, r).ok_or_else(fail)?;
    if noise.is_none() {
        for _ in 0..NOISE_ITERATIONS {
            let r_new = (rss(stats, i, free, &post.0) / dof).max(floor);
            let done = (r_new - r).abs() <= 1e-9 * r;
            r = r_new;
            post = solve(stats, i, free, theta0, p0, r).ok_or_else(fail)?;
            if done {
                break;
            }
        }
    }
    let (theta_s, cov_s) = post;
    let p = theta0.len();
    let mut theta = DVector::zeros(p);
    let mut cov = DMatrix::zeros(p, p);
    for (a, &ja) in free.iter().enumerate() {
        theta[ja] = theta_s[a];
        for (b, &jb) in free.iter().enumerate() {
            cov[(ja, jb)] = cov_s[(a, b)];
        }
    }
    let residual_variance = rss(stats, i, free, &theta_s) / dof;
    Ok(RowPosterior {
        theta,
        cov,
        noise_variance: r,
        residual_variance,
    })
}
