//! Quadratic damping about straight-ahead motion: D_q|δ|δ, diagonal,
//! δ = ν except the surge velocity u, which the LPV schedule follows.
//!
//! Hull damping is linear plus quadratic in the velocity (Fossen 2011,
//! sec. 6.4: D(ν) = D + D_n(ν), D_n = −diag(X_|u|u|u|, Y_|v|v|v|, …)). A
//! sub-model linearized at the forward speed u₀ holds the surge part in its
//! D̄ and load, and blending sub-models in the measured u follows it; in
//! the other DOFs the quadratic force grows with the amplitude of the
//! motion itself, which no linear sub-model can follow: fitted to ±a, its
//! damping is right at ±a only. D_q ≥ 0 entrywise (dissipative).

use nalgebra::DVector;

/// d_i |δ_i| δ_i per modelled DOF, δ = `nu` with the entry `surge` zeroed
/// (`None`: no surge DOF, all of ν). Non-finite input propagates (a
/// diverging simulation shows as such).
pub fn quadratic_force(d_q: &DVector<f64>, nu: &[f64], surge: Option<usize>) -> Vec<f64> {
    nu.iter()
        .enumerate()
        .map(|(i, &v)| {
            if Some(i) == surge {
                0.0
            } else {
                d_q.get(i).copied().unwrap_or(0.0) * v.abs() * v
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_force_is_odd_in_each_velocity_and_leaves_surge_to_the_schedule() {
        let d = DVector::from_vec(vec![50.0, 80.0, 12.0]);
        let f = quadratic_force(&d, &[1.5, -0.5, 0.2], Some(0));
        assert_eq!(f[0], 0.0);
        assert!((f[1] + 80.0 * 0.25).abs() < 1e-12);
        assert!((f[2] - 12.0 * 0.04).abs() < 1e-12);
        let g = quadratic_force(&d, &[1.5, -0.5, 0.2], None);
        assert!((g[0] - 50.0 * 2.25).abs() < 1e-12);
    }
}
