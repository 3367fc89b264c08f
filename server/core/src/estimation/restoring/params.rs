//! The restoring forces and moments g(η) of a vehicle with its centre of
//! buoyancy above the centre of gravity on the body z-axis (thesis eq. 1.5),
//! augmented by the tether's constant pitch moment τ_θ (eq. 1.6), and the
//! input γ = τ − g(η) that the dynamic identification works on (eq. 2.8).

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::error::RestoringError;

/// The constant entries of g(η) (thesis eq. 1.6, Fossen's SNAME signs with
/// z down):
///
/// g(η) = [ (W−B)·sθ, −(W−B)·cθ·sφ, −(W−B)·cθ·cφ,
///          (z_G·W − z_B·B)·cθ·sφ, (z_G·W − z_B·B)·sθ + τ_θ, 0 ]ᵀ
///
/// This is Fossen's general g(η) (1994, eq. 4.6) with x_G = x_B = y_G =
/// y_B = 0, plus the tether moment.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct RestoringParams {
    /// W − B (N): weight minus buoyancy, > 0 for a heavy vehicle.
    pub weight_minus_buoyancy_n: f64,
    /// z_G·W − z_B·B (N·m): the righting lever times force (metacentric
    /// term); > 0 when the centre of buoyancy is above the centre of gravity.
    pub zg_weight_minus_zb_buoyancy_nm: f64,
    /// τ_θ (N·m): constant pitch moment of the tether, entered in g(η) like
    /// the thesis (eq. 1.6), i.e. the pitch moment the thrusters supply to
    /// hold a level attitude against it.
    pub tether_pitch_moment_nm: f64,
}

impl RestoringParams {
    /// g(η) for η = [x y z φ θ ψ] (m, rad); positions and ψ do not enter.
    pub fn g(&self, eta: &[f64; 6]) -> [f64; 6] {
        let (phi, theta) = (eta[3], eta[4]);
        let (sphi, cphi) = phi.sin_cos();
        let (sth, cth) = theta.sin_cos();
        let wb = self.weight_minus_buoyancy_n;
        let bg = self.zg_weight_minus_zb_buoyancy_nm;
        [
            wb * sth,
            -wb * cth * sphi,
            -wb * cth * cphi,
            bg * cth * sphi,
            bg * sth + self.tether_pitch_moment_nm,
            0.0,
        ]
    }

    /// γ = τ − g(η) (thesis eq. 2.8) for a whole record: `tau` and `eta`
    /// are N × 6, one row per sample; the result is N × 6.
    ///
    /// Row k holds τ_k − ½(g(η_k) + g(η_k+1)) (the last row g(η_N−1)): the
    /// models downstream hold γ over [t_k, t_k+1) (ZOH), which is exact for
    /// the commanded τ but not for g(η(t)), which moves within the step; its
    /// mean over the step is the trapezoid to second order. Taking g(η_k)
    /// instead lags the restoring by h/2 and shows up as extra damping in
    /// roll and pitch (≈ K·h/2: +25 % at 10 Hz on a stiff ROV).
    pub fn gamma(
        &self,
        tau: &DMatrix<f64>,
        eta: &DMatrix<f64>,
    ) -> Result<DMatrix<f64>, RestoringError> {
        for (field, m) in [("tau", tau), ("eta", eta)] {
            if m.ncols() != 6 {
                return Err(RestoringError::invalid(
                    field,
                    format!("needs 6 columns, has {}", m.ncols()),
                ));
            }
        }
        if tau.nrows() != eta.nrows() {
            return Err(RestoringError::invalid(
                "eta",
                format!("has {} rows, tau has {}", eta.nrows(), tau.nrows()),
            ));
        }
        let n = tau.nrows();
        let g: Vec<[f64; 6]> = (0..n)
            .map(|i| self.g(&[0, 1, 2, 3, 4, 5].map(|j| eta[(i, j)])))
            .collect();
        let mut out = tau.clone();
        for i in 0..n {
            let next = &g[(i + 1).min(n - 1)];
            for j in 0..6 {
                out[(i, j)] -= 0.5 * (g[i][j] + next[j]);
            }
        }
        Ok(out)
    }
}
