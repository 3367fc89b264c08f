//! The identified innovation-form model and its predictions.
//!
//! x(t+1) = A x(t) + B u(t) + K e(t),  y(t) = C x(t) + D u(t) + e(t),
//! E[e eᵀ] = the innovation covariance.

use nalgebra::{Complex, DMatrix, DVector};

use super::continuous::{ContinuousModel, D2cError, d2c};
use super::settings::Weighting;
use crate::models::predict::no_prediction;
use crate::validation::{Predictor, ValidationRecord};

/// Residual covariances of the state-space least squares: process ρ_w and
/// measurement ρ_v (Van Overschee & De Moor's Q, S, R).
#[derive(Debug, Clone, PartialEq)]
pub struct NoiseCovariances {
    /// E[ρ_w ρ_wᵀ] (n × n).
    pub q: DMatrix<f64>,
    /// E[ρ_w ρ_vᵀ] (n × l).
    pub s: DMatrix<f64>,
    /// E[ρ_v ρ_vᵀ] (l × l).
    pub r: DMatrix<f64>,
}

/// A discrete-time model identified by N4SID, in innovation form.
#[derive(Debug, Clone, PartialEq)]
pub struct N4sidModel {
    /// State matrix (n × n).
    pub a: DMatrix<f64>,
    /// Input matrix (n × m).
    pub b: DMatrix<f64>,
    /// Output matrix (l × n).
    pub c: DMatrix<f64>,
    /// Feedthrough (l × m); zero unless estimated.
    pub d: DMatrix<f64>,
    /// Innovation-form Kalman gain (n × l).
    pub k: DMatrix<f64>,
    /// Sample time h (s).
    pub h: f64,
    /// Model order n.
    pub order: usize,
    /// Horizon i (block rows) used.
    pub horizon: usize,
    /// Weighting used.
    pub weighting: Weighting,
    /// Singular values of W₁ O_i W₂ (descending), for the order choice.
    pub singular_values: Vec<f64>,
    /// Residual covariances of the state-space fit.
    pub noise: NoiseCovariances,
    /// Innovation covariance E[e eᵀ] (l × l).
    pub innovation_covariance: DMatrix<f64>,
    /// Steady-state prediction error covariance P (n × n).
    pub state_covariance: DMatrix<f64>,
    /// Hankel columns used (all experiments).
    pub hankel_columns: usize,
    /// Output channel names (default "y0", "y1", …).
    pub output_names: Vec<String>,
}

/// Samples used by [`N4sidModel::estimate_initial_state`] per state
/// (at least [`X0_MIN_SAMPLES`]): enough to average the noise, short enough
/// that A^t stays well scaled.
pub const X0_SAMPLES_PER_STATE: usize = 10;
/// Lower bound of the samples used for x0.
pub const X0_MIN_SAMPLES: usize = 50;

impl N4sidModel {
    /// Inputs m.
    pub fn inputs(&self) -> usize {
        self.b.ncols()
    }

    /// Outputs l.
    pub fn outputs(&self) -> usize {
        self.c.nrows()
    }

    /// Eigenvalues of A (discrete poles).
    pub fn eigenvalues(&self) -> Vec<Complex<f64>> {
        if self.order == 0 {
            return Vec::new();
        }
        self.a.complex_eigenvalues().iter().copied().collect()
    }

    /// Markov parameters D, CB, CAB, …, CA^{count−2}B (basis-free transfer
    /// function of u → y), `count` matrices l × m.
    pub fn markov_parameters(&self, count: usize) -> Vec<DMatrix<f64>> {
        let mut out = Vec::with_capacity(count);
        if count == 0 {
            return out;
        }
        out.push(self.d.clone());
        let mut ab = self.b.clone();
        for _ in 1..count {
            out.push(&self.c * &ab);
            ab = &self.a * ab;
        }
        out
    }

    /// Continuous-time A_c, B_c with the same C, D (ZOH inverse, see
    /// [`d2c`]).
    pub fn continuous(&self) -> Result<ContinuousModel, D2cError> {
        let (a, b) = d2c(&self.a, &self.b, self.h)?;
        Ok(ContinuousModel {
            a,
            b,
            c: self.c.clone(),
            d: self.d.clone(),
        })
    }

