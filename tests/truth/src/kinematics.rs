//! Kinematics in Fossen's notation (Fossen 2011, ch. 2): the skew-symmetric
//! S(λ), the zyx Euler rotation R(Θ), the attitude transform T(Θ) and
//! η̇ = J(η)ν (eq. 2.40). η = (x, y, z, φ, θ, ψ) in NED, ν = (u, v, w, p, q, r)
//! in the body frame.

use nalgebra::{Matrix3, Vector3, Vector6};

/// S(λ) with S(λ)a = λ × a (Fossen 2011, eq. 2.10).
pub fn skew(l: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -l.z, l.y, l.z, 0.0, -l.x, -l.y, l.x, 0.0)
}

/// Sines and cosines of (φ, θ, ψ), computed once per evaluation and shared
/// by R(Θ), T_Θ(Θ) and g(η).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Trig {
    /// sin φ, cos φ.
    pub sf: f64,
    /// cos φ.
    pub cf: f64,
    /// sin θ.
    pub st: f64,
    /// cos θ.
    pub ct: f64,
    /// sin ψ.
    pub sp: f64,
    /// cos ψ.
    pub cp: f64,
}

impl Trig {
    /// The six values for angles (φ, θ, ψ).
    pub fn new(phi: f64, theta: f64, psi: f64) -> Self {
        let (sf, cf) = phi.sin_cos();
        let (st, ct) = theta.sin_cos();
        let (sp, cp) = psi.sin_cos();
        Trig {
            sf,
            cf,
            st,
            ct,
            sp,
            cp,
        }
    }

    /// R_b^n(Θ) for zyx Euler angles (Fossen 2011, eq. 2.18): body → NED.
    pub fn rotation(&self) -> Matrix3<f64> {
        let Trig {
            sf,
            cf,
            st,
            ct,
            sp,
            cp,
        } = *self;
        Matrix3::new(
            cp * ct,
            -sp * cf + cp * st * sf,
            sp * sf + cp * cf * st,
            sp * ct,
            cp * cf + sf * st * sp,
            -cp * sf + st * sp * cf,
            -st,
            ct * sf,
            ct * cf,
        )
    }

    /// T_Θ(Θ), Θ̇ = T_Θ ω (Fossen 2011, eq. 2.29); singular at θ = ±90°.
    pub fn attitude_transform(&self) -> Matrix3<f64> {
        let Trig { sf, cf, st, ct, .. } = *self;
        let tt = st / ct;
        Matrix3::new(1.0, sf * tt, cf * tt, 0.0, cf, -sf, 0.0, sf / ct, cf / ct)
    }
}

/// R_b^n(Θ) for zyx Euler angles (Fossen 2011, eq. 2.18): body → NED.
pub fn rotation_zyx(phi: f64, theta: f64, psi: f64) -> Matrix3<f64> {
    Trig::new(phi, theta, psi).rotation()
}

/// T_Θ(Θ), Θ̇ = T_Θ ω (Fossen 2011, eq. 2.29); singular at θ = ±90°.
pub fn attitude_transform(phi: f64, theta: f64) -> Matrix3<f64> {
    Trig::new(phi, theta, 0.0).attitude_transform()
}

/// η̇ = J(η)ν = (R(Θ)ν₁, T_Θ(Θ)ν₂) (Fossen 2011, eq. 2.40).
pub fn eta_dot(eta: &Vector6<f64>, nu: &Vector6<f64>) -> Vector6<f64> {
    let trig = Trig::new(eta[3], eta[4], eta[5]);
    let p = trig.rotation() * nu.fixed_rows::<3>(0);
    let a = trig.attitude_transform() * nu.fixed_rows::<3>(3);
    Vector6::new(p.x, p.y, p.z, a.x, a.y, a.z)
}

/// An angle wrapped into (−π, π], as a compass or INS reports heading.
pub fn wrap_pi(a: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    let w = a - TAU * ((a + PI) / TAU).floor();
    if w <= -PI { w + TAU } else { w }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_is_orthonormal_and_skew_is_cross_product() {
        let r = rotation_zyx(0.3, -0.4, 2.0);
        assert!((r.transpose() * r - Matrix3::identity()).norm() < 1e-14);
        assert!((r.determinant() - 1.0).abs() < 1e-14);
        let a = Vector3::new(1.0, -2.0, 0.5);
        let b = Vector3::new(0.3, 0.7, -1.1);
        assert!((skew(&a) * b - a.cross(&b)).norm() < 1e-15);
    }

    #[test]
    fn wrap_keeps_angles_in_half_open_interval() {
        for a in [
            -7.0,
            -std::f64::consts::PI,
            0.0,
            3.0,
            std::f64::consts::PI,
            10.0,
        ] {
            let w = wrap_pi(a);
            assert!(w > -std::f64::consts::PI && w <= std::f64::consts::PI);
            let k = (a - w) / std::f64::consts::TAU;
            assert!((k - k.round()).abs() < 1e-12);
        }
    }
}
