//! Sufficient statistics of the λ-filter regression over a set of runs.
//!
//! The Kalman filter over constant parameters (identity transition, no
//! process noise) is recursive least squares with a Gaussian prior; its
//! posterior after all samples equals the information-form solution
//! (P₀⁻¹ + ΣφφᵀR⁻¹)θ = P₀⁻¹θ₀ + ΣφyR⁻¹. Every output row of [A_λ B_λ]
//! regresses on the same φ_k, so one Gram matrix Σφφᵀ (one O(p²) update
//! per sample, as a single matrix product per run) serves all rows, any
//! mask, and any noise variance; the per-row solves are O(p³) once.
//!
//! Each run's transient e_k = a^k·e₀ (an unknown e₀ per run and row) is
//! profiled out exactly by a Schur complement on ψ_k = a^k, i.e. e₀ is
//! given a flat prior and marginalized, so the filters' initial states
//! cannot bias θ.

use nalgebra::DMatrix;

use super::regressors::RunRegressors;

/// Σφφᵀ, Σφyᵀ and Σy² over all runs (transients profiled out).
#[derive(Debug, Clone)]
pub(crate) struct RegressionStats {
    /// Σ φ φᵀ, p × p (p = 2n + q).
    pub gram: DMatrix<f64>,
    /// Σ φ yᵀ, p × n (column i for output row i).
    pub cross: DMatrix<f64>,
    /// Σ y_i², per output row.
    pub yy: Vec<f64>,
    /// Samples used.
    pub n_samples: usize,
    /// Nuisance parameters profiled out per row (one per run, or 0).
    pub n_nuisance: usize,
}

impl RegressionStats {
    /// Empty statistics for n DOFs and p regressors.
    pub fn new(n: usize, p: usize) -> Self {
        RegressionStats {
            gram: DMatrix::zeros(p, p),
            cross: DMatrix::zeros(p, n),
            yy: vec![0.0; n],
            n_samples: 0,
            n_nuisance: 0,
        }
    }

    /// Adds one run; with `transient` its e₀ is profiled out.
    pub fn add(&mut self, r: &RunRegressors<'_>, transient: bool) {
        let (n_s, p) = r.phi.shape();
        // X = [φ | ψ]: XᵀX and XᵀY by two matrix products (Σφφᵀ and Σφyᵀ
        // for every row at once), Σy² by column norms.
        let mut x = DMatrix::zeros(n_s, p + 1);
        x.columns_mut(0, p).copy_from(&r.phi);
        x.column_mut(p).copy_from_slice(&r.psi);
        let xx = x.tr_mul(&x);
        let xy = x.tr_mul(r.y);
        let mut g = xx.view((0, 0), (p, p)).into_owned();
        let mut c = xy.rows(0, p).into_owned();
        let mut yy: Vec<f64> = r.y.column_iter().map(|col| col.norm_squared()).collect();
        if transient {
            let s = xx[(p, p)];
            let gp = xx.view((0, p), (p, 1)).into_owned();
            let cy = xy.rows(p, 1).into_owned();
            g -= &gp * gp.transpose() / s;
            c -= &gp * &cy / s;
            for (i, v) in yy.iter_mut().enumerate() {
                *v -= cy[(0, i)] * cy[(0, i)] / s;
            }
            self.n_nuisance += 1;
        }
        self.gram += g;
        self.cross += c;
        for (acc, v) in self.yy.iter_mut().zip(yy) {
            *acc += v;
        }
        self.n_samples += n_s;
    }
}
