//! Restoring forces g(η) and constant loads estimated jointly with M and D̄
//! from ordinary runs (thesis eq. 1.5–1.6, 2.7–2.9), not only from
//! dedicated attitude holds.
//!
//! With x_G = x_B, y_G = y_B (Fossen 1994, eq. 4.6) g(η) is linear in two
//! constants through two shapes of the attitude:
//!
//! g(η) = [ (W−B)·sθ, −(W−B)·cθ·sφ, −(W−B)·cθ·cφ, (z_G W − z_B B)·cθ·sφ,
//!          (z_G W − z_B B)·sθ, 0 ]ᵀ
//!
//! so M ν̇ + D̄ ν + F·e = τ with e = [1, sin θ, cos θ sin φ] is a linear
//! regression in F alongside A_λ, B_λ ([`crate::estimation::lambda`]). The
//! constant column carries a tether's pull, the heave part −(W−B)cθcφ ≈
//! −(W−B) (cθcφ departs from 1 by under 1 % at 8° of heel) and the offset of
//! the damping's linearization about the grid speed; it differs per grid
//! point. W − B (from surge and sway) and z_G W − z_B B (from roll and pitch)
//! are physical constants: each grid point's estimates are pooled into one
//! value per campaign by inverse variance, the spread between points
//! inflating the std (Birge ratio) when they disagree beyond their own.

use nalgebra::{DMatrix, DVector};

use super::document::{ParameterRow, RestoringDoc};
use crate::estimation::lambda::{Exogenous, LambdaEstimate};
use crate::estimation::restoring::{RestoringEstimate, RestoringParams};
use crate::planning::dof::Dof;
use crate::planning::vessel::VesselProfile;

/// Names of the exogenous columns.
pub(crate) const CONSTANT: &str = "1";
pub(crate) const SIN_THETA: &str = "sin θ";
pub(crate) const COS_THETA_SIN_PHI: &str = "cos θ·sin φ";

/// Which functions the regression carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Functions {
    /// e = [1]: a constant load per DOF.
    Constant,
    /// e = [1, sin θ, cos θ sin φ]: constant loads and g(η)'s shapes.
    ConstantAndRestoring,
}

/// The shapes of one attitude sample η = [x y z φ θ ψ].
fn shapes(eta: &[f64]) -> [f64; 3] {
    let (sp, _) = eta[3].sin_cos();
    let (st, ct) = eta[4].sin_cos();
    [1.0, st, ct * sp]
}

/// e(t) of a segment from its η (N × 6), held over each step like γ: row k
/// is the trapezoid mean ½(e(η_k) + e(η_{k+1})) (the last row e(η_{N−1})),
/// the step average a zero-order-hold model needs of a term that moves with
/// the attitude within the step.
pub(crate) fn functions_of(eta: &DMatrix<f64>, which: Functions) -> DMatrix<f64> {
    let rows = eta.nrows();
    let q = match which {
        Functions::Constant => 1,
        Functions::ConstantAndRestoring => 3,
    };
    let at = |k: usize| {
        let r: Vec<f64> = eta.row(k).iter().copied().collect();
        shapes(&r)
    };
    DMatrix::from_fn(rows, q, |k, j| {
        if k + 1 < rows {
            0.5 * (at(k)[j] + at(k + 1)[j])
        } else {
            at(k)[j]
        }
    })
}

/// The exogenous specification for `dofs`: the constant acts on every DOF,
/// sin θ on surge (W−B) and pitch (z_G W − z_B B), cos θ sin φ on sway and
/// roll. Prior std of F: ten times the DOF's force limit (weak).
pub(crate) fn specification(profile: &VesselProfile, dofs: &[Dof], which: Functions) -> Exogenous {
    let n = dofs.len();
    let names: Vec<String> = match which {
        Functions::Constant => vec![CONSTANT.into()],
        Functions::ConstantAndRestoring => {
            vec![CONSTANT.into(), SIN_THETA.into(), COS_THETA_SIN_PHI.into()]
        }
    };
    let pattern = DMatrix::from_fn(n, names.len(), |i, j| match j {
        0 => true,
        1 => matches!(dofs[i], Dof::Surge | Dof::Pitch),
        _ => matches!(dofs[i], Dof::Sway | Dof::Roll),
    });
    Exogenous {
        names,
        pattern,
        force_std: weak_force_std(profile, dofs),
    }
}

