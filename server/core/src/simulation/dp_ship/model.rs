//! The 3-DOF low-frequency DP ship in momentum form (Fossen et al. 1995,
//! eq. 26–40), in any consistent units (the supply vessel uses the Bis
//! system):
//!
//! ḣ = −C_h(h)·h + A_h·h + T·K·u + b_h,   η̇ = J(ψ)·M⁻¹·h,
//!
//! with h = M·ν the momentum, A_h = −D·M⁻¹ (eq. 39) and the rigid-body plus
//! added-mass Coriolis term of eq. 11 written through ν = M⁻¹h, so that
//! C_h(h)·h = C(ν)·ν exactly as in the ν-form eq. 8 (the OCR of eq. 40 reads
//! C_h(h) = C(M⁻¹h); the factor M⁻¹ on h is what makes the two forms agree).
//! C depends on M only, so it adds no parameter. The paper's identification
//! model (eq. 35) includes C_h; its state-space form (eq. 50–52) drops it
//! (C_h = 0), as [`DpShip::state_space_a`] and [`DpShip::state_space_b`] do.

use nalgebra::{Matrix3, SMatrix, Vector3, Vector6};

use super::paper;

/// T″-shaped matrices: 3 DOFs × 6 thrusters.
pub type Matrix3x6 = SMatrix<f64, 3, 6>;

/// Number of identified parameters θ″ (eq. 46–47).
pub const N_THETA: usize = 9;

/// Names of θ″1 … θ″9 in the paper's notation (eq. 46–47).
pub const THETA_NAMES: [&str; N_THETA] = [
    "A_h11", "A_h22", "A_h23", "A_h32", "A_h33", "K1=K2", "K3=K4", "K5", "K6",
];

/// A DP ship: known M and T, and the parameters A_h and K that the EKF
/// identifies.
#[derive(Debug, Clone, PartialEq)]
pub struct DpShip {
    /// Inertia including added mass, M = Mᵀ > 0 (eq. 9, 30).
    pub m: Matrix3<f64>,
    /// Thruster configuration T (eq. 7, 29).
    pub t: Matrix3x6,
    /// Momentum-equation matrix A_h = −D·M⁻¹ (eq. 39).
    pub a_h: Matrix3<f64>,
    /// Diagonal of the thrust coefficients K (eq. 6).
    pub k: Vector6<f64>,
}

impl DpShip {
    /// The supply vessel of sec. 4 with the identified values (eq. 29, 30, 48, 49).
    pub fn supply_vessel() -> Self {
        DpShip {
            m: Matrix3::from_fn(|i, j| paper::M_INERTIA[i][j]),
            t: Matrix3x6::from_fn(|i, j| paper::T_CONFIG[i][j]),
            a_h: Matrix3::from_fn(|i, j| paper::A_H[i][j]),
            k: Vector6::from_column_slice(&paper::K_THRUST),
        }
    }

    /// A ship with known M, T and parameters θ″ (eq. 46–47).
    pub fn from_theta(m: Matrix3<f64>, t: Matrix3x6, theta: &[f64; N_THETA]) -> Self {
        DpShip {
            m,
            t,
            a_h: a_h_from_theta(theta),
            k: k_from_theta(theta),
        }
    }

    /// θ″ of this ship (eq. 46–47); K1 stands for K1 = K2 and K3 for K3 = K4.
    pub fn theta(&self) -> [f64; N_THETA] {
        let a = &self.a_h;
        let k = &self.k;
        [
            a[(0, 0)],
            a[(1, 1)],
            a[(1, 2)],
            a[(2, 1)],
            a[(2, 2)],
            k[0],
            k[2],
            k[4],
            k[5],
        ]
    }

    /// M⁻¹ (M is positive definite by construction of a ship).
    pub fn m_inv(&self) -> Matrix3<f64> {
        self.m
            .try_inverse()
            .expect("inertia matrix M must be invertible")
    }

    /// Linear damping D = −A_h·M (from eq. 39).
    pub fn damping(&self) -> Matrix3<f64> {
        -self.a_h * self.m
    }

