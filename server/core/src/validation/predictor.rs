//! The one interface every identified model offers to validation.
//!
//! Convention: a record's signals are matrices with one row per sample and one
//! column per channel (N × m inputs, N × p outputs), column-major, so each
//! channel is a contiguous slice.

use nalgebra::DMatrix;

/// A recorded run on a uniform grid, as validation sees it.
#[derive(Debug, Clone, Copy)]
pub struct ValidationRecord<'a> {
    /// Sample time h (s).
    pub h: f64,
    /// Inputs, N × m (e.g. γ = τ − g(η), or thruster commands u).
    pub u: &'a DMatrix<f64>,
    /// Measured outputs, N × p (e.g. ν, or η for a DP ship).
    pub y: &'a DMatrix<f64>,
}

/// A model that predicts the outputs of a record from its inputs.
pub trait Predictor {
    /// Names of the output channels, in column order of `y`.
    fn output_names(&self) -> Vec<String>;

    /// k-step-ahead predictions ŷ(t | t−k) (k ≥ 1), N × p: the model is
    /// started from the measured (or estimated) state at t−k and run k steps on
    /// the recorded inputs. Rows t < k are NaN (no prediction exists).
    fn predict_k_step(&self, rec: &ValidationRecord<'_>, k: usize) -> DMatrix<f64>;

    /// Free-run simulation ŷ(t) from the record's initial condition on the
    /// recorded inputs alone (thesis eq. 2.20–2.21), N × p.
    fn simulate(&self, rec: &ValidationRecord<'_>) -> DMatrix<f64>;
}
