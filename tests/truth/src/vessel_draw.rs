//! Vessels to fly: seeded random ROVs within published-size ranges, and a
//! fixed Surveyor-like work-class vehicle.
//!
//! Damping is set through time constants T_i: the damping of DOF i at its
//! reference speed a_i is d_i = M_ii / T_i (at u = 1 m/s in surge, at u = 0
//! in the other DOFs), split into a linear part α d_i and a quadratic part
//! (1 − α) d_i / a_i.
//!
//! The speed-scheduled part D_lu|u| plays the hull's lift and cross-flow
//! drag: it keeps the vessel directionally stable. Without it the Munk
//! moments of C_A(ν_r)ν_r, (M₂₂ − M₁₁)uv in yaw and (M₃₃ − M₁₁)uw in pitch,
//! make the sway–yaw and heave–pitch pairs statically unstable at speed
//! (Routh–Hurwitz on the linearized pair needs d_v d_r > M₁₁(M₂₂ − M₁₁)u²).
//! So D_lu,v D_lu,r ≥ κ M₁₁(M₂₂ − M₁₁) and
//! D_lu,w D_lu,q ≥ κ M₁₁(M₃₃ − M₁₁), κ = [`DIRECTIONAL_MARGIN`], split in
//! proportion to the inertias; surge and roll get D_lu = β D_l0 (per m/s).

use nalgebra::{Matrix6, Vector3, Vector6};

use crate::rng::{Rng, derive_seed};
use crate::vessel::{Actuator, GRAVITY, Vessel};

/// Reference DOF speeds a_i of the time constants: 1.0 m/s in surge,
/// 0.5 m/s in sway and heave, 0.3 rad/s in roll, pitch and yaw.
pub const DAMPING_REFERENCE_SPEED: [f64; 6] = [1.0, 0.5, 0.5, 0.3, 0.3, 0.3];

/// κ: static directional stability margin of the speed-scheduled damping.
pub const DIRECTIONAL_MARGIN: f64 = 1.2;

/// Seawater density (kg/m³).
const RHO: f64 = 1025.0;

/// (D_l0, D_lu, D_q) for time constants `t` (s), linear fractions `alpha`
/// and scheduled fractions `beta`, given M (see the module notes).
fn damping_from_time_constants(
    m: &Matrix6<f64>,
    t: &Vector6<f64>,
    alpha: &Vector6<f64>,
    beta: &Vector6<f64>,
) -> (Vector6<f64>, Vector6<f64>, Vector6<f64>) {
    let mut l0 = Vector6::zeros();
    let mut lu = Vector6::zeros();
    let mut q = Vector6::zeros();
    for i in 0..6 {
        let d = m[(i, i)] / t[i];
        let lin = alpha[i] * d;
        q[i] = (1.0 - alpha[i]) * d / DAMPING_REFERENCE_SPEED[i];
        if i == 0 {
            // surge: l0 + lu·(1 m/s) + q·(1 m/s) = d
            l0[i] = lin * (1.0 - beta[i]);
            lu[i] = lin * beta[i];
        } else {
            l0[i] = lin;
            lu[i] = beta[i] * lin;
        }
    }
    // λ with λ² M_jj M_kk = κ M₁₁ (M_jj − M₁₁): lu_j = λ M_jj, lu_k = λ M_kk
    for (j, k) in [(1, 5), (2, 4)] {
        let munk = (m[(j, j)] - m[(0, 0)]).max(0.0);
        let lambda = (DIRECTIONAL_MARGIN * m[(0, 0)] * munk / (m[(j, j)] * m[(k, k)])).sqrt();
        lu[j] = lu[j].max(lambda * m[(j, j)]);
        lu[k] = lu[k].max(lambda * m[(k, k)]);
    }
    (l0, lu, q)
}

impl Vessel {
    /// A random ROV from `seed`:
    /// - mass m ∈ [120, 600] kg, near-neutral volume m/ρ as a box of
    ///   L/B ∈ [1.3, 2.0], H/B ∈ [0.7, 1.0];
    /// - I_g of that box times a factor ∈ [0.8, 1.2] per axis;
    /// - added mass ∈ [30, 100] % of m (translation) or of I_o,ii (rotation);
    /// - time constants ∈ [1, 6] s, linear fraction α ∈ [0.3, 0.7],
    ///   speed-scheduled fraction β ∈ [0.1, 0.4], raised in sway, heave,
    ///   pitch and yaw for directional stability (module notes);
    /// - z_G ∈ [0.03, 0.15] m, z_B = 0, W − B ∈ [−40, 80] N;
    /// - no current, no tether, no disturbance, ideal actuators.
    pub fn draw(seed: u64) -> Vessel {
        let mut rng = Rng::new(derive_seed(seed, 0x5E55E1));
        let mass = rng.range(120.0, 600.0);
        let lb = rng.range(1.3, 2.0);
        let hb = rng.range(0.7, 1.0);
        let b = (mass / RHO / (lb * hb)).cbrt();
        let (l, h) = (lb * b, hb * b);
        let k: Vec<f64> = (0..3).map(|_| rng.range(0.8, 1.2)).collect();
        let inertia_cg = Vector3::new(
            k[0] * mass * (b * b + h * h) / 12.0,
            k[1] * mass * (l * l + h * h) / 12.0,
            k[2] * mass * (l * l + b * b) / 12.0,
        );
        let z_g = rng.range(0.03, 0.15);
        let mut added = Vector6::zeros();
        for i in 0..6 {
            let base = if i < 3 {
                mass
            } else if i < 5 {
                inertia_cg[i - 3] + mass * z_g * z_g
            } else {
                inertia_cg[2]
            };
            added[i] = rng.range(0.3, 1.0) * base;
        }
        let t = Vector6::from_fn(|_, _| rng.range(1.0, 6.0));
        let alpha = Vector6::from_fn(|_, _| rng.range(0.3, 0.7));
        let beta = Vector6::from_fn(|_, _| rng.range(0.1, 0.4));
        let w_minus_b = rng.range(-40.0, 80.0);
        let mut v = Vessel {
            name: format!("drawn ROV (seed {seed})"),
            mass,
            inertia_cg,
            z_g,
            z_b: 0.0,
            added_mass: added,
            damping_linear: Vector6::zeros(),
            damping_linear_per_speed: Vector6::zeros(),
            damping_quadratic: Vector6::zeros(),
            w_minus_b,
            gravity: GRAVITY,
            current_ned: Vector3::zeros(),
            current_drift: None,
            disturbance: None,
            tether: Vector6::zeros(),
            tether_ned: Vector3::zeros(),
            actuator: Actuator::default(),
            size: Vector3::new(l, b, h),
        };
        let m = v.m();
        (
            v.damping_linear,
            v.damping_linear_per_speed,
            v.damping_quadratic,
        ) = damping_from_time_constants(&m, &t, &alpha, &beta);
        v
    }