/// Prior std of an exogenous force in each DOF: ten times its force limit,
/// weak, so the data decide.
pub(crate) fn weak_force_std(profile: &VesselProfile, dofs: &[Dof]) -> Vec<f64> {
    dofs.iter()
        .map(|&d| 10.0 * profile.limit(d).max_force.abs().max(1.0))
        .collect()
}

/// No exogenous functions yet, with [`weak_force_std`] priors for those
/// that will be added.
pub(crate) fn no_exogenous(profile: &VesselProfile, dofs: &[Dof]) -> Exogenous {
    Exogenous {
        names: Vec::new(),
        pattern: DMatrix::from_element(dofs.len(), 0, false),
        force_std: weak_force_std(profile, dofs),
    }
}

/// One pooled constant with its evidence.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Pooled {
    /// Inverse-variance mean.
    pub value: f64,
    /// Its std, inflated by the Birge ratio when the inputs disagree.
    pub std: f64,
    /// Number of estimates pooled.
    pub count: usize,
    /// χ²/dof of the estimates about the mean (1 when they agree).
    pub birge_ratio_sq: f64,
}

/// Inverse-variance pooling of (value, std) pairs with finite, positive
/// std; `None` when none is usable.
pub(crate) fn pool(estimates: &[(f64, f64)]) -> Option<Pooled> {
    let usable: Vec<(f64, f64)> = estimates
        .iter()
        .copied()
        .filter(|(v, s)| v.is_finite() && s.is_finite() && *s > 0.0)
        .collect();
    if usable.is_empty() {
        return None;
    }
    let w: f64 = usable.iter().map(|(_, s)| 1.0 / (s * s)).sum();
    let mean = usable.iter().map(|(v, s)| v / (s * s)).sum::<f64>() / w;
    let dof = usable.len().saturating_sub(1);
    let chi2: f64 = usable.iter().map(|(v, s)| ((v - mean) / s).powi(2)).sum();
    let birge = if dof > 0 { chi2 / dof as f64 } else { 1.0 };
    Some(Pooled {
        value: mean,
        std: (1.0 / w).sqrt() * birge.max(1.0).sqrt(),
        count: usable.len(),
        birge_ratio_sq: birge,
    })
}

/// F_ij and its std of one estimate, for DOF `dof` and function `name`.
fn coefficient(est: &LambdaEstimate, dof: Dof, name: &str) -> Option<(f64, f64)> {
    let i = est.dofs.iter().position(|d| *d == dof)?;
    let j = est.exogenous.iter().position(|e| e == name)?;
    Some((est.force[(i, j)], est.std_force[(i, j)]))
}

/// W − B and z_G W − z_B B pooled over grid points and the two DOFs each
/// shows in: W − B = F[surge, sin θ] = −F[sway, cos θ sin φ],
/// z_G W − z_B B = F[roll, cos θ sin φ] = F[pitch, sin θ].
pub(crate) struct PooledRestoring {
    pub weight_minus_buoyancy: Pooled,
    pub metacentric: Pooled,
}

impl PooledRestoring {
    /// The pooled estimates from every grid point's joint fit.
    pub fn from_points(points: &[(f64, LambdaEstimate)]) -> Option<Self> {
        let mut wb = Vec::new();
        let mut bg = Vec::new();
        for (_, est) in points {
            wb.extend(coefficient(est, Dof::Surge, SIN_THETA));
            wb.extend(coefficient(est, Dof::Sway, COS_THETA_SIN_PHI).map(|(v, s)| (-v, s)));
            bg.extend(coefficient(est, Dof::Roll, COS_THETA_SIN_PHI));
            bg.extend(coefficient(est, Dof::Pitch, SIN_THETA));
        }
        Some(PooledRestoring {
            weight_minus_buoyancy: pool(&wb)?,
            metacentric: pool(&bg)?,
        })
    }

    /// Combines with an independent estimate (dedicated static attitude
    /// holds): value and std of W − B and of z_G W − z_B B.
    pub fn with_static(self, params: &RestoringParams, std: &RestoringParams) -> Self {
        let merge = |a: &Pooled, v: f64, s: f64| {
            let p = pool(&[(a.value, a.std), (v, s)]).unwrap_or_else(|| a.clone());
            Pooled {
                count: a.count + 1,
                ..p
            }
        };
        PooledRestoring {
            weight_minus_buoyancy: merge(
                &self.weight_minus_buoyancy,
                params.weight_minus_buoyancy_n,
                std.weight_minus_buoyancy_n,
            ),
            metacentric: merge(
                &self.metacentric,
                params.zg_weight_minus_zb_buoyancy_nm,
                std.zg_weight_minus_zb_buoyancy_nm,
            ),
        }
    }

