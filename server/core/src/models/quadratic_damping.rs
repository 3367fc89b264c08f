//! Quadratic damping about straight-ahead motion: D_q|δ|δ, diagonal,
//! δ = ν except the surge velocity u, which the LPV schedule follows.
//!
//! Hull damping is linear plus quadratic in the velocity (Fossen 2011,
//! sec. 6.4: D(ν) = D + D_n(ν), D_n = −diag(X_|u|u|u|, Y_|v|v|v|, …)). A
//! sub-model linearized at the forward speed u₀ holds the tangent of the
//! surge part in its D̄ and load; the LPV model adds the remainder
//! ([`surge_remainder`]) per sub-model, which makes the blend exact for
//! X_|u|u|u|u between and beyond the grid points. In the other DOFs the
//! quadratic force grows with the amplitude of the motion itself, which no
//! linear sub-model can follow: fitted to ±a, its damping is right at ±a
//! only. D_q ≥ 0 entrywise (dissipative).

use nalgebra::DVector;

/// The quadratic damping one sub-model carries: D_q (one entry per
/// modelled DOF; surge's is X_|u|u) and the forward speed u₀ (m/s) the
/// sub-model is linearized at, about which surge's remainder is taken.
#[derive(Debug, Clone, PartialEq)]
pub struct QuadraticDamping {
    /// D_q per modelled DOF (N·s²/m², N·m·s²/rad²), ≥ 0.
    pub d_q: DVector<f64>,
    /// The sub-model's forward speed u₀ (m/s).
    pub u0: f64,
}

impl QuadraticDamping {
    /// The force at `nu`: d_i|ν_i|ν_i, and at index `surge` (if surge is
    /// modelled) X_|u|u times [`surge_remainder`] about u₀.
    pub fn force(&self, nu: &[f64], surge: Option<usize>) -> Vec<f64> {
        let mut f = quadratic_force(&self.d_q, nu, surge);
        if let Some(i) = surge.filter(|&i| i < f.len()) {
            f[i] = self.d_q.get(i).copied().unwrap_or(0.0) * surge_remainder(nu[i], self.u0);
        }
        f
    }
}

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

/// The part of |u|u beyond its tangent at the forward speed `u0`:
/// |u|u − |u₀|u₀ − 2|u₀|(u − u₀), (u − u₀)² while u and u₀ are ≥ 0.
/// A sub-model at u₀ carries the tangent in D̄ (2X_|u|u·|u₀|) and its
/// load; X_|u|u times this is the rest of the surge drag. Weights that
/// reproduce quadratics in u₀ (the extension's) sum it to zero at the
/// scheduled speed; the linear blend between two grid points to
/// w(1 − w)Δ², which is exactly what that blend of the tangents' loads
/// misses.
pub fn surge_remainder(u: f64, u0: f64) -> f64 {
    u.abs() * u - surge_tangent(u, u0)
}

/// The tangent of |u|u at `u0`, evaluated at `u`: |u₀|u₀ + 2|u₀|(u − u₀).
pub fn surge_tangent(u: f64, u0: f64) -> f64 {
    u0.abs() * u0 + 2.0 * u0.abs() * (u - u0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_tangents_blended_with_the_remainder_give_the_drag_exactly() {
        // X|u|u at u = 0.8 from tangents at 0.5 and 1.0 (weights 0.4, 0.6).
        let (x, u) = (40.0, 0.8);
        let tangent = |u0: f64| (2.0 * x * u0, -x * u0 * u0); // (D̄, load)
        let force = |u0: f64, w: f64| {
            let (d, b) = tangent(u0);
            w * (d * u + b + x * surge_remainder(u, u0))
        };
        assert!((force(0.5, 0.4) + force(1.0, 0.6) - x * u * u).abs() < 1e-12);
        // Without it the blend misses X·w(1 − w)Δ².
        let plain: f64 = [(0.5, 0.4), (1.0, 0.6)]
            .iter()
            .map(|&(u0, w)| w * (tangent(u0).0 * u + tangent(u0).1))
            .sum();
        assert!((x * u * u - plain - x * 0.4 * 0.6 * 0.25).abs() < 1e-12);
        // Astern: the remainder of |u|u about 0.5 at u = −0.2.
        assert!((surge_remainder(-0.2, 0.5) - (-0.04 - 0.25 + 0.7)).abs() < 1e-12);
    }

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
