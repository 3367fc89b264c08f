//! A current constant in NED seen from the body: ν_c(ψ) = R(ψ)ᵀ[V_N V_E]ᵀ
//! (Fossen 2011, sec. 10.3), the velocity the hull's forces subtract,
//! ν_r = ν − ν_c.

/// (u_c, v_c) = (V_N cos ψ + V_E sin ψ, −V_N sin ψ + V_E cos ψ) (m/s) of the
/// current `v` = [V_N, V_E] at heading `psi` (rad).
pub fn body_current(v: [f64; 2], psi: f64) -> (f64, f64) {
    let (s, c) = psi.sin_cos();
    (v[0] * c + v[1] * s, -v[0] * s + v[1] * c)
}

#[cfg(test)]
mod tests {
    use super::*;

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
