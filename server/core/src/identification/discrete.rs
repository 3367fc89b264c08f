//! ZOH-discretized matrices of a model document at a chosen sample time h,
//! for controller design (MPC at the controller's rate).

use serde::Serialize;

use super::document::{Matrix, ModelDocument, ModelKind, from_rows, to_rows};
use crate::models::state_space::StateSpace;

/// Φ, Γ of ν(k+1) = Φ ν(k) + Γ γ(k) at one operating point.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct DiscretePoint {
    /// Forward speed (m/s) of the LPV sub-model; absent for a DP ship.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub speed_mps: Option<f64>,
    /// Φ = e^{Ah}.
    pub phi: Matrix,
    /// Γ = ∫₀ʰ e^{As} ds · B.
    pub gamma: Matrix,
}

/// The discretized model.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct DiscreteModel {
    /// Sample time h (s).
    pub h: f64,
    /// One pair per operating point.
    pub points: Vec<DiscretePoint>,
}

fn zoh(a: &Matrix, b: &Matrix, h: f64, speed: Option<f64>) -> Result<DiscretePoint, String> {
    let a = from_rows(a).ok_or("A is ragged")?;
    let b = from_rows(b).ok_or("B is ragged")?;
    let (n, m) = (a.nrows(), b.ncols());
    let ss = StateSpace::new(
        a,
        b,
        nalgebra::DMatrix::identity(n, n),
        nalgebra::DMatrix::zeros(n, m),
    )
    .and_then(|s| s.discretize_zoh(h))
    .map_err(|e| e.to_string())?;
    Ok(DiscretePoint {
        speed_mps: speed,
        phi: to_rows(ss.phi()),
        gamma: to_rows(ss.gamma()),
    })
}

/// Φ, Γ at sample time `h` (s) for every operating point of a physical model.
/// A subspace model is already discrete at its own h: `Err` unless `h`
/// equals it (resampling a black box is not exact).
pub fn discretize(doc: &ModelDocument, h: f64) -> Result<DiscreteModel, String> {
    if !(h.is_finite() && h > 0.0) {
        return Err(format!("h must be a positive number of seconds, got {h}"));
    }
    let points = match doc.kind {
        ModelKind::Lpv => {
            let lpv = doc.lpv.as_ref().ok_or("the LPV model has no grid points")?;
            lpv.points
                .iter()
                .map(|p| zoh(&p.a, &p.b, h, Some(p.speed_mps)))
                .collect::<Result<Vec<_>, _>>()?
        }
        ModelKind::DpShip => {
            // The SI A, B: h is in seconds, ν in m/s and rad/s.
            let s = doc.dp_ship.as_ref().ok_or("the DP model is missing")?;
            vec![zoh(&s.a_si, &s.b_si, h, None)?]
        }
        ModelKind::StateSpace => {
            let s = doc
                .state_space
                .as_ref()
                .ok_or("the state-space model is missing")?;
            if (s.h - h).abs() > 1e-9 * s.h {
                return Err(format!(
                    "a subspace model is discrete at its own h = {} s; it cannot be resampled exactly to {h} s",
                    s.h
                ));
            }
            vec![DiscretePoint {
                speed_mps: None,
                phi: s.phi.clone(),
                gamma: s.gamma.clone(),
            }]
        }
    };
    Ok(DiscreteModel { h, points })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identification::tests::lpv_doc;
    use crate::planning::dof::Dof;

    #[test]
    fn scalar_lpv_points_match_the_analytic_zoh() {
        // ν̇ = −(D/M) ν + γ/M: Φ = e^{−Dh/M}, Γ = (1 − Φ)/D.
        let (m, d, h) = (2000.0, 500.0, 0.1);
        let doc = lpv_doc(
            vec![Dof::Surge],
            vec![
                (0.5, vec![vec![m]], vec![vec![d]]),
                (1.0, vec![vec![m]], vec![vec![2.0 * d]]),
            ],
        );
        let dm = discretize(&doc, h).unwrap();
        for (p, d) in dm.points.iter().zip([d, 2.0 * d]) {
            let phi = (-d * h / m).exp();
            assert!((p.phi[0][0] - phi).abs() < 1e-14);
            assert!((p.gamma[0][0] - (1.0 - phi) / d).abs() < 1e-15);
        }
        assert_eq!(dm.points[1].speed_mps, Some(1.0));
        assert!(discretize(&doc, 0.0).unwrap_err().contains("positive"));
    }
}
