//! The λ-filter Kalman identification of one operating point (thesis
//! sec. 2.5): filter ν and γ through λ, estimate [A_λ B_λ] row by row with
//! a Kalman filter over the parameters started at the rigid-body prior, map
//! back to A, B and to M, D̄, and propagate the uncertainty.

use nalgebra::{DMatrix, DVector};

use super::error::{LambdaError, require_finite_matrix};
use super::errors_in_variables::{compensate, expected_excess};
use super::estimate::{LambdaEstimate, UncertaintyMethod};
use super::experiment::{Experiment, validate_runs};
use super::filter::LambdaFilter;
use super::kalman::kalman_row;
use super::posterior::{RowPosterior, apply_sandwich, residual_dof, row_posterior, rss};
use super::regressors::RunRegressors;
use super::robust::{LAG_IN_T, long_run_score_covariance};
use super::settings::{LambdaSettings, MIN_T_OVER_H};
use super::statistics::RegressionStats;
use super::structure::CouplingMask;
use super::symmetric::constrain_symmetric;
use super::transform::{physical, state_space, to_lambda};
use super::uncertainty::{Stacked, delta_method_cov};
use crate::estimation::{NoProgress, Progress};

/// Identifies M ν̇ + D̄ ν = γ from a multi-experiment set of runs at one
/// operating point. See [`identify_with_progress`].
///
/// # Errors
/// As [`identify_with_progress`] (never [`LambdaError::Cancelled`]).
pub fn identify(
    runs: &[Experiment],
    settings: &LambdaSettings,
) -> Result<LambdaEstimate, LambdaError> {
    identify_with_progress(runs, settings, &mut NoProgress)
}

/// Prior mean θ₀ and variances of every row (full 2n regressor order).
struct RowPriors {
    theta0: Vec<DVector<f64>>,
    p0: Vec<DVector<f64>>,
}

/// Validates the settings for n DOFs and a sample time h.
fn validate_settings(s: &LambdaSettings, n: usize) -> Result<CouplingMask, LambdaError> {
    if n == 0 {
        return Err(LambdaError::shape("settings.dofs", "no DOF given"));
    }
    for (i, d) in s.dofs.iter().enumerate() {
        if s.dofs[..i].contains(d) {
            return Err(LambdaError::invalid(
                format!("settings.dofs[{i}]"),
                format!("{} appears twice", d.name()),
            ));
        }
    }
    super::error::require_positive("settings.t_lambda", s.t_lambda)?;
    let mask = s.structure.mask(n);
    mask.validate(n)?;
    for (name, m) in [
        ("settings.prior.m0", &s.prior.m0),
        ("settings.prior.d_bar0", &s.prior.d_bar0),
    ] {
        if m.shape() != (n, n) {
            return Err(LambdaError::shape(
                name,
                format!("is {}×{}, expected {n}×{n}", m.nrows(), m.ncols()),
            ));
        }
        require_finite_matrix(name, m)?;
    }
    super::error::require_positive("settings.prior.a_lambda_std", s.prior.a_lambda_std)?;
    super::error::require_positive("settings.prior.b_lambda_rel_std", s.prior.b_lambda_rel_std)?;
    if let Some(r) = &s.noise_variance {
        if r.len() != n {
            return Err(LambdaError::shape(
                "settings.noise_variance",
                format!("has {} entries, expected one per DOF ({n})", r.len()),
            ));
        }
        for (i, &v) in r.iter().enumerate() {
            super::error::require_positive(&format!("settings.noise_variance[{i}]"), v)?;
        }
    }
    if let Some(x) = &s.exogenous {
        let q = x.names.len();
        if x.pattern.shape() != (n, q) {
            return Err(LambdaError::shape(
                "settings.exogenous.pattern",
                format!(
                    "is {}×{}, expected {n}×{q} (DOFs × functions)",
                    x.pattern.nrows(),
                    x.pattern.ncols()
                ),
            ));
        }
        if x.force_std.len() != n {
            return Err(LambdaError::shape(
                "settings.exogenous.force_std",
                format!(
                    "has {} entries, expected one per DOF ({n})",
                    x.force_std.len()
                ),
            ));
        }
        for (i, &v) in x.force_std.iter().enumerate() {
            super::error::require_positive(&format!("settings.exogenous.force_std[{i}]"), v)?;
        }
    }
    if !(s.random_walk.is_finite() && s.random_walk >= 0.0) {
        return Err(LambdaError::invalid(
            "settings.random_walk",
            format!("must be finite and ≥ 0, got {}", s.random_walk),
        ));
    }
    Ok(mask)
}