    /// State-space A = M⁻¹·A_h·M of ν̇ = A·ν + B·u (eq. 50–51, C_h = 0).
    pub fn state_space_a(&self) -> Matrix3<f64> {
        self.m_inv() * self.a_h * self.m
    }

    /// State-space B = M⁻¹·T·K (eq. 50, 52).
    pub fn state_space_b(&self) -> Matrix3x6 {
        self.m_inv() * self.thrust_matrix()
    }

    /// T·K: the map from thruster commands u to τ (eq. 4).
    pub fn thrust_matrix(&self) -> Matrix3x6 {
        let mut tk = self.t;
        for j in 0..6 {
            tk.column_mut(j).scale_mut(self.k[j]);
        }
        tk
    }

    /// Momentum derivative ḣ = −C(ν)ν + A_h·h + T·K·u + b_h (eq. 35 without w_h).
    pub fn h_dot(
        &self,
        m_inv: &Matrix3<f64>,
        h: &Vector3<f64>,
        u: &[f64],
        b: &Vector3<f64>,
    ) -> Vector3<f64> {
        let nu = m_inv * h;
        let tau = self.thrust_matrix() * Vector6::from_column_slice(u);
        -coriolis_force(&self.m, &nu) + self.a_h * h + tau + b
    }
}

/// A_h from θ″1 … θ″5 (eq. 46).
pub fn a_h_from_theta(theta: &[f64; N_THETA]) -> Matrix3<f64> {
    Matrix3::new(
        theta[0], 0.0, 0.0, //
        0.0, theta[1], theta[2], //
        0.0, theta[3], theta[4],
    )
}

/// K = diag{θ″6, θ″6, θ″7, θ″7, θ″8, θ″9} (eq. 47).
pub fn k_from_theta(theta: &[f64; N_THETA]) -> Vector6<f64> {
    Vector6::new(theta[5], theta[5], theta[6], theta[6], theta[7], theta[8])
}

/// Coriolis and centripetal matrix C(ν) of eq. 11 from the elements of M
/// (eq. 12): skew-symmetric, so it does no work (νᵀC(ν)ν = 0).
pub fn coriolis(m: &Matrix3<f64>, nu: &Vector3<f64>) -> Matrix3<f64> {
    let (m11, m22, m23) = (m[(0, 0)], m[(1, 1)], m[(1, 2)]);
    let (u, v, r) = (nu[0], nu[1], nu[2]);
    let c13 = -m22 * v - m23 * r;
    let c23 = m11 * u;
    Matrix3::new(
        0.0, 0.0, c13, //
        0.0, 0.0, c23, //
        -c13, -c23, 0.0,
    )
}

/// C(ν)·ν, the Coriolis force of eq. 8.
pub fn coriolis_force(m: &Matrix3<f64>, nu: &Vector3<f64>) -> Vector3<f64> {
    coriolis(m, nu) * nu
}

/// ∂(C(ν)·ν)/∂ν, for the EKF's transition Jacobian.
pub fn coriolis_force_jacobian(m: &Matrix3<f64>, nu: &Vector3<f64>) -> Matrix3<f64> {
    let (m11, m22, m23) = (m[(0, 0)], m[(1, 1)], m[(1, 2)]);
    let (u, v, r) = (nu[0], nu[1], nu[2]);
    // C(ν)ν = [(−m22 v − m23 r) r, m11 u r, (m22 v + m23 r) u − m11 u v].
    Matrix3::new(
        0.0,
        -m22 * r,
        -m22 * v - 2.0 * m23 * r,
        m11 * r,
        0.0,
        m11 * u,
        m22 * v + m23 * r - m11 * v,
        (m22 - m11) * u,
        m23 * u,
    )
}

/// Rotation J(ψ) from the body to the earth-fixed frame (eq. 14).
pub fn rotation(psi: f64) -> Matrix3<f64> {
    let (s, c) = psi.sin_cos();
    Matrix3::new(
        c, -s, 0.0, //
        s, c, 0.0, //
        0.0, 0.0, 1.0,
    )
}
