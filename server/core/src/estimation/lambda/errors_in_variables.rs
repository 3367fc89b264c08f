//! Errors in the regressors: bias-compensated least squares.
//!
//! The λ regression ν_k = A_λ[λν]_k + B_λ[λγ]_k + K_λ[λe]_k is least
//! squares, which takes the regressors as exact. Where a regressor signal
//! carries measurement error ε_k — γ = τ − g(η) with g evaluated at the
//! measured attitude, whose noise the vehicle never felt; the restoring
//! shapes sin θ, cos θ sin φ of the measured attitude — the Gram matrix
//! over-counts their variance: E[Σφφᵀ] = Σφ₀φ₀ᵀ + Σ_k Cov([λε]_k), and the
//! coefficients shrink toward zero (attenuation): a 2 mrad roll noise under
//! a 90 N·m/rad restoring moment inflated the independent truth's roll
//! inertia by 7 %. With the errors' covariance known, subtracting the
//! expected excess from the Gram matrix removes the bias to first order
//! (bias-compensated least squares; Söderström, *Errors-in-Variables
//! Methods in System Identification*, 2018, ch. 7).
//!
//! Filtered by a = e^{−h/T}, c = 1 − a, an error sequence with lag-0 and
//! lag-1 covariances Σ₀, Σ₁ (white, or a trapezoid mean of white errors:
//! Σ₀ = ½Σ, Σ₁ = ¼Σ) has the stationary covariance
//! V = c²/(1 − a²)·(Σ₀ + a(Σ₁ + Σ₁ᵀ)); from a first-sample start (filter
//! state = the first sample, error Σ₀) it relaxes to V as a^{2k}. Only
//! errors uncorrelated with the regressand ν_k belong here (the strictly
//! causal filter keeps ν_k's own noise out of [λ·]_k).

use nalgebra::DMatrix;

use super::filter::{FilterInit, LambdaFilter};
use super::statistics::RegressionStats;

/// Per-sample covariance of the errors in the unfiltered regressor signals
/// [ν, γ, e] (2n + q square), at lag 0 and lag 1 (zero beyond).
#[derive(Debug, Clone, PartialEq)]
pub struct RegressorNoise {
    /// Cov(ε_k, ε_k).
    pub lag0: DMatrix<f64>,
    /// Cov(ε_{k+1}, ε_k).
    pub lag1: DMatrix<f64>,
}

impl RegressorNoise {
    /// Errors of a signal held over each step as the trapezoid mean
    /// ½(s(η_k) + s(η_{k+1})) of per-sample white errors of covariance
    /// `cov`: Σ₀ = ½·cov, Σ₁ = ¼·cov.
    pub fn held_over_step(cov: DMatrix<f64>) -> Self {
        RegressorNoise {
            lag1: cov.clone() * 0.25,
            lag0: cov * 0.5,
        }
    }
}

/// The expected excess of Σφφᵀ that `noise` puts into runs of `lengths`
/// samples filtered by `f` from `init`.
pub(crate) fn expected_excess(
    noise: &RegressorNoise,
    f: &LambdaFilter,
    lengths: &[usize],
    init: FilterInit,
) -> DMatrix<f64> {
    let a2 = f.a * f.a;
    let stationary =
        (&noise.lag0 + (&noise.lag1 + noise.lag1.transpose()) * f.a) * (f.c * f.c / (1.0 - a2));
    let start = match init {
        FilterInit::Zero => DMatrix::zeros(noise.lag0.nrows(), noise.lag0.ncols()),
        FilterInit::FirstSample => noise.lag0.clone(),
    };
    let mut total = DMatrix::zeros(noise.lag0.nrows(), noise.lag0.ncols());
    for &n in lengths {
        // Σ_k [V + a^{2k}(V₀ − V)] over k = 0 … n−1
        let relax = (1.0 - a2.powi(n as i32)) / (1.0 - a2);
        total += &stationary * n as f64 + (&start - &stationary) * relax;
    }
    total
}

/// Subtracts `excess` from the Gram matrix of `stats`, scaled down (halved
/// up to six times, then not at all) where the whole would take more than
/// [`KEPT_INFORMATION`]'s complement of any column's information: a
/// regressor that moves little against its noise (an unforced sway's few
/// cm/s under 1 cm/s of GNSS noise) is corrected only as far as the data
/// still determine its coefficient; past that, the correction trades a
/// small bias for an undetermined estimate. Returns the share applied
/// (0 … 1).
pub(crate) fn compensate(stats: &mut RegressionStats, excess: &DMatrix<f64>) -> f64 {
    if excess.shape() != stats.gram.shape() || excess.iter().any(|v| !v.is_finite()) {
        return 0.0;
    }
    // Over the columns that carry anything: a regressor identically zero
    // (a DOF no run forced, τ_Y ≡ 0) is the prior's either way.
    let live: Vec<usize> = (0..stats.gram.nrows())
        .filter(|&j| stats.gram[(j, j)] > 0.0)
        .collect();
    let Some(before) = information(&stats.gram, &live) else {
        return 0.0;
    };
    let mut share = 1.0;
    for _ in 0..7 {
        let g = &stats.gram - excess * share;
        let kept = information(&g, &live).is_some_and(|after| {
            after
                .iter()
                .zip(&before)
                .all(|(a, b)| *a >= KEPT_INFORMATION * b)
        });
        if kept {
            stats.gram = g;
            return share;
        }
        share *= 0.5;
    }
    0.0
}

