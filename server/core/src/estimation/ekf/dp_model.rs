//! The momentum-form DP model with bias for the EKF (Fossen et al. 1995,
//! eq. 35–38, 44–45): per run x = [h; η; b_h] (n = 9),
//!
//! ḣ = −C(ν)·ν + A_h(θ″)·h + T·K(θ″)·u + b_h,  ν = M⁻¹·h,
//! η̇ = J(ψ)·ν,   ḃ_h = 0 (+ w_b),   z = [x, y, ψ] = H·x,
//!
//! with M and T known and a chosen subset of θ″1 … θ″9 (eq. 46–47) free; the
//! others are frozen at given values (earlier stages, Fig. 4).

use nalgebra::{DMatrix, Matrix3, Vector3};

use super::model::ContinuousRunModel;
use crate::simulation::dp_ship::model::{
    N_THETA, ThrustLayout, a_h_from_theta, coriolis_force, coriolis_force_jacobian, rotation,
};

/// States per run: h (3), η (3), b_h (3).
pub const DP_STATES: usize = 9;

/// The momentum-form DP ship with a free subset of θ″.
#[derive(Debug, Clone)]
pub struct DpMomentumModel {
    m: Matrix3<f64>,
    m_inv: Matrix3<f64>,
    thrust: ThrustLayout,
    frozen: [f64; N_THETA],
    free: Vec<usize>,
    h_meas: DMatrix<f64>,
}

impl DpMomentumModel {
    /// Known M and thrust layout; θ″ values `frozen` for the parameters not in `free`
    /// (indices 0–8 into θ″1 … θ″9). Panics on an invalid M or index; the
    /// staged identification validates both first.
    pub fn new(
        m: Matrix3<f64>,
        thrust: ThrustLayout,
        frozen: [f64; N_THETA],
        free: Vec<usize>,
    ) -> Self {
        assert!(free.iter().all(|&f| f < N_THETA), "θ″ index out of range");
        let m_inv = m.try_inverse().expect("M must be invertible");
        let mut h_meas = DMatrix::zeros(3, DP_STATES);
        for j in 0..3 {
            h_meas[(j, 3 + j)] = 1.0;
        }
        DpMomentumModel {
            m,
            m_inv,
            thrust,
            frozen,
            free,
            h_meas,
        }
    }

    /// Full θ″ with the free entries taken from `theta`.
    pub fn full_theta(&self, theta: &[f64]) -> [f64; N_THETA] {
        let mut full = self.frozen;
        for (c, &f) in self.free.iter().enumerate() {
            full[f] = theta[c];
        }
        full
    }
}

impl ContinuousRunModel for DpMomentumModel {
    fn n_states(&self) -> usize {
        DP_STATES
    }
    fn n_params(&self) -> usize {
        self.free.len()
    }
    fn n_inputs(&self) -> usize {
        self.thrust.columns()
    }
    fn measurement_matrix(&self) -> &DMatrix<f64> {
        &self.h_meas
    }
    fn angle_outputs(&self) -> &[usize] {
        &[2]
    }

    fn derivative(
        &self,
        x: &[f64],
        u: &[f64],
        theta: &[f64],
        dx: &mut [f64],
        g_x: &mut DMatrix<f64>,
        g_theta: &mut DMatrix<f64>,
    ) {
        let full = self.full_theta(theta);
        let a_h = a_h_from_theta(&full);
        let h = Vector3::new(x[0], x[1], x[2]);
        let psi = x[5];
        let b = Vector3::new(x[6], x[7], x[8]);
        let nu = self.m_inv * h;
        let mut tau = Vector3::zeros();
        for (j, &g) in self.thrust.groups.iter().enumerate() {
            tau += self.thrust.t.fixed_view::<3, 1>(0, j) * (full[5 + g] * u[j]);
        }
        let h_dot = -coriolis_force(&self.m, &nu) + a_h * h + tau + b;
        let rot = rotation(psi);
        let eta_dot = rot * nu;
        dx[..3].copy_from_slice(h_dot.as_slice());
        dx[3..6].copy_from_slice(eta_dot.as_slice());
        dx[6..].fill(0.0);

        g_x.fill(0.0);
        let dh_dh = a_h - coriolis_force_jacobian(&self.m, &nu) * self.m_inv;
        let deta_dh = rot * self.m_inv;
        let (s, c) = psi.sin_cos();
        let deta_dpsi = Vector3::new(-s * nu[0] - c * nu[1], c * nu[0] - s * nu[1], 0.0);
        for i in 0..3 {
            for j in 0..3 {
                g_x[(i, j)] = dh_dh[(i, j)];
                g_x[(3 + i, j)] = deta_dh[(i, j)];
            }
            g_x[(i, 6 + i)] = 1.0;
            g_x[(3 + i, 5)] = deta_dpsi[i];
        }

        // ∂ḣ/∂θ″ (eq. 46–47); η̇ and ḃ_h do not depend on θ″.
        g_theta.fill(0.0);
        for (col, &f) in self.free.iter().enumerate() {
            let d = match f {
                0 => Vector3::new(h[0], 0.0, 0.0),
                1 => Vector3::new(0.0, h[1], 0.0),
                2 => Vector3::new(0.0, h[2], 0.0),
                3 => Vector3::new(0.0, 0.0, h[1]),
                4 => Vector3::new(0.0, 0.0, h[2]),
                g => self.thrust.group_force(g - 5, u),
            };
            for i in 0..3 {
                g_theta[(i, col)] = d[i];
            }
        }
    }
}
