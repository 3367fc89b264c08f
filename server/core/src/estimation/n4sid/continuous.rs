//! Discrete → continuous time under zero-order hold, by eigendecomposition.
//!
//! With A = V Λ V⁻¹ (diagonalizable), A_c = V log(Λ)/h V⁻¹ (principal
//! logarithm) and, since B = ∫₀ʰ e^{A_c s} ds B_c = V diag(φ) V⁻¹ B_c with
//! φ_k = (λ_k − 1)/μ_k (μ_k = log λ_k / h; φ_k → h as μ_k → 0, so
//! integrators are fine), B_c = V diag(1/φ) V⁻¹ B. A real negative or zero
//! eigenvalue has no real logarithm: no continuous model is ZOH-equivalent,
//! which is an error rather than a complex or arbitrary answer.

use faer::MatRef;
use nalgebra::{Complex, DMatrix};

/// A continuous-time model ẋ = A x + B u, y = C x + D u.
#[derive(Debug, Clone, PartialEq)]
pub struct ContinuousModel {
    pub a: DMatrix<f64>,
    pub b: DMatrix<f64>,
    pub c: DMatrix<f64>,
    pub d: DMatrix<f64>,
}

/// Why [`d2c`] has no answer.
#[derive(Debug, Clone, PartialEq)]
pub enum D2cError {
    /// `a` has a real eigenvalue ≤ 0 (no real matrix logarithm).
    NonPositiveRealEigenvalue { value: f64 },
    /// `a` is (numerically) defective: eigenvector matrix condition number.
    NotDiagonalizable { condition: f64 },
    /// Shapes of `a`, `b` disagree or `h` is not positive and finite.
    Input { field: &'static str },
    /// The eigendecomposition failed.
    Numerical,
}

impl std::fmt::Display for D2cError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            D2cError::NonPositiveRealEigenvalue { value } => write!(
                f,
                "a: real eigenvalue {value} ≤ 0 has no continuous-time equivalent"
            ),
            D2cError::NotDiagonalizable { condition } => write!(
                f,
                "a: not diagonalizable (eigenvector condition number {condition:.3e})"
            ),
            D2cError::Input { field } => write!(f, "{field}: invalid"),
            D2cError::Numerical => f.write_str("a: eigendecomposition failed"),
        }
    }
}

impl std::error::Error for D2cError {}

/// Largest accepted condition number of the eigenvector matrix.
const MAX_CONDITION: f64 = 1e10;

