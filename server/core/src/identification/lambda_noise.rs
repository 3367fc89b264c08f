//! The regressors' errors that the measured attitude's noise puts into the
//! λ identification's columns: through the restoring shapes of the joint
//! fit, or through γ = τ − g(η) once g(η) is known (discounted by
//! bias-compensated least squares).

use nalgebra::{DMatrix, DVector};

use super::joint_restoring::{COS_THETA_SIN_PHI, SIN_THETA};
use crate::estimation::lambda::RegressorNoise;
use crate::estimation::restoring::RestoringParams;

/// The errors of the restoring shapes [1, sin θ, cos θ sin φ] among the
/// exogenous columns `names` (after 2n columns of ν and γ): e_θ and e_φ of
/// std `sd` = [σ_φ, σ_θ], held over each step.
pub(crate) fn attitude_shape_noise(n: usize, names: &[String], sd: [f64; 2]) -> RegressorNoise {
    let p = 2 * n + names.len();
    let mut cov = DMatrix::zeros(p, p);
    for (j, name) in names.iter().enumerate() {
        let var = match name.as_str() {
            COS_THETA_SIN_PHI => sd[0] * sd[0],
            SIN_THETA => sd[1] * sd[1],
            _ => 0.0,
        };
        cov[(2 * n + j, 2 * n + j)] = var;
    }
    RegressorNoise::held_over_step(cov)
}

/// The errors of γ = τ − g(η) (six DOFs, in [`Dof::ALL`] order) from the
/// attitude noise `sd` = [σ_φ, σ_θ] through g's slopes at level attitude:
/// ∂g/∂φ = (0, −(W−B), 0, z_G W − z_B B, 0, 0), ∂g/∂θ = (W−B, 0, 0, 0,
/// z_G W − z_B B, 0); held over each step. q exogenous columns follow.
pub(crate) fn restoring_noise(
    n: usize,
    q: usize,
    g: &RestoringParams,
    sd: [f64; 2],
) -> RegressorNoise {
    let p = 2 * n + q;
    let mut cov = DMatrix::zeros(p, p);
    if n == 6 {
        let (wb, bg) = (g.weight_minus_buoyancy_n, g.zg_weight_minus_zb_buoyancy_nm);
        let slopes = [
            (
                DVector::from_column_slice(&[0.0, -wb, 0.0, bg, 0.0, 0.0]),
                sd[0],
            ),
            (
                DVector::from_column_slice(&[wb, 0.0, 0.0, 0.0, bg, 0.0]),
                sd[1],
            ),
        ];
        for (j, s) in slopes {
            let block = &j * j.transpose() * (s * s);
            let mut view = cov.view_mut((n, n), (n, n));
            view += block;
        }
    }
    RegressorNoise::held_over_step(cov)
}
