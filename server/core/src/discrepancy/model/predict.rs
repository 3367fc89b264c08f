//! Running a model over a record: its state between samples, the free
//! run and the k-step predictions, and the augmented model as a validation
//! [`Predictor`].

use nalgebra::DMatrix;

use super::AugmentedModel;
use crate::discrepancy::data::Record;
use crate::models::predict::no_prediction;
use crate::planning::Dof;
use crate::validation::{Predictor, ValidationRecord};

/// A free run over `rec` (N × n ν): from the measured state at 0, one
/// `step(k, x)` per sample interval.
pub(crate) fn free_run(
    rec: &Record,
    n: usize,
    measured: impl Fn(&Record, usize) -> State,
    mut step: impl FnMut(usize, &State) -> State,
) -> DMatrix<f64> {
    let len = rec.len();
    let mut out = DMatrix::zeros(len, n);
    if len == 0 {
        return out;
    }
    let mut x = measured(rec, 0);
    out.row_mut(0).copy_from_slice(&x.nu);
    for k in 0..len - 1 {
        x = step(k, &x);
        out.row_mut(k + 1).copy_from_slice(&x.nu);
    }
    out
}

/// k-step predictions over `rec` (rows t < k NaN): from the measured state
/// at t − k, k calls of `step`.
pub(crate) fn k_step(
    rec: &Record,
    n: usize,
    k: usize,
    measured: impl Fn(&Record, usize) -> State,
    mut step: impl FnMut(usize, &State) -> State,
) -> DMatrix<f64> {
    let len = rec.len();
    let k = k.max(1);
    let mut out = DMatrix::from_element(len, n, f64::NAN);
    for t in k..len {
        let mut x = measured(rec, t - k);
        for s in t - k..t {
            x = step(s, &x);
        }
        out.row_mut(t).copy_from_slice(&x.nu);
    }
    out
}

/// A model's state between samples: ν, and (φ, θ) when the attitude is in
/// the loop.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct State {
    pub nu: Vec<f64>,
    pub attitude: Option<[f64; 2]>,
}

impl State {
    pub(super) fn is_finite(&self) -> bool {
        self.nu
            .iter()
            .chain(self.attitude.iter().flatten())
            .all(|v| v.is_finite())
    }

    /// Σ wᵢ·xᵢ of states of the same shape (the LPV blend of predictions).
    pub(crate) fn blend(parts: &[(f64, State)]) -> State {
        let (w0, first) = &parts[0];
        let mut out = State {
            nu: first.nu.iter().map(|v| w0 * v).collect(),
            attitude: first.attitude.map(|a| a.map(|v| w0 * v)),
        };
        for (w, x) in &parts[1..] {
            out.nu.iter_mut().zip(&x.nu).for_each(|(o, v)| *o += w * v);
            if let (Some(o), Some(a)) = (out.attitude.as_mut(), x.attitude) {
                o[0] += w * a[0];
                o[1] += w * a[1];
            }
        }
        out
    }
}

/// The augmented model as a [`Predictor`]: a record's `u` holds [τ | η]
/// (n + 6 columns), `y` holds ν.
impl Predictor for AugmentedModel {
    fn output_names(&self) -> Vec<String> {
        Dof::velocity_symbols(&self.dofs)
    }

    fn predict_k_step(&self, rec: &ValidationRecord<'_>, k: usize) -> DMatrix<f64> {
        match Record::from_validation(self.dofs.len(), rec) {
            Some(r) => AugmentedModel::predict_k_step(self, &r, k),
            None => no_prediction(rec, self.dofs.len()),
        }
    }

    fn simulate(&self, rec: &ValidationRecord<'_>) -> DMatrix<f64> {
        match Record::from_validation(self.dofs.len(), rec) {
            Some(r) => AugmentedModel::simulate(self, &r),
            None => no_prediction(rec, self.dofs.len()),
        }
    }
}
