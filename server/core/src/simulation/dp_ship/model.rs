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

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

use super::paper;

/// Number of identified parameters θ″ (eq. 46–47): five of A_h, and the
/// thrust coefficients K″ of up to four thruster groups.
pub const N_THETA: usize = 9;

/// Thruster groups that share a thrust coefficient (θ″6 … θ″9).
pub const N_GROUPS: usize = 4;

/// Names of θ″1 … θ″9 in the paper's notation (eq. 46–47), for the paper's
/// six-thruster layout; [`ThrustLayout::theta_names`] names them for any.
pub const THETA_NAMES: [&str; N_THETA] = [
    "A_h11", "A_h22", "A_h23", "A_h32", "A_h33", "K1=K2", "K3=K4", "K5", "K6",
];

/// The thrust configuration of eq. 4/7: T (3 × r, rows surge, sway, yaw;
/// one column per input channel) and the group of each column — columns of
/// one group share a thrust coefficient K″ (θ″6 for group 0, …, θ″9 for
/// group 3), as the paper's mains share K1 = K2 and its aft tunnels
/// K3 = K4. τ = Σ_j T_j·K″_{g(j)}·u_j.
#[derive(Debug, Clone, PartialEq)]
pub struct ThrustLayout {
    /// T, 3 × r.
    pub t: DMatrix<f64>,
    /// Group 0–3 of each column of T.
    pub groups: Vec<usize>,
}

impl ThrustLayout {
    /// The supply vessel's T″ (eq. 29) with the groups of eq. 47.
    pub fn paper() -> Self {
        ThrustLayout {
            t: DMatrix::from_fn(3, 6, |i, j| paper::T_CONFIG[i][j]),
            groups: vec![0, 0, 1, 1, 2, 3],
        }
    }

    /// Number of input channels r.
    pub fn columns(&self) -> usize {
        self.t.ncols()
    }

    /// Whether group g has a column (its θ″ is a parameter at all).
    pub fn uses(&self, g: usize) -> bool {
        self.groups.contains(&g)
    }

    /// K″ per column from θ″6 … θ″9.
    pub fn k_from_theta(&self, theta: &[f64; N_THETA]) -> DVector<f64> {
        DVector::from_iterator(self.groups.len(), self.groups.iter().map(|&g| theta[5 + g]))
    }

    /// Σ_{j ∈ g} T_j·u_j: the force of group g per unit K″ (∂τ/∂θ″_{6+g}).
    pub fn group_force(&self, g: usize, u: &[f64]) -> Vector3<f64> {
        let mut v = Vector3::zeros();
        for (j, _) in self.groups.iter().enumerate().filter(|(_, gj)| **gj == g) {
            for i in 0..3 {
                v[i] += self.t[(i, j)] * u[j];
            }
        }
        v
    }

    /// Names of θ″1 … θ″9: the paper's for its layout, otherwise
    /// `K(<names of the group's columns>)`; an unused group's slot is "—".
    pub fn theta_names(&self, columns: &[String]) -> [String; N_THETA] {
        if *self == Self::paper() {
            return THETA_NAMES.map(String::from);
        }
        std::array::from_fn(|p| {
            if p < 5 {
                return THETA_NAMES[p].to_string();
            }
            let names: Vec<&str> = (0..self.groups.len())
                .filter(|&j| self.groups[j] == p - 5)
                .map(|j| columns.get(j).map_or("?", String::as_str))
                .collect();
            if names.is_empty() {
                "—".to_string()
            } else {
                format!("K({})", names.join("="))
            }
        })
    }
}

/// A DP ship: known M and thrust layout T, and the parameters A_h and K
/// that the EKF identifies.
#[derive(Debug, Clone, PartialEq)]
pub struct DpShip {
    /// Inertia including added mass, M = Mᵀ > 0 (eq. 9, 30).
    pub m: Matrix3<f64>,
    /// Thruster configuration T and its coefficient groups (eq. 7, 29, 47).
    pub thrust: ThrustLayout,
    /// Momentum-equation matrix A_h = −D·M⁻¹ (eq. 39).
    pub a_h: Matrix3<f64>,
    /// Diagonal of the thrust coefficients K, one per column of T (eq. 6).
    pub k: DVector<f64>,
}

impl DpShip {
    /// The supply vessel of sec. 4 with the identified values (eq. 29, 30, 48, 49).
    pub fn supply_vessel() -> Self {
        DpShip {
            m: Matrix3::from_fn(|i, j| paper::M_INERTIA[i][j]),
            thrust: ThrustLayout::paper(),
            a_h: Matrix3::from_fn(|i, j| paper::A_H[i][j]),
            k: DVector::from_column_slice(&paper::K_THRUST),
        }
    }

    /// A ship with known M, thrust layout and parameters θ″ (eq. 46–47).
    pub fn from_theta(m: Matrix3<f64>, thrust: ThrustLayout, theta: &[f64; N_THETA]) -> Self {
        DpShip {
            m,
            a_h: a_h_from_theta(theta),
            k: thrust.k_from_theta(theta),
            thrust,
        }
    }

    /// θ″ of this ship (eq. 46–47): K″ of a group is that of its first
    /// column; an unused group's slot is 0.
    pub fn theta(&self) -> [f64; N_THETA] {
        let a = &self.a_h;
        let mut theta = [
            a[(0, 0)],
            a[(1, 1)],
            a[(1, 2)],
            a[(2, 1)],
            a[(2, 2)],
            0.0,
            0.0,
            0.0,
            0.0,
        ];
        for g in 0..N_GROUPS {
            if let Some(j) = self.thrust.groups.iter().position(|&gj| gj == g) {
                theta[5 + g] = self.k[j];
            }
        }
        theta
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

    /// State-space B = M⁻¹·T·K (eq. 50, 52), 3 × r.
    pub fn state_space_b(&self) -> DMatrix<f64> {
        let m_inv = DMatrix::from_column_slice(3, 3, self.m_inv().as_slice());
        m_inv * self.thrust_matrix()
    }

    /// T·K: the map from thruster commands u to τ (eq. 4), 3 × r.
    pub fn thrust_matrix(&self) -> DMatrix<f64> {
        let mut tk = self.thrust.t.clone();
        for j in 0..tk.ncols() {
            tk.column_mut(j).scale_mut(self.k[j]);
        }
        tk
    }

    /// τ = T·K·u.
    pub fn thrust(&self, u: &[f64]) -> Vector3<f64> {
        let mut tau = Vector3::zeros();
        for (j, &uj) in u.iter().enumerate().take(self.k.len()) {
            for i in 0..3 {
                tau[i] += self.thrust.t[(i, j)] * self.k[j] * uj;
            }
        }
        tau
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
        -coriolis_force(&self.m, &nu) + self.a_h * h + self.thrust(u) + b
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