    /// g(η)'s parameters (no tether moment: constant loads are per point).
    pub fn params(&self) -> RestoringParams {
        RestoringParams {
            weight_minus_buoyancy_n: self.weight_minus_buoyancy.value,
            zg_weight_minus_zb_buoyancy_nm: self.metacentric.value,
            tether_pitch_moment_nm: 0.0,
        }
    }

    /// The model document's g(η): the pooled values and the evidence from
    /// the `joint` fits per grid point and the station-keeping `holds`.
    pub fn doc(
        &self,
        joint: &[(f64, LambdaEstimate)],
        holds: Option<&RestoringEstimate>,
    ) -> RestoringDoc {
        let row = |symbol: &str, p: &Pooled, unit: &str| ParameterRow {
            group: "g(η)".into(),
            symbol: symbol.into(),
            grid_speed_mps: None,
            value: p.value,
            std: Some(p.std),
            unit: unit.into(),
        };
        let (wb, bg) = (&self.weight_minus_buoyancy, &self.metacentric);
        let mut evidence = vec![format!(
            "estimated with M, D̄ and the constant loads from every run where the attitude moves, at {} grid speeds; W − B from surge (sin θ) and sway (cos θ·sin φ): {} estimates, χ²/dof {:.2}; z_G·W − z_B·B from roll and pitch: {} estimates, χ²/dof {:.2}",
            joint.len(),
            wb.count,
            wb.birge_ratio_sq,
            bg.count,
            bg.birge_ratio_sq
        )];
        if let Some(h) = holds {
            evidence.push(format!(
                "sharpened by {} steady segments of station-keeping attitude holds (W − B {:.1} ± {:.1} N, z_G·W − z_B·B {:.2} ± {:.2} N·m on their own)",
                h.segments.len(),
                h.params.weight_minus_buoyancy_n,
                h.std.weight_minus_buoyancy_n,
                h.params.zg_weight_minus_zb_buoyancy_nm,
                h.std.zg_weight_minus_zb_buoyancy_nm
            ));
        }
        RestoringDoc {
            parameters: vec![row("W−B", wb, "N"), row("z_G·W − z_B·B", bg, "N·m")],
            evidence,
            params: self.params(),
        }
    }
}

/// The constant load b and its std of one estimate (column "1" of F).
pub(crate) fn load(est: &LambdaEstimate) -> Option<(DVector<f64>, DVector<f64>)> {
    let j = est.exogenous.iter().position(|e| e == CONSTANT)?;
    Some((
        est.force.column(j).into_owned(),
        est.std_force.column(j).into_owned(),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pooling_is_inverse_variance_and_inflates_on_disagreement() {
        let p = pool(&[(10.0, 1.0), (12.0, 2.0)]).unwrap();
        assert!((p.value - (10.0 + 12.0 / 4.0) / 1.25).abs() < 1e-12);
        // χ² = (0.4)² + (1.6/2)² = 0.8 < 1: no inflation.
        assert!((p.std - (1.0f64 / 1.25).sqrt()).abs() < 1e-12);
        let q = pool(&[(0.0, 1.0), (10.0, 1.0)]).unwrap();
        assert!((q.birge_ratio_sq - 50.0).abs() < 1e-9);
        assert!((q.std - (0.5f64 * 50.0).sqrt()).abs() < 1e-12);
        assert!(pool(&[(f64::NAN, 1.0), (1.0, 0.0)]).is_none());
    }

    #[test]
    fn shapes_are_step_averages_of_the_attitude_functions() {
        let eta = DMatrix::from_row_slice(
            2,
            6,
            &[0.0, 0.0, 0.0, 0.1, 0.2, 0.0, 0.0, 0.0, 0.0, 0.3, -0.2, 0.0],
        );
        let e = functions_of(&eta, Functions::ConstantAndRestoring);
        assert_eq!(e.shape(), (2, 3));
        assert_eq!(e[(0, 0)], 1.0);
        assert!((e[(0, 1)] - 0.5 * (0.2f64.sin() + (-0.2f64).sin())).abs() < 1e-15);
        let last = 0.2f64.cos() * 0.3f64.sin();
        assert!((e[(1, 2)] - last).abs() < 1e-15);
    }
}
