//! One sea-trial run as the λ-filter identification sees it, and the checks
//! that a set of runs can be identified together.

use nalgebra::DMatrix;

use super::error::{LambdaError, require_finite_matrix, require_positive};

/// One run: body velocities ν and generalized forces γ = τ − g(η)
/// (thesis eq. 2.8), sampled at h, one row per sample, one column per DOF
/// (in the order of the settings' `dofs`).
///
/// Several runs are a multi-experiment set: each keeps its own filter
/// initial state and its own initial transient; they are never concatenated.
#[derive(Debug, Clone, PartialEq)]
pub struct Experiment {
    /// Sample time h (s).
    pub h: f64,
    /// Body velocities ν, N × n.
    pub nu: DMatrix<f64>,
    /// Generalized forces γ = τ − g(η), N × n, held over each sample
    /// interval (zero-order hold).
    pub gamma: DMatrix<f64>,
    /// Known functions e(t) whose force coefficients F are estimated with
    /// M and D̄ (M ν̇ + D̄ ν + F e = γ): N × q, held like γ; q = 0 for none.
    /// E.g. e = [1, sin θ, cos θ sin φ] for constant loads and g(η).
    pub exogenous: DMatrix<f64>,
}

impl Experiment {
    /// A run without exogenous functions (q = 0).
    pub fn new(h: f64, nu: DMatrix<f64>, gamma: DMatrix<f64>) -> Self {
        let rows = nu.nrows();
        Experiment {
            h,
            nu,
            gamma,
            exogenous: DMatrix::zeros(rows, 0),
        }
    }

    /// Number of samples N.
    pub fn len(&self) -> usize {
        self.nu.nrows()
    }

    /// True when the run holds no sample.
    pub fn is_empty(&self) -> bool {
        self.nu.nrows() == 0
    }
}

/// Relative tolerance on equal sample times across runs.
const H_REL_TOL: f64 = 1e-9;

/// Checks `runs` (named `field[i]`) for `n` DOFs and `q` exogenous
/// functions with at least `min_len` samples each, and returns their common
/// sample time h.
///
/// # Errors
/// No run; h not finite or ≤ 0, or differing between runs; ν or γ not
/// N × n or of different lengths; NaN/∞ samples; a run shorter than
/// `min_len`.
pub(crate) fn validate_runs(
    field: &str,
    runs: &[Experiment],
    n: usize,
    q: usize,
    min_len: usize,
) -> Result<f64, LambdaError> {
    let Some(first) = runs.first() else {
        return Err(LambdaError::too_few(field, "no run given"));
    };
    let h = first.h;
    for (i, run) in runs.iter().enumerate() {
        let f = |name: &str| format!("{field}[{i}].{name}");
        require_positive(&f("h"), run.h)?;
        if (run.h - h).abs() > H_REL_TOL * h {
            return Err(LambdaError::invalid(
                f("h"),
                format!(
                    "sample time {} s differs from the first run's {h} s; resample the runs to one h",
                    run.h
                ),
            ));
        }
        if run.nu.ncols() != n {
            return Err(LambdaError::shape(
                f("nu"),
                format!("has {} columns, expected one per DOF ({n})", run.nu.ncols()),
            ));
        }
        if run.gamma.ncols() != n {
            return Err(LambdaError::shape(
                f("gamma"),
                format!(
                    "has {} columns, expected one per DOF ({n})",
                    run.gamma.ncols()
                ),
            ));
        }
        if run.gamma.nrows() != run.nu.nrows() {
            return Err(LambdaError::shape(
                f("gamma"),
                format!(
                    "has {} rows but nu has {}",
                    run.gamma.nrows(),
                    run.nu.nrows()
                ),
            ));
        }
        if run.exogenous.nrows() != run.nu.nrows() || run.exogenous.ncols() != q {
            return Err(LambdaError::shape(
                f("exogenous"),
                format!(
                    "is {}×{}, expected {}×{q} (the rows of nu, the columns of the settings' exogenous functions)",
                    run.exogenous.nrows(),
                    run.exogenous.ncols(),
                    run.nu.nrows()
                ),
            ));
        }
        require_finite_matrix(&f("nu"), &run.nu)?;
        require_finite_matrix(&f("gamma"), &run.gamma)?;
        require_finite_matrix(&f("exogenous"), &run.exogenous)?;
        if run.len() < min_len {
            return Err(LambdaError::too_few(
                f("nu"),
                format!("{} samples, at least {min_len} needed", run.len()),
            ));
        }
    }
    Ok(h)
}