/// θ₀ = [A_λ0 B_λ0 0] from (M₀, D̄₀) and the dimensionally scaled stds;
/// the exogenous block K_λ = −B_λ F starts at 0 with the std of T·B₀ᵢᵢ·σ_F.
fn priors(s: &LambdaSettings, f: &LambdaFilter) -> Result<RowPriors, LambdaError> {
    let n = s.dofs.len();
    let q = s.exogenous.as_ref().map_or(0, |x| x.names.len());
    let (a0, b0) = state_space(&s.prior.m0, &s.prior.d_bar0, "settings.prior.m0")?;
    if let Some(i) = (0..n).find(|&i| b0[(i, i)] <= 0.0 || !b0[(i, i)].is_finite()) {
        return Err(LambdaError::invalid(
            "settings.prior.m0",
            format!("diagonal entry {i} of M₀⁻¹ is not positive: M₀ is not a mass matrix"),
        ));
    }
    let (al0, bl0) = to_lambda(&a0, &b0, f, s.inversion)?;
    let sa = s.prior.a_lambda_std;
    let sb = s.prior.b_lambda_rel_std * s.t_lambda;
    let mut theta0 = Vec::with_capacity(n);
    let mut p0 = Vec::with_capacity(n);
    for i in 0..n {
        theta0.push(DVector::from_fn(2 * n + q, |j, _| {
            if j < n {
                al0[(i, j)]
            } else if j < 2 * n {
                bl0[(i, j - n)]
            } else {
                0.0
            }
        }));
        p0.push(DVector::from_fn(2 * n + q, |j, _| {
            let sd = if j < n {
                sa * (b0[(i, i)] / b0[(j, j)]).sqrt()
            } else if j < 2 * n {
                let j = j - n;
                sb * (b0[(i, i)] * b0[(j, j)]).sqrt()
            } else {
                let x = s.exogenous.as_ref().expect("q > 0 only with exogenous");
                s.t_lambda * b0[(i, i)] * x.force_std[i]
            };
            sd * sd
        }));
    }
    Ok(RowPriors { theta0, p0 })
}

