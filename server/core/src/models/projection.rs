//! The nearest physically valid (M, D̄) to an identified pair: M symmetric
//! positive definite (Fossen 2011, property 6.1) and D̄ dissipative,
//! ½(D̄ + D̄ᵀ) ⪰ 0, so that the unforced model cannot gain kinetic energy
//! (d/dt ½νᵀMν = −νᵀD̄ν ≤ 0). Both are Frobenius-nearest projections on
//! convex cones: M ← sym(M) with its eigenvalues raised to a floor, D̄ ←
//! D̄ minus the negative part of its symmetric part (the skew part, which
//! carries C(ν) and does no work, is kept). Entries a coupling structure
//! fixes at zero stay zero when the input honours the same pattern and the
//! pattern is block diagonal (as the coupling closure is).

use nalgebra::DMatrix;

/// Floor of M's eigenvalues relative to its largest one.
pub const M_EIGEN_FLOOR: f64 = 1e-3;

/// A projected pair and what the projection changed.
#[derive(Debug, Clone, PartialEq)]
pub struct Projection {
    /// Symmetric positive definite M.
    pub m: DMatrix<f64>,
    /// Dissipative D̄.
    pub d_bar: DMatrix<f64>,
    /// ‖M_new − M‖_F / ‖M‖_F.
    pub m_change: f64,
    /// ‖D̄_new − D̄‖_F / ‖D̄‖_F.
    pub d_change: f64,
    /// Eigenvalues of sym(M) that were raised to the floor.
    pub m_raised: usize,
    /// Negative eigenvalues of sym(D̄) removed.
    pub d_removed: usize,
}

impl Projection {
    /// True when the input already was physical (up to symmetrizing M).
    pub fn unchanged(&self) -> bool {
        self.m_raised == 0 && self.d_removed == 0
    }
}

fn sym(a: &DMatrix<f64>) -> DMatrix<f64> {
    (a + a.transpose()) * 0.5
}

fn rel(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    let n = b.norm();
    if n == 0.0 { 0.0 } else { (a - b).norm() / n }
}

/// Projects (M, D̄) (square, same size, finite) onto the physical set.
pub fn project_physical(m: &DMatrix<f64>, d_bar: &DMatrix<f64>) -> Projection {
    let ms = sym(m);
    let eig = ms.clone().symmetric_eigen();
    let top = eig.eigenvalues.iter().copied().fold(0.0, f64::max);
    // An M with no positive eigenvalue has no scale of its own: fall back
    // on the largest |diagonal| entry.
    let scale = if top > 0.0 {
        top
    } else {
        m.diagonal().amax().max(f64::MIN_POSITIVE)
    };
    let floor = M_EIGEN_FLOOR * scale;
    let mut m_raised = 0;
    let lam = eig.eigenvalues.map(|l| {
        if l < floor {
            m_raised += 1;
            floor
        } else {
            l
        }
    });
    let m_new = if m_raised == 0 {
        ms
    } else {
        let v = &eig.eigenvectors;
        sym(&(v * DMatrix::from_diagonal(&lam) * v.transpose()))
    };

    let ds = sym(d_bar);
    let de = ds.symmetric_eigen();
    let mut d_removed = 0;
    let neg = de.eigenvalues.map(|l| {
        if l < 0.0 {
            d_removed += 1;
            l
        } else {
            0.0
        }
    });
    let d_new = if d_removed == 0 {
        d_bar.clone()
    } else {
        let v = &de.eigenvectors;
        let mut d = d_bar - v * DMatrix::from_diagonal(&neg) * v.transpose();
        // Round-off can leave −1e-16-level eigenvalues; nudge the diagonal.
        let min = sym(&d).symmetric_eigenvalues().min();
        if min < 0.0 {
            for i in 0..d.nrows() {
                d[(i, i)] -= min;
            }
        }
        d
    };
    Projection {
        m_change: rel(&m_new, m),
        d_change: rel(&d_new, d_bar),
        m: m_new,
        d_bar: d_new,
        m_raised,
        d_removed,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_physical_pair_is_kept() {
        let m = DMatrix::from_row_slice(2, 2, &[500.0, 20.0, 20.0, 300.0]);
        let d = DMatrix::from_row_slice(2, 2, &[100.0, 40.0, -40.0, 80.0]);
        let p = project_physical(&m, &d);
        assert!(p.unchanged());
        assert_eq!(p.m, m);
        assert_eq!(p.d_bar, d);
    }

    #[test]
    fn negative_inertia_and_energy_gain_are_projected_out() {
        // M with a negative roll inertia; D̄ whose symmetric part has the
        // eigenvalues 100 ± 150 (one negative).
        let m = DMatrix::from_row_slice(2, 2, &[400.0, 0.0, 0.0, -30.0]);
        let d = DMatrix::from_row_slice(2, 2, &[100.0, 150.0, 150.0, 100.0]);
        let p = project_physical(&m, &d);
        assert_eq!((p.m_raised, p.d_removed), (1, 1));
        assert!((p.m[(1, 1)] - 0.4).abs() < 1e-12, "{}", p.m);
        assert!((p.m[(0, 0)] - 400.0).abs() < 1e-12);
        // The negative eigenvalue −50 of sym(D̄) along (1, −1)/√2 is removed:
        // D̄ + 25·[[1, −1], [−1, 1]].
        let expected = DMatrix::from_row_slice(2, 2, &[125.0, 125.0, 125.0, 125.0]);
        assert!((&p.d_bar - expected).amax() < 1e-9, "{}", p.d_bar);
        let min = sym(&p.d_bar).symmetric_eigenvalues().min();
        assert!(min >= 0.0);
    }

    #[test]
    fn the_skew_part_of_damping_is_kept() {
        let m = DMatrix::identity(2, 2);
        let d = DMatrix::from_row_slice(2, 2, &[-1.0, 5.0, -5.0, 2.0]);
        let p = project_physical(&m, &d);
        assert!((p.d_bar[(0, 1)] - p.d_bar[(1, 0)] - 10.0).abs() < 1e-12);
        assert!(p.d_bar[(0, 0)].abs() < 1e-12 && (p.d_bar[(1, 1)] - 2.0).abs() < 1e-12);
    }
}
