//! k-step prediction and free-run simulation of a discrete model whose state
//! is the measured output (ν is measured by the INS, thesis sec. 2.6), shared
//! by the single and the LPV vessel models.
//!
//! Timing: input row t is held over [t h, (t+1) h), so
//! ŷ(t+1 | t) = f(y(t), u(t)) (thesis eq. 2.16), and ŷ(t | t−k) applies k
//! steps to y(t−k) with u(t−k), …, u(t−1).

use nalgebra::{DMatrix, DVector};

use super::error::{ModelError, check_finite, check_sample_time};
use crate::validation::ValidationRecord;

/// Checks a record against a model with `m` inputs and `p` outputs.
pub(crate) fn check_record(
    rec: &ValidationRecord<'_>,
    m: usize,
    p: usize,
) -> Result<(), ModelError> {
    check_sample_time(rec.h)?;
    let n = rec.y.nrows();
    if rec.y.ncols() != p {
        return Err(ModelError::Shape {
            name: "y".into(),
            expected: format!("N×{p} (one column per modelled DOF)"),
            found: rec.y.shape(),
        });
    }
    if rec.u.shape() != (n, m) {
        return Err(ModelError::Shape {
            name: "u".into(),
            expected: format!("{n}×{m} (as many rows as y, one column per modelled DOF)"),
            found: rec.u.shape(),
        });
    }
    check_finite("y", rec.y.iter())?;
    check_finite("u", rec.u.iter())?;
    Ok(())
}

/// ŷ(t | t−k) for every t ≥ k; rows t < k are NaN.
pub(crate) fn k_step<F>(
    rec: &ValidationRecord<'_>,
    k: usize,
    mut step: F,
) -> Result<DMatrix<f64>, ModelError>
where
    F: FnMut(&DVector<f64>, &DVector<f64>) -> DVector<f64>,
{
    if k == 0 {
        return Err(ModelError::InvalidHorizon { k });
    }
    let (n, p) = rec.y.shape();
    let mut out = DMatrix::from_element(n, p, f64::NAN);
    for t in k..n {
        let mut x = rec.y.row(t - k).transpose();
        for i in t - k..t {
            x = step(&x, &rec.u.row(i).transpose());
        }
        out.row_mut(t).copy_from(&x.transpose());
    }
    Ok(out)
}

/// ŷ(0) = y(0), ŷ(t+1) = f(ŷ(t), u(t)) (thesis eq. 2.20–2.21).
pub(crate) fn free_run<F>(rec: &ValidationRecord<'_>, mut step: F) -> DMatrix<f64>
where
    F: FnMut(&DVector<f64>, &DVector<f64>) -> DVector<f64>,
{
    let (n, p) = rec.y.shape();
    let mut out = DMatrix::zeros(n, p);
    if n == 0 {
        return out;
    }
    let mut x = rec.y.row(0).transpose();
    out.row_mut(0).copy_from(&x.transpose());
    for t in 1..n {
        x = step(&x, &rec.u.row(t - 1).transpose());
        out.row_mut(t).copy_from(&x.transpose());
    }
    out
}

/// The trait's answer when the record does not fit the model: no prediction.
pub(crate) fn no_prediction(rec: &ValidationRecord<'_>, p: usize) -> DMatrix<f64> {
    DMatrix::from_element(rec.y.nrows(), p, f64::NAN)
}