/// Identifies M ν̇ + D̄ ν = γ from a multi-experiment set of runs at one
/// operating point, reporting progress per DOF and honouring cancellation.
///
/// Each run is filtered through λ from its own initial state; the
/// parameter posterior is carried across runs (never concatenating the
/// signals). With `random_walk = 0` the Kalman filter's end state is
/// computed in information form from statistics shared by all rows; with
/// `random_walk > 0` the covariance-form filter runs sample by sample.
///
/// # Errors
/// Typed, naming the field: shapes (`runs[i].nu`, `runs[i].gamma`,
/// `settings.prior.m0`, `structure.a` …), NaN (`runs[i].nu` with the row),
/// too few samples, T ≤ 0 or T < [`MIN_T_OVER_H`]·h (`settings.t_lambda`),
/// singular prior mass (`settings.prior.m0`), singular estimated B (`b`),
/// an estimate that is no sampled continuous model (`a_lambda`), and
/// [`LambdaError::Cancelled`].
pub fn identify_with_progress(
    runs: &[Experiment],
    settings: &LambdaSettings,
    progress: &mut dyn Progress,
) -> Result<LambdaEstimate, LambdaError> {
    let n = settings.dofs.len();
    let mask = validate_settings(settings, n)?;
    let q = settings.exogenous.as_ref().map_or(0, |x| x.names.len());
    let p = 2 * n + q;
    // Each run must at least outnumber the regressors plus its transient.
    let h = validate_runs("runs", runs, n, q, p + 2)?;
    if settings.t_lambda < MIN_T_OVER_H * h {
        return Err(LambdaError::invalid(
            "settings.t_lambda",
            format!(
                "T = {} s is not ≫ h = {h} s (need T ≥ {MIN_T_OVER_H}·h)",
                settings.t_lambda
            ),
        ));
    }
    let f = LambdaFilter::new(settings.t_lambda, h)?;
    let pri = priors(settings, &f)?;

    let mut stats = RegressionStats::new(n, p);
    let mut filtered = Vec::with_capacity(runs.len());
    let kf = settings.random_walk > 0.0;
    for (r, run) in runs.iter().enumerate() {
        progress.update(0.5 * r as f64 / runs.len() as f64, "λ-filtering runs")?;
        let reg = RunRegressors::new(run, &f, settings.filter_init);
        stats.add(&reg, settings.estimate_transient);
        filtered.push(reg);
    }
    if let Some(noise) = settings.regressor_noise.as_ref().filter(|_| !kf) {
        let p_all = noise.lag0.nrows();
        if p_all != p || noise.lag0.ncols() != p || noise.lag1.shape() != (p, p) {
            return Err(LambdaError::invalid(
                "settings.regressor_noise",
                format!(
                    "must be {p} × {p} (2n + q), got {p_all} × {}",
                    noise.lag0.ncols()
                ),
            ));
        }
        let lengths: Vec<usize> = runs.iter().map(|r| r.nu.nrows()).collect();
        let excess = expected_excess(noise, &f, &lengths, settings.filter_init);
        compensate(&mut stats, &excess);
    }
    let lag = (LAG_IN_T * settings.t_lambda / h).ceil() as usize;
    let free: Vec<Vec<usize>> = (0..n)
        .map(|i| free_of_row(&mask, settings.exogenous.as_ref(), i))
        .collect();
    if let Some(i) = (0..n).find(|&i| residual_dof(&stats, free[i].len()) < 1.0) {
        return Err(LambdaError::too_few(
            "runs",
            format!(
                "{} samples over {} runs leave no residual degree of freedom for the {} parameters of row {i}",
                stats.n_samples,
                runs.len(),
                free[i].len()
            ),
        ));
    }

    let mut rows: Vec<RowPosterior> = Vec::with_capacity(n);
    for i in 0..n {
        progress.update(
            0.5 + 0.4 * i as f64 / n as f64,
            &format!("estimating {}", settings.dofs[i].name()),
        )?;
        let noise = settings.noise_variance.as_ref().map(|r| r[i]);
        let mut row = row_posterior(&stats, i, &free[i], &pri.theta0[i], &pri.p0[i], noise)?;
        if kf {
            row = kalman_pass(&filtered, i, &free[i], &pri, &row, &f, settings, &stats)?;
        } else if settings.robust_covariance {
            let theta_s = DVector::from_fn(free[i].len(), |a, _| row.theta[free[i][a]]);
            let omega = long_run_score_covariance(
                &filtered,
                i,
                &free[i],
                &theta_s,
                settings.estimate_transient,
                lag,
            );
            apply_sandwich(&mut row, &free[i], &pri.p0[i], &omega);
        }
        rows.push(row);
    }
    progress.update(0.9, "mapping to M, D̄")?;

    let blocks = mask.blocks();
    let mut theta = DMatrix::from_fn(n, p, |i, j| rows[i].theta[j]);
    let stacked = Stacked::new(&free);
    let mut cov = stacked.block_covariance(&rows);
    let symmetry = if settings.symmetric_inertia {
        constrain_symmetric(
            &mut theta,
            &stacked,
            &mut cov,
            settings.inertia_offset.as_ref(),
            &f,
            settings.inversion,
            &blocks,
        )
    } else {
        None
    };
    if let Some(s) = symmetry {
        cov *= s.inflation().powi(2);
    }
    let a_lambda = theta.columns(0, n).into_owned();
    let b_lambda = theta.columns(n, n).into_owned();
    let k_lambda = theta.columns(2 * n, q).into_owned();
    let [a, b, m, d_bar, _, force] = physical(
        &a_lambda,
        &b_lambda,
        &k_lambda,
        &f,
        settings.inversion,
        &blocks,
    )?;
    let [std_a, std_b, std_m, std_d_bar, _, std_force] =
        delta_method_cov(&theta, &stacked, &cov, &f, settings.inversion, &blocks);
    // Each row's block of the (possibly constrained) joint covariance.
    let param_cov: Vec<DMatrix<f64>> = (0..n)
        .map(|i| {
            let mut c = DMatrix::zeros(p, p);
            for (a, &(ia, ja)) in stacked.index.iter().enumerate() {
                for (b, &(ib, jb)) in stacked.index.iter().enumerate() {
                    if ia == i && ib == i {
                        c[(ja, jb)] = cov[(a, b)];
                    }
                }
            }
            c
        })
        .collect();
    progress.update(1.0, "done")?;
    Ok(LambdaEstimate {
        dofs: settings.dofs.clone(),
        t_lambda: settings.t_lambda,
        h,
        inversion: settings.inversion,
        mask,
        a_lambda,
        b_lambda,
        a,
        b,
        m,
        d_bar,
        param_cov,
        std_a,
        std_b,
        std_m,
        std_d_bar,
        exogenous: settings
            .exogenous
            .as_ref()
            .map_or_else(Vec::new, |x| x.names.clone()),
        k_lambda,
        force,
        std_force,
        uncertainty: UncertaintyMethod::DeltaMethod,
        residual_variance: rows.iter().map(|r| r.residual_variance).collect(),
        noise_variance: rows.iter().map(|r| r.noise_variance).collect(),
        n_samples: stats.n_samples,
        n_runs: runs.len(),
        symmetry,
    })
}

