//! Hankel singular values: σᵢ = √λᵢ(P Q) of the controllability and
//! observability Gramians, the energy each state direction passes from
//! inputs to outputs (what balanced truncation keeps). P, Q solve the
//! Lyapunov equations A P + P Aᵀ + B Bᵀ = 0, Aᵀ Q + Q A + Cᵀ C = 0
//! (continuous) or P = A P Aᵀ + B Bᵀ, Q = Aᵀ Q A + Cᵀ C (discrete), here by
//! their Kronecker form. They exist for stable models only. An N4SID
//! model's document also carries the singular values of its weighted
//! oblique projection, which chose its order; they come alongside.

use nalgebra::DMatrix;
use serde::Serialize;

use super::poles::{is_stable_root, poles};
use super::{LinearModel, LinearModels};
use crate::identification::document::{ModelDocument, ModelKind};

/// Largest order solved (the Kronecker system is n² × n²).
pub const MAX_ORDER: usize = 30;

/// Solves the Lyapunov equation of (A, W) for X: continuous
/// A X + X Aᵀ + W = 0, discrete X − A X Aᵀ = W.
pub fn lyapunov(a: &DMatrix<f64>, w: &DMatrix<f64>, continuous: bool) -> Option<DMatrix<f64>> {
    let n = a.nrows();
    let eye = DMatrix::<f64>::identity(n, n);
    // vec(A X Bᵀ) = (B ⊗ A) vec(X), column-major vec.
    let k = if continuous {
        eye.kronecker(a) + a.kronecker(&eye)
    } else {
        DMatrix::identity(n * n, n * n) - a.kronecker(a)
    };
    let rhs = if continuous { -w.clone() } else { w.clone() };
    let v = nalgebra::DVector::from_column_slice(rhs.as_slice());
    let x = k.lu().solve(&v)?;
    let x = DMatrix::from_column_slice(n, n, x.as_slice());
    // Symmetric by construction; average away the rounding.
    Some((&x + x.transpose()) * 0.5)
}

/// Hankel singular values of a stable model, descending; `Err` says why
/// there are none.
pub fn hankel_singular_values(m: &LinearModel) -> Result<Vec<f64>, String> {
    let n = m.n_states();
    if n == 0 {
        return Ok(Vec::new());
    }
    if n > MAX_ORDER {
        return Err(format!(
            "order {n} is above the {MAX_ORDER} states solved here"
        ));
    }
    if let Some(z) = poles(m)
        .into_iter()
        .find(|z| !is_stable_root(*z, m.continuous()))
    {
        return Err(format!(
            "the model is not stable (pole {:.4} {} {:.4}j {}): its Gramians do not exist",
            z.re,
            if z.im < 0.0 { '−' } else { '+' },
            z.im.abs(),
            if m.continuous() {
                "in the right half plane or on the axis"
            } else {
                "on or outside the unit circle"
            }
        ));
    }
    let c = m.continuous();
    let p = lyapunov(&m.a, &(&m.b * m.b.transpose()), c)
        .ok_or("the controllability Lyapunov equation is singular")?;
    let q = lyapunov(&m.a.transpose(), &(m.c.transpose() * &m.c), c)
        .ok_or("the observability Lyapunov equation is singular")?;
    let mut s: Vec<f64> = (p * q)
        .complex_eigenvalues()
        .iter()
        .map(|z| z.re.max(0.0).sqrt())
        .collect();
    s.sort_by(|a, b| b.total_cmp(a));
    Ok(s)
}

/// The Hankel singular values of one operating point.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct HankelPoint {
    /// Grid forward speed (m/s) of an LPV point.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub grid_speed_mps: Option<f64>,
    /// Sample time (s) of the (discretized) model; 0 for continuous.
    pub sample_time_s: f64,
    /// σ₁ ≥ σ₂ ≥ … (empty when undefined).
    pub values: Vec<f64>,
    /// Why there are none (an unstable model).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub undefined: Option<String>,
}

