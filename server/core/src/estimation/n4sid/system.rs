//! A, B, C, D and the residual covariances by least squares on the states.
//!
//! X̂_i = Γ_i^† O_i = M W_p and X̂_{i+1} = Γ_{i−1}^† O_{i+1} = M⁺ W_p⁺ with
//! W_p⁺ = [U_{0|i}; Y_{0|i}]: both are rows of the same bank of
//! non-steady Kalman filters, so X̂_{i+1} = A X̂_i + B U_{i|i} + K_i E_i and
//! the residuals carry the innovation statistics (every window lies in one
//! Hankel column, so none spans two experiments). Then
//!
//! ```text
//!   [X̂_{i+1}]   [A B] [X̂_i    ]   [ρ_w]
//!   [Y_{i|i}] = [C D] [U_{i|i}] + [ρ_v]
//! ```
//!
//! in the least-squares sense (Van Overschee & De Moor 1996, sec. 4.3.1,
//! Algorithm 1). Every row is a combination of rows
//! of H = L Qᵀ, so the problem is solved on the r coordinates of L
//! (Q orthonormal): the cost does not depend on N. The residual covariance
//! [Q S; Sᵀ R] = [ρ_w; ρ_v][ρ_w; ρ_v]ᵀ / j.

use nalgebra::DMatrix;

use super::error::N4sidError;
use super::hankel::HankelLq;
use super::projection::{Subspace, next_state_map};

/// System matrices and residual covariances in the scaled coordinates.
#[derive(Debug, Clone)]
pub(crate) struct StateSpaceFit {
    pub a: DMatrix<f64>,
    pub b: DMatrix<f64>,
    pub c: DMatrix<f64>,
    pub d: DMatrix<f64>,
    /// Covariance of ρ_w (n × n).
    pub q: DMatrix<f64>,
    /// Cross covariance E[ρ_w ρ_vᵀ] (n × l).
    pub s: DMatrix<f64>,
    /// Covariance of ρ_v (l × l).
    pub r: DMatrix<f64>,
}

/// Rows of L selected by H-row indices.
fn rows_of(l: &DMatrix<f64>, rows: &[usize]) -> DMatrix<f64> {
    DMatrix::from_fn(rows.len(), l.ncols(), |a, b| l[(rows[a], b)])
}

/// Least squares X = lhs · rhs^† on the coordinates (rows are signals).
fn ls(lhs: &DMatrix<f64>, rhs: &DMatrix<f64>) -> Result<DMatrix<f64>, N4sidError> {
    // Solve rhsᵀ Xᵀ = lhsᵀ by SVD (tolerant to a rank-deficient rhs).
    let svd = rhs.transpose().svd(true, true);
    let tol = svd.singular_values.max() * 1e-13;
    let sol = svd
        .solve(&lhs.transpose(), tol)
        .map_err(|_| N4sidError::Numerical {
            step: "state least squares",
        })?;
    Ok(sol.transpose())
}

pub(crate) fn fit_state_space(
    lq: &HankelLq,
    sub: &Subspace,
    estimate_d: bool,
) -> Result<StateSpaceFit, N4sidError> {
    let lay = lq.layout;
    let (m, l, i, n) = (lay.m, lay.l, lay.i, sub.order);
    let mut past: Vec<usize> = (0..i)
        .flat_map(|k| (0..m).map(move |ch| lay.u_row(k, ch)))
        .collect();
    past.extend((0..i).flat_map(|k| (0..l).map(move |ch| lay.y_row(k, ch))));
    let x = &sub.state_map * rows_of(&lq.l, &past);
    let (next_map, next_rows) = next_state_map(lq, sub)?;
    let x1 = next_map * rows_of(&lq.l, &next_rows);
    let u: Vec<usize> = (0..m).map(|ch| lay.u_row(i, ch)).collect();
    let y: Vec<usize> = (0..l).map(|ch| lay.y_row(i, ch)).collect();
    let u = rows_of(&lq.l, &u);
    let y = rows_of(&lq.l, &y);
    let xu = stack(&x, &u);

    let ab = ls(&x1, &xu)?;
    let (a, b) = (ab.columns(0, n).into_owned(), ab.columns(n, m).into_owned());
    let (c, d) = if estimate_d {
        let cd = ls(&y, &xu)?;
        (cd.columns(0, n).into_owned(), cd.columns(n, m).into_owned())
    } else {
        (ls(&y, &x)?, DMatrix::zeros(l, m))
    };
    let rw = x1 - &a * &x - &b * &u;
    let rv = y - &c * &x - &d * &u;
    let j = lq.columns as f64;
    let sym = |m: DMatrix<f64>| (&m + m.transpose()) * 0.5;
    Ok(StateSpaceFit {
        q: sym(&rw * rw.transpose() / j),
        s: &rw * rv.transpose() / j,
        r: sym(&rv * rv.transpose() / j),
        a,
        b,
        c,
        d,
    })
}

/// [top; bottom].
pub(crate) fn stack(top: &DMatrix<f64>, bottom: &DMatrix<f64>) -> DMatrix<f64> {
    let mut out = DMatrix::zeros(top.nrows() + bottom.nrows(), top.ncols());
    out.rows_mut(0, top.nrows()).copy_from(top);
    out.rows_mut(top.nrows(), bottom.nrows()).copy_from(bottom);
    out
}
