//! A current constant in NED seen from the body: ν_c(ψ) = R(ψ)ᵀ[V_N V_E]ᵀ
//! (Fossen 2011, sec. 10.3), the velocity the hull's forces subtract,
//! ν_r = ν − ν_c.

/// (u_c, v_c) = (V_N cos ψ + V_E sin ψ, −V_N sin ψ + V_E cos ψ) (m/s) of the
/// current `v` = [V_N, V_E] at heading `psi` (rad).
pub fn body_current(v: [f64; 2], psi: f64) -> (f64, f64) {
    let (s, c) = psi.sin_cos();
    (v[0] * c + v[1] * s, -v[0] * s + v[1] * c)
}

/// (u_c, v_c, w_c) = R(φ, θ, ψ)ᵀ[V_N V_E 0]ᵀ (m/s), R the ZYX rotation
/// of Fossen (2011, eq. 2.18): a horizontal current seen from a hull that
/// rolls and pitches as well, u_c = cos θ·a, v_c = cos φ·b + sin φ sin θ·a,
/// w_c = −sin φ·b + cos φ sin θ·a with (a, b) = [`body_current`].
pub fn body_current_tilted(v: [f64; 2], phi: f64, theta: f64, psi: f64) -> (f64, f64, f64) {
    let (a, b) = body_current(v, psi);
    let (sp, cp) = phi.sin_cos();
    let (st, ct) = theta.sin_cos();
    (ct * a, cp * b + sp * st * a, -sp * b + cp * st * a)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against the rotation matrix written out: Rᵀ v, R = R_z(ψ)R_y(θ)R_x(φ).
    #[test]
    fn the_tilted_current_is_the_transposed_rotation_of_the_ned_current() {
        for &(phi, theta, psi) in &[(0.0, 0.0, 0.7), (0.2, -0.3, 2.0), (-1.0, 0.9, -2.5)] {
            let v = [0.25, -0.15];
            let r = nalgebra::Rotation3::from_euler_angles(phi, theta, psi);
            let want = r.transpose() * nalgebra::Vector3::new(v[0], v[1], 0.0);
            let (u, vv, w) = body_current_tilted(v, phi, theta, psi);
            assert!((u - want.x).abs() < 1e-15 && (vv - want.y).abs() < 1e-15);
            assert!((w - want.z).abs() < 1e-15, "{w} vs {}", want.z);
        }
        let (u, v, w) = body_current_tilted([0.3, 0.1], 0.0, 0.0, 1.1);
        assert_eq!(
            (u, v, w),
            (
                body_current([0.3, 0.1], 1.1).0,
                body_current([0.3, 0.1], 1.1).1,
                0.0
            )
        );
    }

    #[test]
    fn a_current_ahead_turns_onto_the_beam_as_the_hull_turns() {
        let (u, v) = body_current([0.3, 0.0], 0.0);
        assert!((u - 0.3).abs() < 1e-15 && v.abs() < 1e-15);
        // Heading east (90°): a northward current comes from port, −v.
        let (u, v) = body_current([0.3, 0.0], std::f64::consts::FRAC_PI_2);
        assert!(u.abs() < 1e-15 && (v + 0.3).abs() < 1e-15);
        // Speed is kept at any heading.
        let (u, v) = body_current([0.2, -0.1], 2.3);
        assert!((u.hypot(v) - 0.2f64.hypot(0.1)).abs() < 1e-15);
    }
}
