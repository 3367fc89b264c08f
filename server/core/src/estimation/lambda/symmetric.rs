//! M = M_RB + M_A is symmetric (Fossen 2011, property 6.1), but the λ
//! regression estimates each row of [A_λ B_λ] on its own, so M = B⁻¹ comes
//! out slightly asymmetric, and the Frobenius-nearest symmetric matrix
//! ½(M + Mᵀ) averages a well-determined entry with a poorly determined one
//! while leaving D̄ where the unconstrained fit put it.
//!
//! Instead the rows are re-estimated under the constraint M_ij = M_ji as a
//! generalized least-squares problem over their joint posterior: with x̂
//! the free entries, P their covariance and g(x) = (M_ij − M_ji)_{i<j},
//! x = x̂ − P Gᵀ (G P Gᵀ)⁻¹ [g(x_k) + G (x̂ − x_k)] (Gauss–Newton on the
//! linearized constraint, G = ∂g/∂x at x_k), and
//! P_c = P − P Gᵀ (G P Gᵀ)⁻¹ G P. Every entry of a row moves with M by its
//! correlation to it, so D̄ follows the constrained M as the data ask.
//! χ² = g(x̂)ᵀ(G P Gᵀ)⁻¹g(x̂) on as many degrees of freedom as constraints
//! measures how far the unconstrained rows disagree with a symmetric M.
//! The residual-based posterior is too narrow when that disagreement is
//! larger than it allows (closed-loop noise, unmodelled dynamics), so the
//! identification scales its covariance by the Birge ratio √(χ²/m) when it
//! exceeds 1 — the same test of consistency as across grid speeds.

use nalgebra::{DMatrix, DVector};

use super::filter::LambdaFilter;
use super::transform::Inversion;
use super::uncertainty::{Layout, Stacked, jacobian, outputs};

/// Gauss–Newton iterations at most.
const MAX_ITER: usize = 8;
/// Converged when every |M_ij − M_ji| is below this fraction of ‖M‖.
const TOL: f64 = 1e-12;

/// How the symmetric constraint changed the estimate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SymmetryFit {
    /// Off-diagonal pairs (i < j) constrained.
    pub constraints: usize,
    /// χ² of the unconstrained asymmetry against its covariance.
    pub chi2: f64,
}

impl SymmetryFit {
    /// The Birge ratio √(χ²/m), at least 1: the factor by which the
    /// posterior's standard deviations understate the error.
    pub fn inflation(&self) -> f64 {
        if self.constraints == 0 || !self.chi2.is_finite() {
            return 1.0;
        }
        (self.chi2 / self.constraints as f64).sqrt().max(1.0)
    }
}

/// The pairs i < j whose M entries the structure lets be non-zero.
fn pairs(blocks: &DMatrix<bool>) -> Vec<(usize, usize)> {
    let n = blocks.nrows();
    (0..n)
        .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
        .filter(|&(i, j)| blocks[(i, j)] || blocks[(j, i)])
        .collect()
}