    /// A fixed vehicle of the Surveyor ROV's proportions (thesis §1: about
    /// 5 m × 2 m × 1.4 m, 5 t): z_G = 0.10 m, z_B = 0, W − B = +150 N, time
    /// constants 4, 3, 3, 1.5, 1.5, 2 s (surge … yaw), α = 0.5, β = 0.25.
    pub fn surveyor_like() -> Vessel {
        let mass = 5000.0;
        let (l, b, h) = (5.0, 2.0, 1.4);
        let inertia_cg = Vector3::new(
            mass * (b * b + h * h) / 12.0,
            mass * (l * l + h * h) / 12.0,
            mass * (l * l + b * b) / 12.0,
        );
        let z_g = 0.10;
        let ratio = [0.3, 0.8, 1.0, 0.5, 0.8, 0.6];
        let base = [
            mass,
            mass,
            mass,
            inertia_cg.x + mass * z_g * z_g,
            inertia_cg.y + mass * z_g * z_g,
            inertia_cg.z,
        ];
        let mut v = Vessel {
            name: "Surveyor-like ROV".into(),
            mass,
            inertia_cg,
            z_g,
            z_b: 0.0,
            added_mass: Vector6::from_fn(|i, _| ratio[i] * base[i]),
            damping_linear: Vector6::zeros(),
            damping_linear_per_speed: Vector6::zeros(),
            damping_quadratic: Vector6::zeros(),
            w_minus_b: 150.0,
            gravity: GRAVITY,
            current_ned: Vector3::zeros(),
            current_drift: None,
            disturbance: None,
            tether: Vector6::zeros(),
            tether_ned: Vector3::zeros(),
            actuator: Actuator::default(),
            size: Vector3::new(l, b, h),
        };
        let t = Vector6::new(4.0, 3.0, 3.0, 1.5, 1.5, 2.0);
        let m = v.m();
        (
            v.damping_linear,
            v.damping_linear_per_speed,
            v.damping_quadratic,
        ) = damping_from_time_constants(&m, &t, &Vector6::repeat(0.5), &Vector6::repeat(0.25));
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn drawn_vessels_stay_in_their_ranges() {
        for seed in 0..50 {
            let v = Vessel::draw(seed);
            assert!((120.0..600.0).contains(&v.mass));
            assert!((0.03..0.15).contains(&v.z_g));
            assert!((-40.0..80.0).contains(&v.w_minus_b));
            let m = v.m();
            assert!(m.cholesky().is_some(), "M must be positive definite");
            assert!((m - m.transpose()).norm() < 1e-9);
            for i in 0..6 {
                // damping at the reference speed gives T in [1, 6] s
                let a = DAMPING_REFERENCE_SPEED[i];
                let u = if i == 0 { 1.0 } else { 0.0 };
                let d = v.damping_linear[i]
                    + v.damping_linear_per_speed[i] * u
                    + v.damping_quadratic[i] * a;
                let t = m[(i, i)] / d;
                assert!((1.0 - 1e-9..6.0 + 1e-9).contains(&t), "dof {i}: T = {t}");
            }
        }
        assert_ne!(Vessel::draw(1), Vessel::draw(2));
    }

    #[test]
    fn drawn_vessels_are_directionally_stable_at_every_speed() {
        // ν̇ = −M⁻¹ D̄(u₀) ν, D̄ the tangent including C(ν)'s Munk terms:
        // every eigenvalue of M⁻¹ D̄ has a positive real part.
        for seed in 0..51 {
            let v = if seed == 50 {
                Vessel::surveyor_like()
            } else {
                Vessel::draw(seed)
            };
            let m_inv = v.m().try_inverse().unwrap();
            for u0 in [0.2, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0] {
                let a = m_inv * v.linearization(u0).d_bar;
                for e in a.complex_eigenvalues().iter() {
                    assert!(e.re > 0.0, "seed {seed} at {u0} m/s: eigenvalue {e}");
                }
            }
        }
        assert_eq!(Vessel::draw(1), Vessel::draw(1));
    }
}
