//! The filtered regressors of one run, shared by every output row:
//! φ_k = [[λν]_k; [λγ]_k; [λe]_k] (2n + q entries) and the transient shape
//! ψ_k = a^k.

use nalgebra::DMatrix;

use super::experiment::Experiment;
use super::filter::{FilterInit, LambdaFilter};

/// One run filtered through λ: row k of `phi` is φ_kᵀ.
pub(crate) struct RunRegressors<'a> {
    /// N × (2n + q): [λν], [λγ], then the exogenous functions [λe].
    pub phi: DMatrix<f64>,
    /// ψ_k = a^k, the initial-condition transient of the regression.
    pub psi: Vec<f64>,
    /// The regressands ν (N × n), borrowed from the run.
    pub y: &'a DMatrix<f64>,
}

impl<'a> RunRegressors<'a> {
    /// Filters ν and γ of `run`, each from its own initial state.
    pub fn new(run: &'a Experiment, f: &LambdaFilter, init: FilterInit) -> Self {
        let (n_s, n) = run.nu.shape();
        let q = run.exogenous.ncols();
        let mut phi = DMatrix::zeros(n_s, 2 * n + q);
        phi.columns_mut(0, n).copy_from(&f.apply(&run.nu, init));
        phi.columns_mut(n, n).copy_from(&f.apply(&run.gamma, init));
        if q > 0 {
            phi.columns_mut(2 * n, q)
                .copy_from(&f.apply(&run.exogenous, init));
        }
        RunRegressors {
            phi,
            psi: f.transient(n_s),
            y: &run.nu,
        }
    }
}
