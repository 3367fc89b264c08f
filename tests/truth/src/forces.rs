//! Forces of the plant M ν̇_r + C_RB(ν)ν + C_A(ν_r)ν_r + D(ν_r)ν_r + g(η) = τ:
//! the Coriolis–centripetal term from an inertia matrix, the damping and the
//! restoring forces.

use nalgebra::{Matrix6, Vector3, Vector6};

use crate::kinematics::{Trig, skew};
use crate::vessel::Vessel;

fn split(v: &Vector6<f64>) -> (Vector3<f64>, Vector3<f64>) {
    (
        Vector3::new(v[0], v[1], v[2]),
        Vector3::new(v[3], v[4], v[5]),
    )
}

fn join(a: &Vector3<f64>, b: &Vector3<f64>) -> Vector6<f64> {
    Vector6::new(a.x, a.y, a.z, b.x, b.y, b.z)
}

/// C(ν) from a symmetric inertia matrix M (Fossen 2011, Thm 3.2;
/// the same form gives C_A(ν_r) from M_A, ch. 6):
/// C(ν) = [[0, −S(M₁₁ν₁ + M₁₂ν₂)], [−S(M₁₁ν₁ + M₁₂ν₂), −S(M₂₁ν₁ + M₂₂ν₂)]].
/// Skew-symmetric for every ν, so νᵀC(ν)ν = 0.
pub fn coriolis_matrix(m: &Matrix6<f64>, nu: &Vector6<f64>) -> Matrix6<f64> {
    let (a1, a2) = split(&(m * nu));
    let mut c = Matrix6::zeros();
    c.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-skew(&a1)));
    c.fixed_view_mut::<3, 3>(3, 0).copy_from(&(-skew(&a1)));
    c.fixed_view_mut::<3, 3>(3, 3).copy_from(&(-skew(&a2)));
    c
}

/// C(ν)ν without forming C: with (a₁, a₂) = Mν,
/// C(ν)ν = (ν₂ × a₁, ν₁ × a₁ + ν₂ × a₂).
pub fn coriolis_force(m: &Matrix6<f64>, nu: &Vector6<f64>) -> Vector6<f64> {
    let (a1, a2) = split(&(m * nu));
    let (n1, n2) = split(nu);
    join(&n2.cross(&a1), &(n1.cross(&a1) + n2.cross(&a2)))
}

/// ∂(C(ν)ν)/∂ν = C(ν) + [[S(ν₂), 0], [S(ν₁), S(ν₂)]]·M (product rule on the
/// cross products of [`coriolis_force`]).
pub fn coriolis_jacobian(m: &Matrix6<f64>, nu: &Vector6<f64>) -> Matrix6<f64> {
    let (n1, n2) = split(nu);
    let mut q = Matrix6::zeros();
    q.fixed_view_mut::<3, 3>(0, 0).copy_from(&skew(&n2));
    q.fixed_view_mut::<3, 3>(3, 0).copy_from(&skew(&n1));
    q.fixed_view_mut::<3, 3>(3, 3).copy_from(&skew(&n2));
    coriolis_matrix(m, nu) + q * m
}

impl Vessel {
    /// D(ν_r)ν_r with D(ν_r) = D_l0 + D_lu|u_r| + D_q diag(|ν_r|) (diagonal):
    /// component i is (l0ᵢ + luᵢ|u_r|) ν_r,i + qᵢ |ν_r,i| ν_r,i.
    pub fn damping_force(&self, nu_r: &Vector6<f64>) -> Vector6<f64> {
        let au = nu_r[0].abs();
        Vector6::from_fn(|i, _| {
            let x = nu_r[i];
            (self.damping_linear[i] + self.damping_linear_per_speed[i] * au) * x
                + self.damping_quadratic[i] * x.abs() * x
        })
    }

    /// ∂(D(ν_r)ν_r)/∂ν_r: diagonal l0ᵢ + luᵢ|u| + 2qᵢ|νᵢ| (surge: l0 + 2(lu + q)|u|)
    /// plus the column ∂/∂u of the speed scheduling, luᵢ sgn(u) νᵢ.
    pub fn damping_jacobian(&self, nu_r: &Vector6<f64>) -> Matrix6<f64> {
        let u = nu_r[0];
        let mut j = Matrix6::zeros();
        for i in 0..6 {
            let x = nu_r[i];
            j[(i, i)] = self.damping_linear[i]
                + self.damping_linear_per_speed[i] * u.abs()
                + 2.0 * self.damping_quadratic[i] * x.abs();
            j[(i, 0)] += self.damping_linear_per_speed[i] * u.signum() * x;
        }
        j
    }

    /// g(η) for x_G = x_B, y_G = y_B = 0 (Fossen 2011, eq. 4.6; thesis eq. 1.5):
    /// ((W−B)sθ, −(W−B)cθsφ, −(W−B)cθcφ, (z_G W − z_B B)cθsφ, (z_G W − z_B B)sθ, 0).
    /// It sits on the left of the equation: a heavy vessel (W − B > 0) sinks
    /// (g_Z < 0), and z_G W − z_B B > 0 rights it.
    pub fn restoring(&self, eta: &Vector6<f64>) -> Vector6<f64> {
        restoring_lumped(self.w_minus_b, self.zg_w_minus_zb_b(), eta[3], eta[4])
    }

    /// The hydrodynamic force of the linearizations: C(ν)ν + D(ν)ν with
    /// M = M_RB + M_A and no current (ν = ν_r).
    pub fn hydrodynamic_force(&self, nu: &Vector6<f64>) -> Vector6<f64> {
        coriolis_force(&self.m(), nu) + self.damping_force(nu)
    }
}

/// g(η) from the lumped W − B and z_G W − z_B B at roll φ and pitch θ.
pub fn restoring_lumped(
    w_minus_b: f64,
    zg_w_minus_zb_b: f64,
    phi: f64,
    theta: f64,
) -> Vector6<f64> {
    restoring_trig(w_minus_b, zg_w_minus_zb_b, &Trig::new(phi, theta, 0.0))
}

/// g(η) from precomputed sines and cosines.
pub fn restoring_trig(w_minus_b: f64, zg_w_minus_zb_b: f64, t: &Trig) -> Vector6<f64> {
    let (sf, cf, st, ct) = (t.sf, t.cf, t.st, t.ct);
    Vector6::new(
        w_minus_b * st,
        -w_minus_b * ct * sf,
        -w_minus_b * ct * cf,
        zg_w_minus_zb_b * ct * sf,
        zg_w_minus_zb_b * st,
        0.0,
    )
}