    /// Deterministic response from x0 (outputs N × l).
    pub fn simulate_from(&self, u: &DMatrix<f64>, x0: &DVector<f64>) -> DMatrix<f64> {
        let mut y = DMatrix::zeros(u.nrows(), self.outputs());
        let mut x = x0.clone();
        for t in 0..u.nrows() {
            let ut = u.row(t).transpose();
            let yt = &self.c * &x + &self.d * &ut;
            y.row_mut(t).copy_from(&yt.transpose());
            x = &self.a * &x + &self.b * &ut;
        }
        y
    }

    /// Initial state of a record by least squares on its first
    /// max(X0_MIN_SAMPLES, X0_SAMPLES_PER_STATE · n) samples (all if
    /// fewer): y(t) − y_{x0=0}(t) = C Aᵗ x0.
    pub fn estimate_initial_state(&self, u: &DMatrix<f64>, y: &DMatrix<f64>) -> DVector<f64> {
        let n = self.order;
        let l = self.outputs();
        let len = u
            .nrows()
            .min(y.nrows())
            .min((X0_SAMPLES_PER_STATE * n).max(X0_MIN_SAMPLES));
        if n == 0 || len == 0 {
            return DVector::zeros(n);
        }
        let u0 = u.rows(0, len).into_owned();
        let forced = self.simulate_from(&u0, &DVector::zeros(n));
        let mut phi = DMatrix::zeros(len * l, n);
        let mut rhs = DVector::zeros(len * l);
        let mut cat = self.c.clone();
        for t in 0..len {
            phi.rows_mut(t * l, l).copy_from(&cat);
            for ch in 0..l {
                rhs[t * l + ch] = y[(t, ch)] - forced[(t, ch)];
            }
            cat = &cat * &self.a;
        }
        let svd = phi.svd(true, true);
        let tol = svd.singular_values.max() * 1e-12;
        svd.solve(&rhs, tol).unwrap_or_else(|_| DVector::zeros(n))
    }

    /// One-step predictor states x̂(t | t−1), t = 0..N, from x̂(0|−1) = x0.
    fn filter_states(
        &self,
        u: &DMatrix<f64>,
        y: &DMatrix<f64>,
        x0: &DVector<f64>,
    ) -> Vec<DVector<f64>> {
        let mut xs = Vec::with_capacity(u.nrows());
        let mut x = x0.clone();
        for t in 0..u.nrows() {
            xs.push(x.clone());
            let ut = u.row(t).transpose();
            let e = y.row(t).transpose() - &self.c * &x - &self.d * &ut;
            x = &self.a * &x + &self.b * &ut + &self.k * e;
        }
        xs
    }

    fn fits_record(&self, rec: &ValidationRecord<'_>) -> bool {
        rec.u.ncols() == self.inputs()
            && rec.y.ncols() == self.outputs()
            && rec.u.nrows() == rec.y.nrows()
    }
}

impl Predictor for N4sidModel {
    fn output_names(&self) -> Vec<String> {
        self.output_names.clone()
    }

    /// ŷ(t | t−k): the Kalman predictor (gain K) runs on the record up to
    /// t−k from the least-squares x0, then the model runs k−1 steps on the
    /// inputs alone. Rows t < k are NaN; k = 0 is taken as 1. A record whose
    /// shape does not match the model gives all NaN.
    fn predict_k_step(&self, rec: &ValidationRecord<'_>, k: usize) -> DMatrix<f64> {
        let k = k.max(1);
        let n_rows = rec.y.nrows();
        let mut out = DMatrix::from_element(n_rows, self.outputs(), f64::NAN);
        if !self.fits_record(rec) {
            return out;
        }
        let x0 = self.estimate_initial_state(rec.u, rec.y);
        let xs = self.filter_states(rec.u, rec.y, &x0);
        for t in k..n_rows {
            // x̂(t−k+1 | t−k), then k−1 open-loop steps.
            let mut x = xs[t + 1 - k].clone();
            for s in t + 1 - k..t {
                x = &self.a * x + &self.b * rec.u.row(s).transpose();
            }
            let yt = &self.c * x + &self.d * rec.u.row(t).transpose();
            out.row_mut(t).copy_from(&yt.transpose());
        }
        out
    }

    /// Free run on the inputs from the least-squares initial state of the
    /// record ([`N4sidModel::estimate_initial_state`]).
    fn simulate(&self, rec: &ValidationRecord<'_>) -> DMatrix<f64> {
        if !self.fits_record(rec) {
            return no_prediction(rec, self.outputs());
        }
        let x0 = self.estimate_initial_state(rec.u, rec.y);
        self.simulate_from(rec.u, &x0)
    }
}