/// An N4SID model's subspace singular values and the order they chose.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct SubspaceValues {
    /// Singular values of W₁ O_i W₂, descending.
    pub values: Vec<f64>,
    /// The order chosen (values beyond it are taken as noise).
    pub order: usize,
}

/// Hankel singular values of every point, and an N4SID model's subspace
/// singular values.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct HankelView {
    /// One entry per operating point.
    pub points: Vec<HankelPoint>,
    /// The N4SID order choice (absent for other kinds).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub subspace: Option<SubspaceValues>,
}

/// The view of a model's points.
pub fn hankel_view(doc: &ModelDocument, models: &LinearModels) -> HankelView {
    let points = models
        .points
        .iter()
        .map(|(speed, m)| {
            let (values, undefined) = match hankel_singular_values(m) {
                Ok(v) => (v, None),
                Err(e) => (Vec::new(), Some(e)),
            };
            HankelPoint {
                grid_speed_mps: *speed,
                sample_time_s: m.sample_time_s,
                values,
                undefined,
            }
        })
        .collect();
    let subspace = match (doc.kind, &doc.state_space) {
        (ModelKind::StateSpace, Some(s)) => Some(SubspaceValues {
            values: s
                .singular_values
                .iter()
                .copied()
                .filter(|v| v.is_finite())
                .collect(),
            order: s.order,
        }),
        _ => None,
    };
    HankelView { points, subspace }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scalar(a: f64, b: f64, c: f64, h: f64) -> LinearModel {
        let one = |v: f64| DMatrix::from_element(1, 1, v);
        LinearModel {
            a: one(a),
            b: one(b),
            c: one(c),
            d: one(0.0),
            sample_time_s: h,
        }
    }

    #[test]
    fn first_order_values_are_the_closed_forms() {
        // ẋ = −a x + b u, y = c x: P = b²/2a, Q = c²/2a, σ = |b c| / 2a.
        let s = hankel_singular_values(&scalar(-0.5, 2.0, 3.0, 0.0)).unwrap();
        assert!((s[0] - 6.0).abs() < 1e-12, "{s:?}");
        // x⁺ = φ x + γ u: σ = |γ c| / (1 − φ²).
        let s = hankel_singular_values(&scalar(0.6, 2.0, 0.5, 0.1)).unwrap();
        assert!((s[0] - 1.0 / 0.64).abs() < 1e-12, "{s:?}");
    }

    #[test]
    fn decoupled_lags_give_their_own_values_and_unstable_has_none() {
        let m = LinearModel {
            a: DMatrix::from_diagonal(&nalgebra::dvector![-1.0, -4.0]),
            b: DMatrix::identity(2, 2),
            c: DMatrix::identity(2, 2),
            d: DMatrix::zeros(2, 2),
            sample_time_s: 0.0,
        };
        let s = hankel_singular_values(&m).unwrap();
        assert!(
            (s[0] - 0.5).abs() < 1e-12 && (s[1] - 0.125).abs() < 1e-12,
            "{s:?}"
        );
        let e = hankel_singular_values(&scalar(0.1, 1.0, 1.0, 0.0)).unwrap_err();
        assert!(e.contains("not stable"), "{e}");
        let e = hankel_singular_values(&scalar(1.0, 1.0, 1.0, 0.1)).unwrap_err();
        assert!(e.contains("unit circle"), "{e}");
    }

    #[test]
    fn discrete_lyapunov_matches_the_series() {
        // P = Σ Aᵏ B Bᵀ Aᵀᵏ for a 2 × 2 stable A.
        let a = DMatrix::from_row_slice(2, 2, &[0.5, 0.2, -0.1, 0.3]);
        let b = DMatrix::from_row_slice(2, 1, &[1.0, 2.0]);
        let w = &b * b.transpose();
        let p = lyapunov(&a, &w, false).unwrap();
        let mut sum = DMatrix::zeros(2, 2);
        let mut ak = DMatrix::identity(2, 2);
        for _ in 0..200 {
            sum += &ak * &w * ak.transpose();
            ak = &a * ak;
        }
        assert!((p - sum).abs().max() < 1e-12);
    }
}
