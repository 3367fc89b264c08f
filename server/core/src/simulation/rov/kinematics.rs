//! Kinematics η̇ = J(η)ν with zyx Euler angles Θ = [φ θ ψ]ᵀ
//! (Fossen 2011, eq. 2.18, 2.29, 2.41): J(η) = diag(R(Θ), T(Θ)).

use nalgebra::{Matrix3, Vector3, Vector6};

/// R(Θ) = R_z(ψ) R_y(θ) R_x(φ): body velocities to NED.
pub fn rotation(phi: f64, theta: f64, psi: f64) -> Matrix3<f64> {
    let (sf, cf) = phi.sin_cos();
    let (st, ct) = theta.sin_cos();
    let (ss, cs) = psi.sin_cos();
    Matrix3::new(
        cs * ct,
        -ss * cf + cs * st * sf,
        ss * sf + cs * cf * st,
        ss * ct,
        cs * cf + sf * st * ss,
        -cs * sf + st * ss * cf,
        -st,
        ct * sf,
        ct * cf,
    )
}

/// T(Θ): body angular rates [p q r] to Euler-angle rates [φ̇ θ̇ ψ̇]; singular
/// at θ = ±90°, where the entries are infinite.
pub fn euler_rates(phi: f64, theta: f64) -> Matrix3<f64> {
    let (sf, cf) = phi.sin_cos();
    let (st, ct) = theta.sin_cos();
    let tt = st / ct;
    Matrix3::new(1.0, sf * tt, cf * tt, 0.0, cf, -sf, 0.0, sf / ct, cf / ct)
}

/// η̇ = J(η)ν.
pub fn eta_dot(eta: &Vector6<f64>, nu: &Vector6<f64>) -> Vector6<f64> {
    let r = rotation(eta[3], eta[4], eta[5]);
    let t = euler_rates(eta[3], eta[4]);
    let lin: Vector3<f64> = r * nu.fixed_rows::<3>(0);
    let ang: Vector3<f64> = t * nu.fixed_rows::<3>(3);
    Vector6::new(lin.x, lin.y, lin.z, ang.x, ang.y, ang.z)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_is_the_zyx_product_and_orthonormal() {
        let (phi, theta, psi) = (0.3_f64, -0.5_f64, 2.0_f64);
        let rx = Matrix3::new(
            1.0,
            0.0,
            0.0,
            0.0,
            phi.cos(),
            -phi.sin(),
            0.0,
            phi.sin(),
            phi.cos(),
        );
        let ry = Matrix3::new(
            theta.cos(),
            0.0,
            theta.sin(),
            0.0,
            1.0,
            0.0,
            -theta.sin(),
            0.0,
            theta.cos(),
        );
        let rz = Matrix3::new(
            psi.cos(),
            -psi.sin(),
            0.0,
            psi.sin(),
            psi.cos(),
            0.0,
            0.0,
            0.0,
            1.0,
        );
        let r = rotation(phi, theta, psi);
        assert!((r - rz * ry * rx).amax() < 1e-15);
        assert!((r.transpose() * r - Matrix3::identity()).amax() < 1e-15);
        assert!((r.determinant() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn euler_rates_invert_the_angular_velocity_map() {
        // ω_b = T⁻¹ Θ̇ with T⁻¹ = [[1, 0, −sθ], [0, cφ, cθ sφ], [0, −sφ, cθ cφ]]
        // (Fossen 2011, eq. 2.28).
        let (phi, theta) = (0.4_f64, -0.7_f64);
        let t_inv = Matrix3::new(
            1.0,
            0.0,
            -theta.sin(),
            0.0,
            phi.cos(),
            theta.cos() * phi.sin(),
            0.0,
            -phi.sin(),
            theta.cos() * phi.cos(),
        );
        assert!((euler_rates(phi, theta) * t_inv - Matrix3::identity()).amax() < 1e-14);
    }
}
