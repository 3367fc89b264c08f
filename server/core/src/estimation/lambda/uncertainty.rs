//! Standard deviations of A, B, M, D̄ (and K, F of the exogenous terms) by
//! the delta method: the posterior covariance of the free entries of
//! [A_λ B_λ K_λ] pushed through the Jacobian of the map
//! (A_λ, B_λ, K_λ) → (A, B, M, D̄, K, F), taken by central
//! differences of the exact map at steps small against each parameter's
//! own standard deviation (so the linearization is the local one).

use nalgebra::{DMatrix, DVector};

use super::filter::LambdaFilter;
use super::posterior::RowPosterior;
use super::transform::{Inversion, physical};

/// Central-difference step as a fraction of a parameter's posterior std.
const STEP_OF_STD: f64 = 1e-3;

/// The free entries of [A_λ B_λ K_λ] stacked row after row: entry c is
/// (row i, column j) of θ (n × (2n + q)).
#[derive(Debug, Clone)]
pub(crate) struct Stacked {
    pub index: Vec<(usize, usize)>,
}

impl Stacked {
    pub fn new(free: &[Vec<usize>]) -> Self {
        Stacked {
            index: free
                .iter()
                .enumerate()
                .flat_map(|(i, f)| f.iter().map(move |&j| (i, j)))
                .collect(),
        }
    }

    pub fn len(&self) -> usize {
        self.index.len()
    }

    pub fn gather(&self, theta: &DMatrix<f64>) -> DVector<f64> {
        DVector::from_iterator(self.len(), self.index.iter().map(|&(i, j)| theta[(i, j)]))
    }

    pub fn scatter(&self, x: &DVector<f64>, theta: &mut DMatrix<f64>) {
        for (c, &(i, j)) in self.index.iter().enumerate() {
            theta[(i, j)] = x[c];
        }
    }

    /// The block-diagonal covariance of independent rows.
    pub fn block_covariance(&self, rows: &[RowPosterior]) -> DMatrix<f64> {
        let k = self.len();
        DMatrix::from_fn(k, k, |a, b| {
            let (ia, ja) = self.index[a];
            let (ib, jb) = self.index[b];
            if ia == ib {
                rows[ia].cov[(ja, jb)]
            } else {
                0.0
            }
        })
    }
}

/// The map's outputs (A, B, M, D̄, K, F) of θ (n × (2n + q)).
pub(crate) fn outputs(
    theta: &DMatrix<f64>,
    f: &LambdaFilter,
    inversion: Inversion,
    blocks: &DMatrix<bool>,
) -> Option<[DMatrix<f64>; 6]> {
    let n = theta.nrows();
    let q = theta.ncols() - 2 * n;
    let al = theta.columns(0, n).into_owned();
    let bl = theta.columns(n, n).into_owned();
    let kl = theta.columns(2 * n, q).into_owned();
    physical(&al, &bl, &kl, f, inversion, blocks).ok()
}

/// Where each output of the map (A, B, M, D̄, K, F) sits among the
/// Jacobian's rows (entries column-major), for θ of n rows and q exogenous
/// columns.
pub(crate) struct Layout {
    pub n: usize,
    /// Columns of each output.
    pub shapes: [usize; 6],
    /// First Jacobian row of each output.
    pub offsets: [usize; 6],
    /// Jacobian rows in all.
    pub rows: usize,
}

impl Layout {
    pub fn of(theta: &DMatrix<f64>) -> Self {
        let n = theta.nrows();
        let q = theta.ncols() - 2 * n;
        let shapes = [n, n, n, n, q, q];
        let mut offsets = [0; 6];
        let mut rows = 0;
        for (o, c) in shapes.iter().enumerate() {
            offsets[o] = rows;
            rows += n * c;
        }
        Layout {
            n,
            shapes,
            offsets,
            rows,
        }
    }

    /// The Jacobian row of entry (r, c) of output `o`.
    pub fn row(&self, o: usize, r: usize, c: usize) -> usize {
        self.offsets[o] + c * self.n + r
    }
}

/// ∂(A, B, M, D̄, K, F)/∂x at θ, one column per stacked free entry, by
/// central differences with steps `STEP_OF_STD`·σ (σ from `cov`'s
/// diagonal); `None` when the map fails at a perturbed point.
pub(crate) fn jacobian(
    theta: &DMatrix<f64>,
    stacked: &Stacked,
    cov: &DMatrix<f64>,
    f: &LambdaFilter,
    inversion: Inversion,
    blocks: &DMatrix<bool>,
) -> Option<DMatrix<f64>> {
    use rayon::prelude::*;
    let layout = Layout::of(theta);
    // The columns are independent (each its own pair of maps): side by
    // side on the pool, the same values in the same places.
    let columns: Vec<Option<Vec<f64>>> = stacked
        .index
        .par_iter()
        .enumerate()
        .map(|(c, &(i, j))| {
            let sd = cov[(c, c)].max(0.0).sqrt();
            let step = (STEP_OF_STD * sd).max(1e-12 * theta[(i, j)].abs().max(f64::MIN_POSITIVE));
            let mut plus = theta.clone();
            plus[(i, j)] += step;
            let mut minus = theta.clone();
            minus[(i, j)] -= step;
            let (pl, mi) = (
                outputs(&plus, f, inversion, blocks)?,
                outputs(&minus, f, inversion, blocks)?,
            );
            let mut col = vec![0.0; layout.rows];
            for o in 0..6 {
                for (e, (x, y)) in pl[o].iter().zip(mi[o].iter()).enumerate() {
                    col[layout.offsets[o] + e] = (x - y) / (2.0 * step);
                }
            }
            Some(col)
        })
        .collect();
    let mut jac = DMatrix::zeros(layout.rows, stacked.len());
    for (c, col) in columns.into_iter().enumerate() {
        jac.column_mut(c).copy_from_slice(&col?);
    }
    Some(jac)
}

/// Stds of (A, B, M, D̄, K, F) from the covariance `cov` of the stacked
/// free entries; all NaN when the map fails at a perturbed point.
pub(crate) fn delta_method_cov(
    theta: &DMatrix<f64>,
    stacked: &Stacked,
    cov: &DMatrix<f64>,
    f: &LambdaFilter,
    inversion: Inversion,
    blocks: &DMatrix<bool>,
) -> [DMatrix<f64>; 6] {
    let layout = Layout::of(theta);
    let Some(jac) = jacobian(theta, stacked, cov, f, inversion, blocks) else {
        return std::array::from_fn(|o| {
            DMatrix::from_element(layout.n, layout.shapes[o], f64::NAN)
        });
    };
    let jc = &jac * cov;
    std::array::from_fn(|o| {
        DMatrix::from_fn(layout.n, layout.shapes[o], |r, c| {
            let row = layout.row(o, r, c);
            jc.row(row).dot(&jac.row(row)).max(0.0).sqrt()
        })
    })
}
