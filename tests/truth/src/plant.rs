//! The plant and its integrator: state (η, ν, τ_act), right-hand side
//!   M ν̇_r = τ_act + τ_tether − C_RB(ν)ν − C_A(ν_r)ν_r − D(ν_r)ν_r − g(η),
//!   η̇ = J(η)ν,  ν_r = ν − ν_c,
//! integrated by classical fourth-order Runge–Kutta under a zero-order-held
//! command.
//!
//! The current is constant and irrotational in NED, V_c; in the body frame
//! ν_c = (Rᵀ V_c, 0), so ν̇_c = (ν_c₁ × ω, 0) and ν̇ = ν̇_r + ν̇_c.

use nalgebra::{Matrix6, Vector3, Vector6};

use crate::forces::{coriolis_force, restoring_trig};
use crate::kinematics::{Trig, rotation_zyx};
use crate::vessel::Vessel;

/// The plant's state: pose η (NED), velocity over ground ν (body) and the
/// force τ_act the actuators deliver (only a state with an actuator lag).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct State {
    /// η = (x, y, z, φ, θ, ψ) (m, rad); ψ is not wrapped here.
    pub eta: Vector6<f64>,
    /// ν = (u, v, w, p, q, r) (m/s, rad/s).
    pub nu: Vector6<f64>,
    /// τ acting on the hull (N, N·m).
    pub tau_act: Vector6<f64>,
}

impl State {
    /// At rest at pose `eta` moving with `nu`, actuators delivering nothing.
    pub fn new(eta: Vector6<f64>, nu: Vector6<f64>) -> Self {
        State {
            eta,
            nu,
            tau_act: Vector6::zeros(),
        }
    }

    fn axpy(&self, k: &State, s: f64) -> State {
        State {
            eta: self.eta + k.eta * s,
            nu: self.nu + k.nu * s,
            tau_act: self.tau_act + k.tau_act * s,
        }
    }
}

/// A vessel ready to integrate: M, M⁻¹, M_RB and M_A precomputed.
#[derive(Debug, Clone)]
pub struct Plant {
    vessel: Vessel,
    m_rb: Matrix6<f64>,
    m_a: Matrix6<f64>,
    m: Matrix6<f64>,
    m_inv: Matrix6<f64>,
    zg_w_minus_zb_b: f64,
    has_current: bool,
}

impl Plant {
    /// Precomputes the inertia matrices of `vessel`.
    pub fn new(vessel: &Vessel) -> Self {
        let m = vessel.m();
        Plant {
            vessel: vessel.clone(),
            m_rb: vessel.m_rb(),
            m_a: vessel.m_a(),
            m,
            m_inv: m.try_inverse().expect("M is positive definite"),
            zg_w_minus_zb_b: vessel.zg_w_minus_zb_b(),
            has_current: vessel.current_ned != Vector3::zeros(),
        }
    }

    /// The vessel integrated.
    pub fn vessel(&self) -> &Vessel {
        &self.vessel
    }

    /// τ_cmd clipped to the actuator limits, if any.
    pub fn limit(&self, tau_cmd: &Vector6<f64>) -> Vector6<f64> {
        match &self.vessel.actuator.limits {
            Some(l) => Vector6::from_fn(|i, _| tau_cmd[i].clamp(-l[i], l[i])),
            None => *tau_cmd,
        }
    }

    /// The force on the hull at state `x` under command `tau_cmd`.
    pub fn applied_force(&self, x: &State, tau_cmd: &Vector6<f64>) -> Vector6<f64> {
        match self.vessel.actuator.lag_s {
            Some(_) => x.tau_act,
            None => self.limit(tau_cmd),
        }
    }

    /// ν_c = (Rᵀ V_c, 0) in the body frame.
    pub fn current_body(&self, eta: &Vector6<f64>) -> Vector6<f64> {
        if !self.has_current {
            return Vector6::zeros();
        }
        let r = rotation_zyx(eta[3], eta[4], eta[5]);
        let c = r.transpose() * self.vessel.current_ned;
        Vector6::new(c.x, c.y, c.z, 0.0, 0.0, 0.0)
    }

