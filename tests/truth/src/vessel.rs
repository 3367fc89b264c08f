//! The vessel's true parameters and its inertia matrices (Fossen 2011,
//! ch. 3 and 6): M = M_RB + M_A with the CG at r_G = (0, 0, z_G) below the
//! body origin CO (z down), diagonal positive added mass M_A, speed-scheduled
//! linear plus quadratic diagonal damping, lumped restoring terms.

use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

use crate::kinematics::skew;

/// Standard gravity (m/s²).
pub const GRAVITY: f64 = 9.81;

/// Optional actuator effects between the command τ_cmd and the force τ that
/// acts on the hull, in the order command → transport delay → dead zone →
/// limits → lag → hull. Default: ideal (τ = τ_cmd).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Actuator {
    /// First-order lag time constants T_a per DOF (s): τ̇ = (τ_cmd − τ)/T_a.
    pub lag_s: Option<Vector6<f64>>,
    /// Thrust limits per DOF (N, N·m): τ_cmd is clipped to ±limit.
    pub limits: Option<Vector6<f64>>,
    /// A pure transport delay d (s) of the command, the same in every DOF:
    /// the hull sees τ_cmd(t − d). The plant has no memory of past
    /// commands; whoever holds the command (the flyer,
    /// [`crate::plant::DelayLine`]) delays it before it reaches
    /// [`crate::plant::Plant`].
    pub delay_s: Option<f64>,
    /// Dead-zone half-widths δ per DOF (N, N·m): no thrust for
    /// |τ_cmd| < δ, τ_cmd − sign(τ_cmd)·δ beyond (0: none).
    pub dead_zone: Option<Vector6<f64>>,
}

impl Actuator {
    /// The static part of the actuator map: the dead zone, then the limits.
    pub fn shape(&self, tau_cmd: &Vector6<f64>) -> Vector6<f64> {
        let after_dead_zone = match &self.dead_zone {
            Some(d) => Vector6::from_fn(|i, _| dead_zone(tau_cmd[i], d[i])),
            None => *tau_cmd,
        };
        match &self.limits {
            Some(l) => Vector6::from_fn(|i, _| after_dead_zone[i].clamp(-l[i], l[i])),
            None => after_dead_zone,
        }
    }
}

/// The dead-zone map of half-width `delta` ≥ 0: 0 for |x| < δ (and at
/// |x| = δ), x − sign(x)·δ beyond; continuous, slope 1 outside the zone.
pub fn dead_zone(x: f64, delta: f64) -> f64 {
    if x > delta {
        x - delta
    } else if x < -delta {
        x + delta
    } else {
        0.0
    }
}

/// A current that drifts about its mean `Vessel::current_ned`, one slow
/// sinusoid per NED axis:
///   V_c(t) = V̄_c + Σ_k a_k sin(2π t / T_k + φ_k) e_k,
///   V̇_c(t) = Σ_k a_k (2π / T_k) cos(2π t / T_k + φ_k) e_k,
/// t on the control clock (s). Both its direction and its speed wander.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurrentDrift {
    /// Amplitudes a_k per NED axis (m/s); 0 leaves the axis constant.
    pub amplitude: Vector3<f64>,
    /// Periods T_k (s), > 0 where the amplitude is not 0.
    pub period_s: Vector3<f64>,
    /// Phases φ_k (rad).
    pub phase: Vector3<f64>,
}

impl CurrentDrift {
    /// The drift V_c(t) − V̄_c (m/s).
    pub fn offset(&self, t: f64) -> Vector3<f64> {
        Vector3::from_fn(|k, _| {
            let a = self.amplitude[k];
            if a == 0.0 {
                return 0.0;
            }
            a * (std::f64::consts::TAU * t / self.period_s[k] + self.phase[k]).sin()
        })
    }

    /// Its rate V̇_c(t) (m/s²).
    pub fn rate(&self, t: f64) -> Vector3<f64> {
        Vector3::from_fn(|k, _| {
            let a = self.amplitude[k];
            if a == 0.0 {
                return 0.0;
            }
            let w = std::f64::consts::TAU / self.period_s[k];
            a * w * (w * t + self.phase[k]).cos()
        })
    }
}

/// A narrow-band disturbance fixed in the body frame, outside any library
/// of hull physics (waves on a vehicle near the surface, a vortex-shedding
/// tether, a pump): τ_d(t) = a sin(2π f t + φ), t on the control clock.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Disturbance {
    /// Amplitudes per DOF (N, N·m), body frame.
    pub amplitude: Vector6<f64>,
    /// Frequency f (Hz).
    pub frequency_hz: f64,
    /// Phase φ (rad).
    pub phase: f64,
}

impl Disturbance {
    /// τ_d(t) (N, N·m).
    pub fn force(&self, t: f64) -> Vector6<f64> {
        self.amplitude * (std::f64::consts::TAU * self.frequency_hz * t + self.phase).sin()
    }
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
    /// Ocean current in NED, V_c (m/s), irrotational; zero by default.
    /// Constant, or the mean of [`Vessel::current_drift`].
    pub current_ned: Vector3<f64>,
    /// A slow drift of the current about `current_ned`; None: constant.
    pub current_drift: Option<CurrentDrift>,
    /// A narrow-band force in the body frame, added to τ; None: none.
    pub disturbance: Option<Disturbance>,
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

