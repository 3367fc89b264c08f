//! Fisher information of the λ-filter regression before any run is flown.
//!
//! For the regression ν_k = θᵀφ_k + ε_k with white ε of variance σ², the
//! information about θ is Σφφᵀ / σ² (the Gram matrix of the filtered
//! regressors, each run's initial transient profiled out as the
//! identification does): the quantity a D-optimal experiment design
//! maximises. Every output row shares one Gram matrix, so it alone ranks
//! designs; σ only scales it.

use nalgebra::DMatrix;

use super::error::LambdaError;
use super::experiment::Experiment;
use super::filter::{FilterInit, LambdaFilter};
use super::regressors::RunRegressors;
use super::statistics::RegressionStats;

/// Σφφᵀ of `runs` (p × p, p = 2n + q) filtered through λ with time
/// constant `t_lambda` (s), each run's transient profiled out, and the
/// number of samples it holds.
///
/// # Errors
/// No run, runs of differing sample time or shape, or a filter that cannot
/// be built at their sample time.
pub fn regression_information(
    runs: &[Experiment],
    t_lambda: f64,
) -> Result<(DMatrix<f64>, usize), LambdaError> {
    let first = runs
        .first()
        .ok_or_else(|| LambdaError::too_few("runs", "no run to take information from"))?;
    let n = first.nu.ncols();
    let q = first.exogenous.ncols();
    let f = LambdaFilter::new(t_lambda, first.h)?;
    let mut stats = RegressionStats::new(n, 2 * n + q);
    for (i, run) in runs.iter().enumerate() {
        if run.h != first.h
            || run.nu.ncols() != n
            || run.gamma.ncols() != n
            || run.exogenous.ncols() != q
        {
            return Err(LambdaError::invalid(
                format!("runs[{i}]"),
                "runs differ in sample time or columns",
            ));
        }
        stats.add(&RunRegressors::new(run, &f, FilterInit::FirstSample), true);
    }
    Ok((stats.gram, stats.n_samples))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Information is additive over runs and scales with the square of the
    /// input amplitude (γ columns).
    #[test]
    fn information_adds_over_runs_and_grows_with_amplitude_squared() {
        let h = 0.1;
        let n_s = 400;
        let run = |amp: f64| {
            let gamma = DMatrix::from_fn(n_s, 1, |k, _| if (k / 37) % 2 == 0 { amp } else { -amp });
            let mut nu = DMatrix::zeros(n_s, 1);
            for k in 1..n_s {
                nu[(k, 0)] = 0.9 * nu[(k - 1, 0)] + 0.1 * gamma[(k - 1, 0)];
            }
            Experiment::new(h, nu, gamma)
        };
        let (g1, s1) = regression_information(&[run(1.0)], 0.5).unwrap();
        let (g2, s2) = regression_information(&[run(1.0), run(1.0)], 0.5).unwrap();
        let (g3, _) = regression_information(&[run(3.0)], 0.5).unwrap();
        assert_eq!(s2, 2 * s1);
        assert!((&g2 - &g1 * 2.0).norm() <= 1e-9 * g2.norm());
        assert!((&g3 - &g1 * 9.0).norm() <= 1e-9 * g3.norm());
        assert!(g1.determinant() > 0.0);
        assert!(regression_information(&[], 0.5).is_err());
    }
}