    /// ẋ = f(x, τ_cmd).
    pub fn derivative(&self, x: &State, tau_cmd: &Vector6<f64>) -> State {
        let v = &self.vessel;
        let (tau, tau_act_dot) = match v.actuator.lag_s {
            Some(t) => (
                x.tau_act,
                (self.limit(tau_cmd) - x.tau_act).component_div(&t),
            ),
            None => (self.limit(tau_cmd), Vector6::zeros()),
        };
        let trig = Trig::new(x.eta[3], x.eta[4], x.eta[5]);
        let r = trig.rotation();
        let restoring = restoring_trig(v.w_minus_b, self.zg_w_minus_zb_b, &trig);
        let (nu_r, coriolis) = if self.has_current {
            let nu_r = x.nu - self.current_body(&x.eta);
            let c = coriolis_force(&self.m_rb, &x.nu) + coriolis_force(&self.m_a, &nu_r);
            (nu_r, c)
        } else {
            // ν_r = ν: C_RB(ν)ν + C_A(ν)ν = C(ν)ν with M (C is linear in M)
            (x.nu, coriolis_force(&self.m, &x.nu))
        };
        let hydro = coriolis + v.damping_force(&nu_r) + restoring;
        let pull = r.transpose() * v.tether_ned;
        let tether = v.tether + Vector6::new(pull.x, pull.y, pull.z, 0.0, 0.0, 0.0);
        let mut nu_dot = self.m_inv * (tau + tether - hydro);
        if self.has_current {
            let nu_c = x.nu - nu_r;
            let c1 = Vector3::new(nu_c[0], nu_c[1], nu_c[2]);
            let w = Vector3::new(x.nu[3], x.nu[4], x.nu[5]);
            let dc = c1.cross(&w);
            nu_dot += Vector6::new(dc.x, dc.y, dc.z, 0.0, 0.0, 0.0);
        }
        let p = r * x.nu.fixed_rows::<3>(0);
        let a = trig.attitude_transform() * x.nu.fixed_rows::<3>(3);
        State {
            eta: Vector6::new(p.x, p.y, p.z, a.x, a.y, a.z),
            nu: nu_dot,
            tau_act: tau_act_dot,
        }
    }

    /// One classical RK4 step of length `h` with `tau_cmd` held.
    pub fn rk4_step(&self, x: &State, tau_cmd: &Vector6<f64>, h: f64) -> State {
        let k1 = self.derivative(x, tau_cmd);
        let k2 = self.derivative(&x.axpy(&k1, 0.5 * h), tau_cmd);
        let k3 = self.derivative(&x.axpy(&k2, 0.5 * h), tau_cmd);
        let k4 = self.derivative(&x.axpy(&k3, h), tau_cmd);
        let mut out = *x;
        out = out.axpy(&k1, h / 6.0);
        out = out.axpy(&k2, h / 3.0);
        out = out.axpy(&k3, h / 3.0);
        out.axpy(&k4, h / 6.0)
    }

    /// Advances `x` by `dt` with `tau_cmd` held, in equal RK4 steps no
    /// longer than `h_max`.
    pub fn advance(&self, x: &State, tau_cmd: &Vector6<f64>, dt: f64, h_max: f64) -> State {
        if dt <= 0.0 {
            return *x;
        }
        let n = (dt / h_max - 1e-9).ceil().max(1.0) as usize;
        let h = dt / n as f64;
        let mut s = *x;
        for _ in 0..n {
            s = self.rk4_step(&s, tau_cmd, h);
        }
        s
    }

    /// Kinetic energy ½ νᵀ M ν with M = M_RB + M_A (Fossen 2011, ch. 3).
    pub fn kinetic_energy(&self, nu: &Vector6<f64>) -> f64 {
        0.5 * nu.dot(&(self.m * nu))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tether_fixed_in_ned_turns_with_the_heading() {
        // A 100 N pull to the north on a vessel at rest, neutral and level:
        // heading north it is a surge force, heading east (ψ = π/2) a sway
        // force to port (−y), so M ν̇ = (0, −100, 0, …).
        let mut v = Vessel::surveyor_like();
        v.w_minus_b = 0.0;
        v.tether_ned = Vector3::new(100.0, 0.0, 0.0);
        let plant = Plant::new(&v);
        let m = v.m();
        for (psi, want) in [
            (0.0, [100.0, 0.0]),
            (std::f64::consts::FRAC_PI_2, [0.0, -100.0]),
        ] {
            let x = State::new(
                Vector6::new(0.0, 0.0, 10.0, 0.0, 0.0, psi),
                Vector6::zeros(),
            );
            let f = m * plant.derivative(&x, &Vector6::zeros()).nu;
            assert!(
                (f[0] - want[0]).abs() < 1e-6 && (f[1] - want[1]).abs() < 1e-6,
                "ψ = {psi}: {f}"
            );
            assert!(f.rows(2, 4).norm() < 1e-6, "ψ = {psi}: {f}");
        }
    }
}