/// (A_c, B_c) from the ZOH pair (A, B) at sample time h.
pub fn d2c(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    h: f64,
) -> Result<(DMatrix<f64>, DMatrix<f64>), D2cError> {
    let n = a.nrows();
    if a.ncols() != n {
        return Err(D2cError::Input { field: "a" });
    }
    if b.nrows() != n {
        return Err(D2cError::Input { field: "b" });
    }
    if !(h.is_finite() && h > 0.0) {
        return Err(D2cError::Input { field: "h" });
    }
    if n == 0 {
        return Ok((a.clone(), b.clone()));
    }
    if !a.iter().chain(b.iter()).all(|v| v.is_finite()) {
        return Err(D2cError::Input { field: "a" });
    }
    let view = MatRef::from_column_major_slice(a.as_slice(), n, n);
    let eig = view.eigen().map_err(|_| D2cError::Numerical)?;
    let (u, s) = (eig.U(), eig.S().column_vector());
    let v = DMatrix::from_fn(n, n, |r, c| {
        let z = u[(r, c)];
        Complex::new(z.re, z.im)
    });
    let lambda: Vec<Complex<f64>> = (0..n).map(|k| Complex::new(s[k].re, s[k].im)).collect();
    let scale = lambda.iter().map(|z| z.norm()).fold(0.0, f64::max);
    for z in &lambda {
        if z.im.abs() <= 1e-12 * scale.max(1.0) && z.re <= 0.0 {
            return Err(D2cError::NonPositiveRealEigenvalue { value: z.re });
        }
    }
    let svd_v = v.clone().svd(false, false).singular_values;
    let condition = svd_v.max() / svd_v.min();
    if !condition.is_finite() || condition > MAX_CONDITION {
        return Err(D2cError::NotDiagonalizable { condition });
    }
    let v_inv = v.clone().try_inverse().ok_or(D2cError::NotDiagonalizable {
        condition: f64::INFINITY,
    })?;
    let mu: Vec<Complex<f64>> = lambda.iter().map(|z| z.ln() / h).collect();
    let inv_phi: Vec<Complex<f64>> = lambda
        .iter()
        .zip(&mu)
        .map(|(z, m)| {
            if (m * h).norm() > 1e-8 {
                m / (z - Complex::new(1.0, 0.0))
            } else {
                // (e^{μh} − 1)/μ = h (1 + μh/2 + …)
                Complex::new(1.0, 0.0) / (h * (Complex::new(1.0, 0.0) + m * h * 0.5))
            }
        })
        .collect();
    let diag = |d: &[Complex<f64>]| {
        let mut out = v.clone();
        for (c, dc) in d.iter().enumerate() {
            for r in 0..n {
                out[(r, c)] *= dc;
            }
        }
        out * &v_inv
    };
    let ac = diag(&mu);
    let bc = diag(&inv_phi) * b.map(|x| Complex::new(x, 0.0));
    Ok((ac.map(|z| z.re), bc.map(|z| z.re)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// e^M by scaling and squaring of the Taylor series (independent of the
    /// eigendecomposition under test).
    fn expm(m: &DMatrix<f64>) -> DMatrix<f64> {
        let norm = m.abs().row_sum().max();
        let squarings = (norm.max(1e-300).log2().ceil().max(0.0) as i32) + 4;
        let scaled = m / 2f64.powi(squarings);
        let n = m.nrows();
        let mut term = DMatrix::<f64>::identity(n, n);
        let mut sum = term.clone();
        for k in 1..30 {
            term = &term * &scaled / k as f64;
            sum += &term;
        }
        for _ in 0..squarings {
            sum = &sum * &sum;
        }
        sum
    }

    /// ZOH discretization through the augmented exponential.
    fn c2d(ac: &DMatrix<f64>, bc: &DMatrix<f64>, h: f64) -> (DMatrix<f64>, DMatrix<f64>) {
        let (n, m) = (ac.nrows(), bc.ncols());
        let mut aug = DMatrix::zeros(n + m, n + m);
        aug.view_mut((0, 0), (n, n)).copy_from(&(ac * h));
        aug.view_mut((0, n), (n, m)).copy_from(&(bc * h));
        let e = expm(&aug);
        (
            e.view((0, 0), (n, n)).into_owned(),
            e.view((0, n), (n, m)).into_owned(),
        )
    }

    #[test]
    fn recovers_a_continuous_model_with_oscillation_and_an_integrator() {
        // Surge-sway-yaw-like: damped coupled velocities, one position
        // integrator (eigenvalue 1 after ZOH), a lightly damped oscillation.
        let ac = DMatrix::from_row_slice(
            4,
            4,
            &[
                -0.5, 0.1, 0.0, 0.0, //
                0.0, -0.2, 1.5, 0.0, //
                0.0, -1.5, -0.2, 0.0, //
                1.0, 0.0, 0.0, 0.0,
            ],
        );
        let bc = DMatrix::from_row_slice(4, 2, &[1.0, 0.0, 0.5, 0.2, 0.0, 1.0, 0.0, 0.0]);
        for h in [0.01, 0.1, 0.5] {
            let (ad, bd) = c2d(&ac, &bc, h);
            let (a2, b2) = d2c(&ad, &bd, h).unwrap();
            assert!(
                (&a2 - &ac).amax() < 1e-9,
                "h {h}: A_c error {}",
                (&a2 - &ac).amax()
            );
            assert!(
                (&b2 - &bc).amax() < 1e-9,
                "h {h}: B_c error {}",
                (&b2 - &bc).amax()
            );
        }
    }

    #[test]
    fn negative_real_eigenvalue_and_bad_inputs_are_errors() {
        let a = DMatrix::from_row_slice(2, 2, &[-0.5, 0.0, 0.0, 0.9]);
        let b = DMatrix::from_element(2, 1, 1.0);
        assert!(matches!(
            d2c(&a, &b, 0.1),
            Err(D2cError::NonPositiveRealEigenvalue { value }) if (value + 0.5).abs() < 1e-12
        ));
        let jordan = DMatrix::from_row_slice(2, 2, &[0.9, 1.0, 0.0, 0.9]);
        assert!(matches!(
            d2c(&jordan, &b, 0.1),
            Err(D2cError::NotDiagonalizable { .. })
        ));
        assert_eq!(d2c(&a, &b, 0.0), Err(D2cError::Input { field: "h" }));
        let b3 = DMatrix::from_element(3, 1, 1.0);
        assert_eq!(d2c(&a, &b3, 0.1), Err(D2cError::Input { field: "b" }));
    }
}
