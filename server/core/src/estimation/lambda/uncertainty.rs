//! Standard deviations of A, B, M, D̄ by the delta method: the posterior
//! covariance of each row of [A_λ B_λ] (rows independent) pushed through
//! the Jacobian of the map (A_λ, B_λ) → (A, B, M, D̄), taken by central
//! differences of the exact map at steps small against each parameter's
//! own standard deviation (so the linearization is the local one).

use nalgebra::DMatrix;

use super::filter::LambdaFilter;
use super::posterior::RowPosterior;
use super::transform::{Inversion, physical};

/// Central-difference step as a fraction of a parameter's posterior std.
const STEP_OF_STD: f64 = 1e-3;

/// Stds of (A, B, M, D̄); entries whose perturbed map fails are NaN.
pub(crate) fn delta_method(
    rows: &[RowPosterior],
    free: &[Vec<usize>],
    f: &LambdaFilter,
    inversion: Inversion,
    blocks: &DMatrix<bool>,
) -> [DMatrix<f64>; 4] {
    let n = rows.len();
    let theta = DMatrix::from_fn(n, 2 * n, |i, j| rows[i].theta[j]);
    let eval = |th: &DMatrix<f64>| {
        let al = th.columns(0, n).into_owned();
        let bl = th.columns(n, n).into_owned();
        physical(&al, &bl, f, inversion, blocks).ok()
    };
    let mut var: [DMatrix<f64>; 4] = std::array::from_fn(|_| DMatrix::zeros(n, n));
    for (i, row) in rows.iter().enumerate() {
        // J_i: one column per free parameter of row i, 4n² outputs.
        let k = free[i].len();
        let mut jac = DMatrix::zeros(4 * n * n, k);
        let mut ok = true;
        for (c, &j) in free[i].iter().enumerate() {
            let sd = row.cov[(j, j)].sqrt();
            let step = (STEP_OF_STD * sd).max(1e-12 * theta[(i, j)].abs().max(f64::MIN_POSITIVE));
            let mut plus = theta.clone();
            plus[(i, j)] += step;
            let mut minus = theta.clone();
            minus[(i, j)] -= step;
            match (eval(&plus), eval(&minus)) {
                (Some(p), Some(m)) => {
                    for q in 0..4 {
                        for (e, (x, y)) in p[q].iter().zip(m[q].iter()).enumerate() {
                            jac[(q * n * n + e, c)] = (x - y) / (2.0 * step);
                        }
                    }
                }
                _ => ok = false,
            }
        }
        if !ok {
            for v in var.iter_mut() {
                v.fill(f64::NAN);
            }
            continue;
        }
        let cov = DMatrix::from_fn(k, k, |a, b| row.cov[(free[i][a], free[i][b])]);
        let jc = &jac * cov;
        for (q, v) in var.iter_mut().enumerate() {
            for (e, x) in v.iter_mut().enumerate() {
                let r = q * n * n + e;
                *x += jc.row(r).dot(&jac.row(r));
            }
        }
    }
    var.map(|v| v.map(|x| x.max(0.0).sqrt()))
}