    /// The current V_c(t) in NED (m/s) at control-clock time `t`.
    pub fn current_at(&self, t: f64) -> Vector3<f64> {
        match &self.current_drift {
            Some(d) => self.current_ned + d.offset(t),
            None => self.current_ned,
        }
    }

    /// Its rate V̇_c(t) in NED (m/s²): zero for a constant current.
    pub fn current_rate_at(&self, t: f64) -> Vector3<f64> {
        self.current_drift
            .as_ref()
            .map_or_else(Vector3::zeros, |d| d.rate(t))
    }

    /// Whether the plant sees a current at all.
    pub fn has_current(&self) -> bool {
        self.current_ned != Vector3::zeros() || self.current_drift.is_some()
    }

    /// The body-frame disturbance τ_d(t) (N, N·m) at control-clock time `t`.
    pub fn disturbance_at(&self, t: f64) -> Vector6<f64> {
        self.disturbance
            .as_ref()
            .map_or_else(Vector6::zeros, |d| d.force(t))
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_dead_zone_removes_delta_and_then_the_limits_clip() {
        // δ = 10: 0 inside, τ ∓ 10 outside, continuous at ±δ
        for (x, want) in [
            (0.0, 0.0),
            (9.99, 0.0),
            (-10.0, 0.0),
            (10.0, 0.0),
            (10.5, 0.5),
            (30.0, 20.0),
            (-30.0, -20.0),
        ] {
            assert_eq!(dead_zone(x, 10.0), want, "x = {x}");
        }
        let a = Actuator {
            dead_zone: Some(Vector6::new(0.0, 0.0, 10.0, 0.0, 0.0, 0.0)),
            limits: Some(Vector6::repeat(15.0)),
            ..Actuator::default()
        };
        let out = a.shape(&Vector6::new(12.0, -3.0, 30.0, 0.0, 0.0, -40.0));
        // heave: 30 − 10 = 20, then clipped at 15; other DOFs only clipped
        assert_eq!(out, Vector6::new(12.0, -3.0, 15.0, 0.0, 0.0, -15.0));
        let ideal = Actuator::default();
        let tau = Vector6::new(1.0, -2.0, 3.0, -4.0, 5.0, -6.0);
        assert_eq!(ideal.shape(&tau), tau);
    }

    #[test]
    fn the_disturbance_is_a_sinusoid_of_the_clock() {
        let d = Disturbance {
            amplitude: Vector6::new(0.0, 40.0, 0.0, 0.0, 0.0, 0.0),
            frequency_hz: 0.1,
            phase: 0.5,
        };
        // 40 sin(2π·0.1·t + 0.5): t = 0 → 40 sin 0.5; t = 2.5 s (a quarter
        // period) → 40 cos 0.5; t = 10 s (a period) → 40 sin 0.5 again
        for (t, want) in [
            (0.0, 40.0 * 0.5f64.sin()),
            (2.5, 40.0 * 0.5f64.cos()),
            (10.0, 40.0 * 0.5f64.sin()),
            (5.0, -40.0 * 0.5f64.sin()),
        ] {
            let f = d.force(t);
            assert!((f[1] - want).abs() < 1e-12, "t = {t}: {}", f[1]);
            assert_eq!(f[0], 0.0);
            assert_eq!(f.rows(2, 4).norm(), 0.0);
        }
    }

    #[test]
    fn the_drift_rate_is_the_derivative_of_the_drift() {
        let d = CurrentDrift {
            amplitude: Vector3::new(0.1, 0.08, 0.0),
            period_s: Vector3::new(400.0, 333.0, 0.0),
            phase: Vector3::new(0.3, -2.0, 1.0),
        };
        let mut v = Vessel::surveyor_like();
        v.current_ned = Vector3::new(0.25, 0.15, 0.0);
        v.current_drift = Some(d);
        assert!(v.has_current());
        let dt = 1e-3;
        for t in [0.0, 123.4, 777.7, 2000.0] {
            let fd = (v.current_at(t + dt) - v.current_at(t - dt)) / (2.0 * dt);
            let rate = v.current_rate_at(t);
            assert!((fd - rate).norm() < 1e-10, "t = {t}: {fd} vs {rate}");
            // within the mean ± amplitude, D axis untouched
            let c = v.current_at(t);
            assert!((c.x - 0.25).abs() <= 0.1 && (c.y - 0.15).abs() <= 0.08);
            assert_eq!(c.z, 0.0);
        }
        // a zero amplitude needs no period
        assert_eq!(v.current_rate_at(5.0).z, 0.0);
        v.current_drift = None;
        assert_eq!(v.current_rate_at(5.0), Vector3::zeros());
        assert_eq!(v.current_at(5.0), v.current_ned);
    }
}