/// Least share of each column's information (1/[G⁻¹]_jj, its variance not
/// explained by the other columns) the correction leaves.
const KEPT_INFORMATION: f64 = 0.5;

/// 1/[G⁻¹]_jj of the `live` columns of `g`, `None` unless that block is
/// positive definite.
fn information(g: &DMatrix<f64>, live: &[usize]) -> Option<Vec<f64>> {
    let inv = g
        .select_rows(live)
        .select_columns(live)
        .cholesky()?
        .inverse();
    let info: Vec<f64> = inv.diagonal().iter().map(|v| 1.0 / v).collect();
    info.iter()
        .all(|v| v.is_finite() && *v > 0.0)
        .then_some(info)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_expected_excess_matches_the_filtered_variance() {
        // White unit errors, first-sample start: the sum of the exact
        // variance recursion v₀ = 1, v_{k+1} = a² v_k + c².
        let f = LambdaFilter::new(0.5, 0.1).unwrap();
        let noise = RegressorNoise {
            lag0: DMatrix::from_element(1, 1, 1.0),
            lag1: DMatrix::zeros(1, 1),
        };
        let n = 40;
        let mut v = 1.0;
        let mut sum = 0.0;
        for _ in 0..n {
            sum += v;
            v = f.a * f.a * v + f.c * f.c;
        }
        let got = expected_excess(&noise, &f, &[n], FilterInit::FirstSample)[(0, 0)];
        assert!((got - sum).abs() < 1e-12 * sum, "{got} against {sum}");
        // Trapezoid-held errors: stationary variance c²/(1−a²)·½(1 + a).
        let held = RegressorNoise::held_over_step(DMatrix::from_element(1, 1, 1.0));
        let long = expected_excess(&held, &f, &[1_000_000], FilterInit::Zero)[(0, 0)] / 1e6;
        let want = f.c * f.c / (1.0 - f.a * f.a) * 0.5 * (1.0 + f.a);
        assert!((long - want).abs() < 1e-5 * want);
    }

    #[test]
    fn an_excess_larger_than_the_data_is_applied_only_in_part() {
        let mut stats = RegressionStats::new(1, 2);
        stats.gram = DMatrix::from_row_slice(2, 2, &[4.0, 1.0, 1.0, 2.0]);
        let small = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, 0.5]);
        assert_eq!(compensate(&mut stats, &small), 1.0);
        assert_eq!(stats.gram[(0, 0)], 3.0);
        let huge = DMatrix::from_row_slice(2, 2, &[3.0, 0.0, 0.0, 0.0]);
        let share = compensate(&mut stats, &huge);
        assert!(share > 0.0 && share < 1.0, "share {share}");
        assert!(stats.gram[(0, 0)] >= 0.3 - 1e-12);
        let bad = DMatrix::from_element(2, 2, f64::NAN);
        assert_eq!(compensate(&mut stats, &bad), 0.0);
    }

    /// A regressor identically zero (τ_Y of an unforced sway) leaves the
    /// correction in force over the others; a column nearly explained by
    /// another (information 1 − 1.9²/4 = 0.0975 of its 1) is corrected
    /// only as far as half its information stays: the whole 0.05 would
    /// leave 0.0475, half of it 0.0725.
    #[test]
    fn a_zero_column_does_not_void_the_correction_and_collinear_ones_keep_half() {
        let mut stats = RegressionStats::new(1, 3);
        stats.gram = DMatrix::from_row_slice(3, 3, &[4.0, 1.9, 0.0, 1.9, 1.0, 0.0, 0.0, 0.0, 0.0]);
        let mut excess = DMatrix::zeros(3, 3);
        excess[(1, 1)] = 0.05;
        assert_eq!(compensate(&mut stats, &excess), 0.5);
        assert!((stats.gram[(1, 1)] - 0.975).abs() < 1e-15);
        assert_eq!(stats.gram[(2, 2)], 0.0);
        assert_eq!(stats.gram[(0, 0)], 4.0);
        // Away from collinearity the whole excess is taken.
        stats.gram = DMatrix::from_row_slice(3, 3, &[4.0, 0.2, 0.0, 0.2, 1.0, 0.0, 0.0, 0.0, 0.0]);
        assert_eq!(compensate(&mut stats, &excess), 1.0);
        assert!((stats.gram[(1, 1)] - 0.95).abs() < 1e-15);
    }
}
