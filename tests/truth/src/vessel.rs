//! The vessel's true parameters and its inertia matrices (Fossen 2011,
//! ch. 3 and 6): M = M_RB + M_A with the CG at r_G = (0, 0, z_G) below the
//! body origin CO (z down), diagonal positive added mass M_A, speed-scheduled
//! linear plus quadratic diagonal damping, lumped restoring terms.

use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

use crate::kinematics::skew;

/// Standard gravity (m/s²).
pub const GRAVITY: f64 = 9.81;

/// Optional actuator effects between the command τ_cmd and the force τ that
/// acts on the hull. Default: ideal (τ = τ_cmd).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Actuator {
    /// First-order lag time constants T_a per DOF (s): τ̇ = (τ_cmd − τ)/T_a.
    pub lag_s: Option<Vector6<f64>>,
    /// Thrust limits per DOF (N, N·m): τ_cmd is clipped to ±limit.
    pub limits: Option<Vector6<f64>>,
}

/// True parameters of a 6-DOF ROV.
///
/// Damping (Fossen 2011, ch. 6: diagonal linear + quadratic):
/// D(ν_r)ν_r with D(ν_r) = D_l0 + D_lu·|u_r| + D_q·diag(|ν_r|), all diagonal.
#[derive(Debug, Clone, PartialEq)]
pub struct Vessel {
    /// A label for reports.
    pub name: String,
    /// Rigid-body mass m (kg).
    pub mass: f64,
    /// Principal moments of inertia about the CG, I_g = diag(I_x, I_y, I_z) (kg·m²).
    pub inertia_cg: Vector3<f64>,
    /// z_G > 0: the CG lies below the CO (m). x_G = y_G = 0.
    pub z_g: f64,
    /// z_B of the centre of buoyancy (m); x_B = y_B = 0.
    pub z_b: f64,
    /// Added mass, the positive diagonal of M_A = −diag(X_u̇, …, N_ṙ).
    pub added_mass: Vector6<f64>,
    /// Linear damping at zero forward speed, diag(D_l0) (> 0).
    pub damping_linear: Vector6<f64>,
    /// Growth of linear damping with |u_r|, diag(D_lu) (≥ 0).
    pub damping_linear_per_speed: Vector6<f64>,
    /// Quadratic damping, diag(D_q) (≥ 0).
    pub damping_quadratic: Vector6<f64>,
    /// W − B (N): positive is heavy (sinks).
    pub w_minus_b: f64,
    /// Gravity g (m/s²), W = m g.
    pub gravity: f64,
    /// Constant ocean current in NED, V_c (m/s); zero by default.
    pub current_ned: Vector3<f64>,
    /// Constant tether force/moment in the body frame, added to τ (N, N·m).
    pub tether: Vector6<f64>,
    /// A tether pull fixed in NED (N), acting at the body origin: the cable
    /// leads to the ship, so in the body frame it turns with the heading,
    /// τ_t = [R(Θ)ᵀ f_n; 0] (Fossen 2011, eq. 2.18 rotation).
    pub tether_ned: Vector3<f64>,
    /// Actuator lag and limits; ideal by default.
    pub actuator: Actuator,
    /// Overall length, beam and height (m), for scaling amplitudes and limits.
    pub size: Vector3<f64>,
}

impl Vessel {
    /// Weight W = m g (N).
    pub fn weight(&self) -> f64 {
        self.mass * self.gravity
    }

    /// Buoyancy B = W − (W − B) (N).
    pub fn buoyancy(&self) -> f64 {
        self.weight() - self.w_minus_b
    }

    /// z_G W − z_B B (N·m), the metacentric restoring moment coefficient.
    pub fn zg_w_minus_zb_b(&self) -> f64 {
        self.z_g * self.weight() - self.z_b * self.buoyancy()
    }

    /// r_G = (0, 0, z_G).
    pub fn r_g(&self) -> Vector3<f64> {
        Vector3::new(0.0, 0.0, self.z_g)
    }

    /// M_RB about the CO (Fossen 2011, eq. 3.44):
    /// [[m I, −m S(r_G)], [m S(r_G), I_g − m S²(r_G)]].
    pub fn m_rb(&self) -> Matrix6<f64> {
        let s = skew(&self.r_g());
        let m = self.mass;
        let i_o = Matrix3::from_diagonal(&self.inertia_cg) - m * s * s;
        let mut out = Matrix6::zeros();
        out.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&(m * Matrix3::identity()));
        out.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-m * s));
        out.fixed_view_mut::<3, 3>(3, 0).copy_from(&(m * s));
        out.fixed_view_mut::<3, 3>(3, 3).copy_from(&i_o);
        out
    }

    /// M_A = diag(added mass): only the diagonal of Fossen's M_A (2011, ch. 6).
    pub fn m_a(&self) -> Matrix6<f64> {
        Matrix6::from_diagonal(&self.added_mass)
    }

    /// M = M_RB + M_A, symmetric positive definite.
    pub fn m(&self) -> Matrix6<f64> {
        self.m_rb() + self.m_a()
    }

    /// The same vessel with g(η) ≡ 0 (W = B and z_B = z_G), for tests.
    pub fn without_restoring(&self) -> Vessel {
        Vessel {
            w_minus_b: 0.0,
            z_b: self.z_g,
            ..self.clone()
        }
    }

    /// The same vessel without any damping, for energy tests.
    pub fn without_damping(&self) -> Vessel {
        Vessel {
            damping_linear: Vector6::zeros(),
            damping_linear_per_speed: Vector6::zeros(),
            damping_quadratic: Vector6::zeros(),
            ..self.clone()
        }
    }
}
