//! Restoring forces and moments g(η) of a submerged vehicle from weight W,
//! buoyancy B and the centres of gravity r_G and buoyancy r_B in the body
//! frame (Fossen 2011, eq. 4.6; thesis eq. 1.4).

use nalgebra::Vector6;

/// W, B (N) and r_G, r_B (m, body frame). All zero (the default) means no
/// restoring: g(η) = 0.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Restoring {
    /// Weight W = m g (N).
    pub weight: f64,
    /// Buoyancy B = ρ g ∇ (N).
    pub buoyancy: f64,
    /// Centre of gravity r_G = [x_G y_G z_G] (m).
    pub r_g: [f64; 3],
    /// Centre of buoyancy r_B = [x_B y_B z_B] (m).
    pub r_b: [f64; 3],
}

impl Restoring {
    /// g(η) at roll φ and pitch θ (rad), Fossen 2011 eq. 4.6.
    pub fn g(&self, phi: f64, theta: f64) -> Vector6<f64> {
        let (w, b) = (self.weight, self.buoyancy);
        let [xg, yg, zg] = self.r_g;
        let [xb, yb, zb] = self.r_b;
        let (sf, cf) = phi.sin_cos();
        let (st, ct) = theta.sin_cos();
        let (dx, dy, dz) = (xg * w - xb * b, yg * w - yb * b, zg * w - zb * b);
        Vector6::new(
            (w - b) * st,
            -(w - b) * ct * sf,
            -(w - b) * ct * cf,
            -dy * ct * cf + dz * ct * sf,
            dz * st + dx * ct * cf,
            -dx * ct * sf - dy * st,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simulation::rov::kinematics::rotation;
    use nalgebra::Vector3;

    #[test]
    fn closed_form_equals_gravity_and_buoyancy_as_vectors() {
        // g(η) = −[f_G + f_B; r_G × f_G + r_B × f_B] with f_G = Rᵀ[0 0 W],
        // f_B = −Rᵀ[0 0 B] (Fossen 2011, eq. 4.5): an independent derivation.
        let r = Restoring {
            weight: 49_050.0,
            buoyancy: 49_300.0,
            r_g: [0.05, -0.02, 0.1],
            r_b: [-0.03, 0.01, -0.15],
        };
        for &(phi, theta, psi) in &[(0.0, 0.0, 0.0), (0.3, -0.2, 1.0), (-0.8, 1.1, -2.5)] {
            let rt = rotation(phi, theta, psi).transpose();
            let fg = rt * Vector3::new(0.0, 0.0, r.weight);
            let fb = -(rt * Vector3::new(0.0, 0.0, r.buoyancy));
            let rg = Vector3::from(r.r_g);
            let rb = Vector3::from(r.r_b);
            let force = -(fg + fb);
            let moment = -(rg.cross(&fg) + rb.cross(&fb));
            let g = r.g(phi, theta);
            for i in 0..3 {
                assert!(
                    (g[i] - force[i]).abs() < 1e-9,
                    "force {i}: {} vs {}",
                    g[i],
                    force[i]
                );
                assert!((g[i + 3] - moment[i]).abs() < 1e-9, "moment {i}");
            }
        }
        // Upright and neutral: no restoring at all.
        let neutral = Restoring {
            weight: 1000.0,
            buoyancy: 1000.0,
            r_g: [0.0; 3],
            r_b: [0.0, 0.0, -0.1],
        };
        assert_eq!(neutral.g(0.0, 0.0), Vector6::zeros());
        // Roll φ > 0 with B above G gives a positive (restoring) g₄ = B·BG·sin φ.
        assert!((neutral.g(0.2, 0.0)[3] - 100.0 * 0.2_f64.sin()).abs() < 1e-12);
    }
}