/// Constrains θ (n × (2n + q)) and the covariance `cov` of its stacked free
/// entries so that M + S is symmetric (S = `offset`, zero when `None`).
/// `None` (θ and `cov` untouched) when there is nothing to constrain, the
/// map fails, or G P Gᵀ is singular.
pub(crate) fn constrain_symmetric(
    theta: &mut DMatrix<f64>,
    stacked: &Stacked,
    cov: &mut DMatrix<f64>,
    offset: Option<&DMatrix<f64>>,
    f: &LambdaFilter,
    inversion: Inversion,
    blocks: &DMatrix<bool>,
) -> Option<SymmetryFit> {
    let pairs = pairs(blocks);
    if pairs.is_empty() || stacked.len() == 0 {
        return None;
    }
    let layout = Layout::of(theta);
    let m_row = |i: usize, j: usize| layout.row(2, i, j);
    let x_hat = stacked.gather(theta);
    let mut x = x_hat.clone();
    let mut th = theta.clone();
    let mut chi2 = None;
    let mut last = None;
    for _ in 0..MAX_ITER {
        stacked.scatter(&x, &mut th);
        let mut m = outputs(&th, f, inversion, blocks)?[2].clone();
        if let Some(s) = offset.filter(|s| s.shape() == m.shape()) {
            m += s;
        }
        let jac = jacobian(&th, stacked, cov, f, inversion, blocks)?;
        let g = DVector::from_iterator(
            pairs.len(),
            pairs.iter().map(|&(i, j)| m[(i, j)] - m[(j, i)]),
        );
        let gm = DMatrix::from_fn(pairs.len(), stacked.len(), |r, c| {
            let (i, j) = pairs[r];
            jac[(m_row(i, j), c)] - jac[(m_row(j, i), c)]
        });
        let pg = &*cov * gm.transpose();
        let s = &gm * &pg;
        let chol = s.clone().cholesky()?;
        if chi2.is_none() {
            chi2 = Some(g.dot(&chol.solve(&g)));
        }
        let scale = m.norm().max(f64::MIN_POSITIVE);
        let done = g.amax() <= TOL * scale;
        last = Some((pg.clone(), chol.clone()));
        if done {
            break;
        }
        let rhs = &g + &gm * (&x_hat - &x);
        x = &x_hat - &pg * chol.solve(&rhs);
        if x.iter().any(|v| !v.is_finite()) {
            return None;
        }
    }
    let (pg, chol) = last?;
    stacked.scatter(&x, &mut th);
    // The constrained estimate must still map to a model.
    outputs(&th, f, inversion, blocks)?;
    let reduced = &*cov - &pg * chol.solve(&pg.transpose());
    *cov = (&reduced + reduced.transpose()) * 0.5;
    *theta = th;
    Some(SymmetryFit {
        constraints: pairs.len(),
        chi2: chi2?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::estimation::lambda::transform::{Inversion, to_lambda};

    fn filter() -> LambdaFilter {
        LambdaFilter::new(1.0, 0.1).unwrap()
    }

    /// θ of a 2-DOF model, and its full coupling blocks.
    fn theta_of(m: &DMatrix<f64>, d: &DMatrix<f64>, inv: Inversion) -> DMatrix<f64> {
        let b = m.clone().try_inverse().unwrap();
        let a = -(&b * d);
        let (al, bl) = to_lambda(&a, &b, &filter(), inv).unwrap();
        let mut th = DMatrix::zeros(2, 4);
        th.columns_mut(0, 2).copy_from(&al);
        th.columns_mut(2, 2).copy_from(&bl);
        th
    }

    #[test]
    fn a_symmetric_estimate_is_left_where_it_is() {
        let m = DMatrix::from_row_slice(2, 2, &[10.0, 2.0, 2.0, 5.0]);
        let d = DMatrix::from_row_slice(2, 2, &[3.0, 0.5, 0.2, 4.0]);
        let mut th = theta_of(&m, &d, Inversion::Exact);
        let stacked = Stacked::new(&[vec![0, 1, 2, 3], vec![0, 1, 2, 3]]);
        let mut cov = DMatrix::identity(8, 8) * 1e-4;
        let blocks = DMatrix::from_element(2, 2, true);
        let before = th.clone();
        let fit = constrain_symmetric(
            &mut th,
            &stacked,
            &mut cov,
            None,
            &filter(),
            Inversion::Exact,
            &blocks,
        )
        .unwrap();
        assert_eq!(fit.constraints, 1);
        assert!(fit.chi2 < 1e-12, "{}", fit.chi2);
        assert!((&th - &before).amax() < 1e-12);
    }

    #[test]
    fn the_precise_row_decides_and_its_variance_shrinks() {
        // Thesis map (B = B_λ/T, row by row). Row 0 is nearly exact, row 1's
        // B_λ entries carry the asymmetry with a large variance: the
        // constrained estimate takes row 0's coupling and puts the
        // correction on B_λ[1,0], whose variance then collapses.
        let inv = Inversion::Thesis;
        let m = DMatrix::from_row_slice(2, 2, &[10.0, 2.0, 2.0, 5.0]);
        let d = DMatrix::from_row_slice(2, 2, &[3.0, 0.5, 0.2, 4.0]);
        let truth = theta_of(&m, &d, inv);
        let mut th = truth.clone();
        th[(1, 2)] += 0.002; // B_λ[1,0]
        let stacked = Stacked::new(&[vec![0, 1, 2, 3], vec![0, 1, 2, 3]]);
        let mut var = vec![1e-10; 8];
        var[6] = 1e-4; // row 1, B_λ[1,0]
        var[7] = 1e-4;
        let mut cov = DMatrix::from_diagonal(&DVector::from_vec(var));
        let blocks = DMatrix::from_element(2, 2, true);
        let fit = constrain_symmetric(&mut th, &stacked, &mut cov, None, &filter(), inv, &blocks)
            .unwrap();
        let m_c = outputs(&th, &filter(), inv, &blocks).unwrap()[2].clone();
        assert!((m_c[(0, 1)] - m_c[(1, 0)]).abs() < 1e-9 * m_c.norm());
        for j in 0..4 {
            assert!((th[(0, j)] - truth[(0, j)]).abs() < 1e-6, "row 0 col {j}");
        }
        // B_λ[1,0] returns to the truth (the 0.002 error removed to 1 %).
        assert!(
            (th[(1, 2)] - truth[(1, 2)]).abs() < 2e-5,
            "{}",
            th[(1, 2)] - truth[(1, 2)]
        );
        // χ² = 0.002² / 1e-4 = 0.04 to first order.
        assert!((fit.chi2 - 0.04).abs() < 0.004, "{}", fit.chi2);
        assert!(cov[(6, 6)] < 1e-6, "{}", cov[(6, 6)]);
        assert_eq!(fit.inflation(), 1.0);
        let biased = SymmetryFit {
            constraints: 2,
            chi2: 18.0,
        };
        assert!((biased.inflation() - 3.0).abs() < 1e-12);
    }

    #[test]
    fn with_an_offset_m_plus_s_is_what_comes_out_symmetric() {
        // A fit to logged commands missing c·K_ν ν̇ sees M̂ = M − S with an
        // asymmetric S (a coupled controller): M̂ itself must stay asymmetric.
        let m = DMatrix::from_row_slice(2, 2, &[10.0, 2.0, 2.0, 5.0]);
        let s_off = DMatrix::from_row_slice(2, 2, &[0.4, 0.3, -0.1, 0.2]);
        let d = DMatrix::from_row_slice(2, 2, &[3.0, 0.5, 0.2, 4.0]);
        let m_hat = &m - &s_off;
        let mut th = theta_of(&m_hat, &d, Inversion::Exact);
        let before = th.clone();
        let stacked = Stacked::new(&[vec![0, 1, 2, 3], vec![0, 1, 2, 3]]);
        let mut cov = DMatrix::identity(8, 8) * 1e-4;
        let blocks = DMatrix::from_element(2, 2, true);
        let f = filter();
        let fit = constrain_symmetric(
            &mut th,
            &stacked,
            &mut cov,
            Some(&s_off),
            &f,
            Inversion::Exact,
            &blocks,
        )
        .unwrap();
        assert!(fit.chi2 < 1e-12, "{}", fit.chi2);
        assert!((&th - &before).amax() < 1e-12);
        // Without the offset the same estimate is pulled to a symmetric M̂.
        let mut th2 = before.clone();
        let mut cov2 = DMatrix::identity(8, 8) * 1e-6;
        let fit2 = constrain_symmetric(
            &mut th2,
            &stacked,
            &mut cov2,
            None,
            &f,
            Inversion::Exact,
            &blocks,
        )
        .unwrap();
        assert!(fit2.chi2 > 1.0, "{}", fit2.chi2);
        let m2 = outputs(&th2, &f, Inversion::Exact, &blocks).unwrap()[2].clone();
        assert!((m2[(0, 1)] - m2[(1, 0)]).abs() < 1e-9 * m2.norm());
    }

    #[test]
    fn uncoupled_structure_has_nothing_to_constrain() {
        let m = DMatrix::from_row_slice(2, 2, &[10.0, 0.0, 0.0, 5.0]);
        let d = DMatrix::from_row_slice(2, 2, &[3.0, 0.0, 0.0, 4.0]);
        let mut th = theta_of(&m, &d, Inversion::Exact);
        let stacked = Stacked::new(&[vec![0, 2], vec![1, 3]]);
        let mut cov = DMatrix::identity(4, 4) * 1e-4;
        let blocks = DMatrix::from_row_slice(2, 2, &[true, false, false, true]);
        assert!(
            constrain_symmetric(
                &mut th,
                &stacked,
                &mut cov,
                None,
                &filter(),
                Inversion::Exact,
                &blocks
            )
            .is_none()
        );
    }
}
