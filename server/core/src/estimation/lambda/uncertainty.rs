//! Standard deviations of A, B, M, D̄ (and K, F of the exogenous terms) by
//! the delta method: the posterior covariance of each row of
//! [A_λ B_λ K_λ] (rows independent) pushed through the Jacobian of the map
//! (A_λ, B_λ, K_λ) → (A, B, M, D̄, K, F), taken by central
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
) -> [DMatrix<f64>; 6] {
    let n = rows.len();
    let p = rows.first().map_or(2 * n, |r| r.theta.len());
    let q = p - 2 * n;
    let theta = DMatrix::from_fn(n, p, |i, j| rows[i].theta[j]);
    let eval = |th: &DMatrix<f64>| {
        let al = th.columns(0, n).into_owned();
        let bl = th.columns(n, n).into_owned();
        let kl = th.columns(2 * n, q).into_owned();
        physical(&al, &bl, &kl, f, inversion, blocks).ok()
    };
    let shapes = [n, n, n, n, q, q];
    let offsets: Vec<usize> = shapes
        .iter()
        .scan(0, |acc, &c| {
            let o = *acc;
            *acc += n * c;
            Some(o)
        })
        .collect();
    let outputs = n * shapes.iter().sum::<usize>();
    let mut var: [DMatrix<f64>; 6] = std::array::from_fn(|o| DMatrix::zeros(n, shapes[o]));
    for (i, row) in rows.iter().enumerate() {
        // J_i: one column per free parameter of row i, one row per entry of
        // (A, B, M, D̄, K, F).
        let k = free[i].len();
        let mut jac = DMatrix::zeros(outputs, k);
        let mut ok = true;
        for (c, &j) in free[i].iter().enumerate() {
            let sd = row.cov[(j, j)].sqrt();
            let step = (STEP_OF_STD * sd).max(1e-12 * theta[(i, j)].abs().max(f64::MIN_POSITIVE));
            let mut plus = theta.clone();
            plus[(i, j)] += step;
            let mut minus = theta.clone();
            minus[(i, j)] -= step;
            match (eval(&plus), eval(&minus)) {
                (Some(pl), Some(mi)) => {
                    for o in 0..6 {
                        for (e, (x, y)) in pl[o].iter().zip(mi[o].iter()).enumerate() {
                            jac[(offsets[o] + e, c)] = (x - y) / (2.0 * step);
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
        for (o, v) in var.iter_mut().enumerate() {
            for (e, x) in v.iter_mut().enumerate() {
                let r = offsets[o] + e;
                *x += jc.row(r).dot(&jac.row(r));
            }
        }
    }
    var.map(|v| v.map(|x| x.max(0.0).sqrt()))
}