/// Free regressors of row `i`: the mask's entries of [A_λ B_λ] and the
/// exogenous columns 2n + j that reach row i through a free B entry
/// (K_λ = −B_λ F mixes the rows of F that B couples).
fn free_of_row(
    mask: &CouplingMask,
    exogenous: Option<&super::settings::Exogenous>,
    i: usize,
) -> Vec<usize> {
    let n = mask.n();
    let mut free = mask.free_of_row(i);
    if let Some(x) = exogenous {
        for j in 0..x.names.len() {
            if (0..n).any(|l| mask.b[(i, l)] && x.pattern[(l, j)]) {
                free.push(2 * n + j);
            }
        }
    }
    free
}

/// The covariance-form Kalman filter with random-walk parameters for row
/// `i`, using the noise variance of the constant-parameter posterior.
#[allow(clippy::too_many_arguments)]
fn kalman_pass(
    filtered: &[RunRegressors<'_>],
    i: usize,
    free: &[usize],
    pri: &RowPriors,
    constant: &RowPosterior,
    f: &LambdaFilter,
    settings: &LambdaSettings,
    stats: &RegressionStats,
) -> Result<RowPosterior, LambdaError> {
    let k = free.len();
    let theta0 = DVector::from_fn(k, |a, _| pri.theta0[i][free[a]]);
    let p0 = DMatrix::from_fn(k, k, |a, b| if a == b { pri.p0[i][free[a]] } else { 0.0 });
    let q = DVector::from_fn(k, |a, _| settings.random_walk * pri.p0[i][free[a]]);
    let r = constant.noise_variance;
    let transient = settings.estimate_transient.then_some(f.c);
    let (theta_s, cov_s) = kalman_row(filtered, i, free, theta0, p0, r, &q, transient);
    if theta_s.iter().chain(cov_s.iter()).any(|v| !v.is_finite()) {
        return Err(LambdaError::singular(
            "settings.random_walk",
            format!("the parameter Kalman filter of row {i} diverged"),
        ));
    }
    let p = pri.theta0[i].len();
    let mut theta = DVector::zeros(p);
    let mut cov = DMatrix::zeros(p, p);
    for (a, &ja) in free.iter().enumerate() {
        theta[ja] = theta_s[a];
        for (b, &jb) in free.iter().enumerate() {
            cov[(ja, jb)] = 0.5 * (cov_s[(a, b)] + cov_s[(b, a)]);
        }
    }
    let residual_variance = rss(stats, i, free, &theta_s) / residual_dof(stats, k).max(1.0);
    Ok(RowPosterior {
        theta,
        cov,
        noise_variance: r,
        residual_variance,
    })
}
