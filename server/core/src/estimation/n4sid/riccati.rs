//! Innovation-form Kalman gain from the residual covariances: the filter
//! DARE with cross covariance S, solved by the structure-preserving doubling
//! algorithm (Chu, Fan & Lin 2005), quadratically convergent.
//!
//! P = A P Aᵀ + Q − (A P Cᵀ + S)(C P Cᵀ + R)⁻¹(A P Cᵀ + S)ᵀ,
//! K = (A P Cᵀ + S)(C P Cᵀ + R)⁻¹, innovation covariance C P Cᵀ + R.
//! S is removed first (Ā = A − S R⁻¹ C, Q̄ = Q − S R⁻¹ Sᵀ), leaving the
//! standard form P = Ā P (I + G P)⁻¹ Āᵀ + Q̄ with G = Cᵀ R⁻¹ C.

use nalgebra::DMatrix;

use super::error::N4sidError;

/// Solution of the filter Riccati equation.
#[derive(Debug, Clone)]
pub struct KalmanGain {
    /// Steady-state one-step prediction error covariance P (n × n).
    pub p: DMatrix<f64>,
    /// Innovation-form gain K (n × l).
    pub k: DMatrix<f64>,
    /// Innovation covariance C P Cᵀ + R (l × l).
    pub innovation_covariance: DMatrix<f64>,
}

fn riccati_err(reason: &str) -> N4sidError {
    N4sidError::Riccati {
        reason: reason.to_string(),
    }
}

/// K, P and the innovation covariance for x⁺ = A x + w, y = C x + v with
/// E[w wᵀ] = Q, E[w vᵀ] = S, E[v vᵀ] = R.
pub fn kalman_gain(
    a: &DMatrix<f64>,
    c: &DMatrix<f64>,
    q: &DMatrix<f64>,
    s: &DMatrix<f64>,
    r: &DMatrix<f64>,
) -> Result<KalmanGain, N4sidError> {
    let n = a.nrows();
    let r_chol = r
        .clone()
        .cholesky()
        .ok_or_else(|| riccati_err("measurement residual covariance R is not positive definite"))?;
    let r_inv = r_chol.inverse();
    let abar = a - s * &r_inv * c;
    let qbar = q - s * &r_inv * s.transpose();
    let sym = |m: &DMatrix<f64>| (m + m.transpose()) * 0.5;
    let mut ak = abar.transpose();
    let mut gk = sym(&(c.transpose() * &r_inv * c));
    let mut hk = sym(&qbar);
    let eye = DMatrix::<f64>::identity(n, n);
    let mut converged = false;
    for _ in 0..100 {
        let w = (&eye + &gk * &hk)
            .lu()
            .try_inverse()
            .ok_or_else(|| riccati_err("I + G H singular in the doubling"))?;
        let a_w = &ak * &w;
        let h_next = sym(&(&hk + ak.transpose() * &hk * &w * &ak));
        let g_next = sym(&(&gk + &a_w * &gk * ak.transpose()));
        let a_next = &a_w * &ak;
        let change = (&h_next - &hk).amax();
        let size = h_next.amax().max(f64::MIN_POSITIVE);
        hk = h_next;
        gk = g_next;
        ak = a_next;
        if !hk.iter().all(|v| v.is_finite()) {
            return Err(riccati_err("doubling diverged (no stabilizing solution)"));
        }
        if change <= 1e-14 * size {
            converged = true;
            break;
        }
    }
    if !converged {
        return Err(riccati_err("doubling did not converge in 100 iterations"));
    }
    let p = hk;
    let re = sym(&(c * &p * c.transpose() + r));
    let re_inv = re
        .clone()
        .cholesky()
        .ok_or_else(|| riccati_err("innovation covariance not positive definite"))?
        .inverse();
    let k = (a * &p * c.transpose() + s) * re_inv;
    Ok(KalmanGain {
        p,
        k,
        innovation_covariance: re,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn doubling_matches_the_iterated_riccati_recursion_with_cross_covariance() {
        let a = DMatrix::from_row_slice(3, 3, &[0.9, 0.3, 0.0, -0.2, 0.8, 0.1, 0.0, 0.05, 1.02]);
        let c = DMatrix::from_row_slice(2, 3, &[1.0, 0.0, 0.5, 0.0, 1.0, -1.0]);
        let g = DMatrix::from_row_slice(
            5,
            5,
            &[
                1.0, 0.2, 0.0, 0.1, 0.0, 0.2, 0.5, 0.1, 0.0, 0.05, 0.0, 0.1, 0.3, 0.02, 0.0, 0.1,
                0.0, 0.02, 0.4, 0.1, 0.0, 0.05, 0.0, 0.1, 0.6,
            ],
        );
        let cov = &g * g.transpose();
        let q = cov.view((0, 0), (3, 3)).into_owned();
        let s = cov.view((0, 3), (3, 2)).into_owned();
        let r = cov.view((3, 3), (2, 2)).into_owned();
        let kg = kalman_gain(&a, &c, &q, &s, &r).unwrap();
        // Truth: the time-varying Riccati recursion run to its fixed point
        // (the plant has an unstable mode, the filter is stable).
        let mut p = DMatrix::<f64>::identity(3, 3);
        let mut k = DMatrix::zeros(3, 2);
        for _ in 0..5000 {
            let re = &c * &p * c.transpose() + &r;
            k = (&a * &p * c.transpose() + &s) * re.clone().try_inverse().unwrap();
            p = &a * &p * a.transpose() + &q - &k * re * k.transpose();
        }
        assert!(
            (&kg.p - &p).amax() < 1e-10 * p.amax(),
            "P {} vs {}",
            kg.p,
            p
        );
        assert!((&kg.k - &k).amax() < 1e-10, "K {} vs {}", kg.k, k);
        let closed = &a - &kg.k * &c;
        let rho = closed
            .complex_eigenvalues()
            .iter()
            .map(|z| z.norm())
            .fold(0.0, f64::max);
        assert!(rho < 1.0, "A − K C must be stable, ρ = {rho}");
    }

    #[test]
    fn singular_measurement_covariance_is_an_error() {
        let a = DMatrix::from_element(1, 1, 0.5);
        let c = DMatrix::from_element(1, 1, 1.0);
        let z = DMatrix::zeros(1, 1);
        assert!(matches!(
            kalman_gain(&a, &c, &z, &z, &z),
            Err(N4sidError::Riccati { .. })
        ));
    }
}
