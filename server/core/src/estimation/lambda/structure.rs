//! Which entries of A and B (equivalently of A_λ, B_λ) are estimated.

use nalgebra::DMatrix;

use super::error::LambdaError;

/// Free-entry patterns of A (n × n) and B (n × n); entries not free are
/// fixed at zero. Diagonals must be free.
#[derive(Debug, Clone, PartialEq)]
pub struct CouplingMask {
    /// `a[(i, j)]`: A_ij (ν_j's effect on ν̇_i) is estimated.
    pub a: DMatrix<bool>,
    /// `b[(i, j)]`: B_ij (γ_j's effect on ν̇_i) is estimated.
    pub b: DMatrix<bool>,
}

impl CouplingMask {
    /// Every entry free (fully coupled model).
    pub fn full(n: usize) -> Self {
        CouplingMask {
            a: DMatrix::from_element(n, n, true),
            b: DMatrix::from_element(n, n, true),
        }
    }

    /// Diagonal entries only (each DOF alone).
    pub fn diagonal(n: usize) -> Self {
        CouplingMask {
            a: DMatrix::from_fn(n, n, |i, j| i == j),
            b: DMatrix::from_fn(n, n, |i, j| i == j),
        }
    }

    /// A and B both free on `pattern` and on the diagonal.
    pub fn from_pattern(pattern: &DMatrix<bool>) -> Self {
        let p = DMatrix::from_fn(pattern.nrows(), pattern.ncols(), |i, j| {
            i == j || pattern[(i, j)]
        });
        CouplingMask { a: p.clone(), b: p }
    }

    /// Number of DOFs.
    pub fn n(&self) -> usize {
        self.a.nrows()
    }

    /// Indices of the free regressors of output row i, in the regressor
    /// order φ = [[λν]_0 … [λν]_{n−1}, [λγ]_0 … [λγ]_{n−1}].
    pub(crate) fn free_of_row(&self, i: usize) -> Vec<usize> {
        let n = self.n();
        (0..n)
            .filter(|&j| self.a[(i, j)])
            .chain((0..n).filter(|&j| self.b[(i, j)]).map(|j| n + j))
            .collect()
    }

    /// The block closure: (i, j) connected when i and j lie in one connected
    /// component of the graph of free off-diagonal entries of A or B. Zero
    /// patterns closed this way are preserved by e^{hA} and its logarithm,
    /// so the sampled-data ↔ continuous map keeps them exactly.
    pub fn blocks(&self) -> DMatrix<bool> {
        let n = self.n();
        let mut comp: Vec<usize> = (0..n).collect();
        fn root(c: &mut [usize], mut i: usize) -> usize {
            while c[i] != i {
                c[i] = c[c[i]];
                i = c[i];
            }
            i
        }
        for i in 0..n {
            for j in 0..n {
                if self.a[(i, j)] || self.b[(i, j)] {
                    let (ri, rj) = (root(&mut comp, i), root(&mut comp, j));
                    comp[ri] = rj;
                }
            }
        }
        let roots: Vec<usize> = (0..n).map(|i| root(&mut comp, i)).collect();
        DMatrix::from_fn(n, n, |i, j| roots[i] == roots[j])
    }

    /// Checks the shapes against `n` DOFs and that the diagonals are free.
    pub(crate) fn validate(&self, n: usize) -> Result<(), LambdaError> {
        for (name, m) in [("structure.a", &self.a), ("structure.b", &self.b)] {
            if m.shape() != (n, n) {
                return Err(LambdaError::shape(
                    name,
                    format!("is {}×{}, expected {n}×{n}", m.nrows(), m.ncols()),
                ));
            }
            if let Some(i) = (0..n).find(|&i| !m[(i, i)]) {
                return Err(LambdaError::invalid(
                    name,
                    format!(
                        "diagonal entry ({i}, {i}) must be free (a DOF without its own dynamics or input is unidentifiable and B would be singular)"
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// Model structure of the λ-filter regression.
#[derive(Debug, Clone, PartialEq)]
pub enum Structure {
    /// Each DOF alone: ν_i on [λν_i] and [λγ_i] (thesis' uncoupled model).
    Diagonal,
    /// The free entries of A and B given by the mask (thesis' coupled model
    /// with `CouplingMask::full`).
    Coupled(CouplingMask),
}

impl Structure {
    /// The mask for `n` DOFs.
    pub fn mask(&self, n: usize) -> CouplingMask {
        match self {
            Structure::Diagonal => CouplingMask::diagonal(n),
            Structure::Coupled(m) => m.clone(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn free_indices_and_blocks() {
        let mut p = DMatrix::from_element(4, 4, false);
        p[(0, 2)] = true;
        p[(2, 3)] = true;
        let m = CouplingMask::from_pattern(&p);
        assert_eq!(m.free_of_row(0), vec![0, 2, 4, 6]);
        assert_eq!(m.free_of_row(1), vec![1, 5]);
        let b = m.blocks();
        // 0–2–3 chain closes into one block; 1 stays alone.
        assert!(b[(0, 3)] && b[(3, 0)] && b[(2, 0)]);
        assert!(!b[(1, 0)] && !b[(0, 1)] && b[(1, 1)]);
    }

    #[test]
    fn validation_names_the_field() {
        let mut m = CouplingMask::full(3);
        m.b[(1, 1)] = false;
        assert_eq!(m.validate(3).unwrap_err().field(), "structure.b");
        assert_eq!(
            CouplingMask::full(2).validate(3).unwrap_err().field(),
            "structure.a"
        );
        assert!(CouplingMask::diagonal(3).validate(3).is_ok());
    }
}
