//! ZOH-discretized prediction of an identified model for validation
//! (thesis sec. 2.6): 1-step predictions ν̂(k+1|k) = Φν(k) + Γγ(k)
//! (eq. 2.16) and free-run simulation ν̂(k+1) = Φν̂(k) + Γγ(k) from the
//! measured ν(0) (eq. 2.20–2.21).

use nalgebra::{DMatrix, DVector};

use super::error::LambdaError;
use super::transform::zoh;

/// A continuous model ν̇ = Aν + Bγ discretized with zero-order hold.
#[derive(Debug, Clone, PartialEq)]
pub struct ZohModel {
    /// Φ = e^{hA}.
    pub phi: DMatrix<f64>,
    /// Γ = ∫₀ʰ e^{As} ds·B.
    pub gamma: DMatrix<f64>,
}

impl ZohModel {
    /// Discretizes (A, B) at step h.
    ///
    /// # Errors
    /// As [`zoh`].
    pub fn new(a: &DMatrix<f64>, b: &DMatrix<f64>, h: f64) -> Result<Self, LambdaError> {
        let (phi, gamma) = zoh(a, b, h)?;
        Ok(ZohModel { phi, gamma })
    }

    fn check(&self, nu: &DMatrix<f64>, gamma: &DMatrix<f64>) -> Result<(), LambdaError> {
        let n = self.phi.nrows();
        if nu.ncols() != n {
            return Err(LambdaError::shape("nu", format!("must have {n} columns")));
        }
        if gamma.ncols() != self.gamma.ncols() || gamma.nrows() != nu.nrows() {
            return Err(LambdaError::shape(
                "gamma",
                format!("must be {} × {}", nu.nrows(), self.gamma.ncols()),
            ));
        }
        Ok(())
    }

    /// 1-step predictions: row 0 is NaN (no prediction), row k is
    /// Φν_{k−1} + Γγ_{k−1} from the measured ν.
    ///
    /// # Errors
    /// Shapes of `nu` / `gamma`.
    pub fn one_step(
        &self,
        nu: &DMatrix<f64>,
        gamma: &DMatrix<f64>,
    ) -> Result<DMatrix<f64>, LambdaError> {
        self.check(nu, gamma)?;
        let (rows, n) = nu.shape();
        let mut out = DMatrix::from_element(rows, n, f64::NAN);
        if rows > 1 {
            // Rows 1.. at once: (Φ ν_{0..N−1}ᵀ + Γ γ_{0..N−1}ᵀ)ᵀ.
            let x = nu.rows(0, rows - 1);
            let u = gamma.rows(0, rows - 1);
            let pred = x * self.phi.transpose() + u * self.gamma.transpose();
            out.rows_mut(1, rows - 1).copy_from(&pred);
        }
        Ok(out)
    }

    /// Free-run simulation from the measured ν(0) on the recorded γ alone.
    ///
    /// # Errors
    /// Shapes of `nu` / `gamma`.
    pub fn simulate(
        &self,
        nu: &DMatrix<f64>,
        gamma: &DMatrix<f64>,
    ) -> Result<DMatrix<f64>, LambdaError> {
        self.check(nu, gamma)?;
        let (rows, n) = nu.shape();
        let mut out = DMatrix::zeros(rows, n);
        if rows == 0 {
            return Ok(out);
        }
        let mut x = DVector::from_iterator(n, nu.row(0).iter().copied());
        for k in 0..rows {
            out.row_mut(k).copy_from(&x.transpose());
            let u = DVector::from_iterator(gamma.ncols(), gamma.row(k).iter().copied());
            x = &self.phi * &x + &self.gamma * u;
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simulation::integrate::rk4_step;

    #[test]
    fn simulation_matches_fine_rk4_and_one_step_is_exact_noise_free() {
        let a = DMatrix::from_row_slice(2, 2, &[-0.5, 0.3, -0.2, -1.0]);
        let b = DMatrix::from_row_slice(2, 1, &[1.0, 0.5]);
        let h = 0.1;
        let model = ZohModel::new(&a, &b, h).unwrap();
        let gamma = DMatrix::from_fn(200, 1, |k, _| ((k / 15) % 2) as f64 * 2.0 - 1.0);
        let mut nu = DMatrix::zeros(200, 2);
        let mut x = [0.3, -0.1];
        for k in 0..200 {
            nu[(k, 0)] = x[0];
            nu[(k, 1)] = x[1];
            let mut f = |x: &[f64], u: &[f64], dx: &mut [f64]| {
                dx[0] = a[(0, 0)] * x[0] + a[(0, 1)] * x[1] + b[(0, 0)] * u[0];
                dx[1] = a[(1, 0)] * x[0] + a[(1, 1)] * x[1] + b[(1, 0)] * u[0];
            };
            for _ in 0..10 {
                rk4_step(&mut f, &mut x, &[gamma[(k, 0)]], h / 10.0);
            }
        }
        let sim = model.simulate(&nu, &gamma).unwrap();
        assert!((&sim - &nu).amax() < 1e-9);
        let one = model.one_step(&nu, &gamma).unwrap();
        assert!(one.row(0).iter().all(|v| v.is_nan()));
        assert!((one.rows(1, 199) - nu.rows(1, 199)).amax() < 1e-9);
        assert_eq!(
            model
                .one_step(&nu, &DMatrix::zeros(10, 1))
                .unwrap_err()
                .field(),
            "gamma"
        );
    }
}
