//! The plant and its integrator: state (η, ν, τ_act), right-hand side
//!   M_RB ν̇ + M_A ν̇_r = τ_act + τ_tether + τ_d(t) − C_RB(ν)ν − C_A(ν_r)ν_r − D(ν_r)ν_r − g(η),
//!   η̇ = J(η)ν,  ν_r = ν − ν_c (Fossen 2011, eq. 10.1), solved as
//!   M ν̇_r = … − M_RB ν̇_c and ν̇ = ν̇_r + ν̇_c,
//! integrated by classical fourth-order Runge–Kutta under a zero-order-held
//! command. Time t (the control clock) enters only through a drifting
//! current and the disturbance τ_d(t); without them the `_at` methods give
//! the same numbers at every t.
//!
//! The current is irrotational in NED, V_c(t); in the body frame
//! ν_c = (Rᵀ V_c, 0). With Ṙ = R S(ω) (Fossen 2011, eq. 2.27),
//! d(Rᵀ)/dt = S(ω)ᵀ Rᵀ = −S(ω) Rᵀ, so
//!   ν̇_c₁ = −ω × (Rᵀ V_c) + Rᵀ V̇_c = ν_c₁ × ω + Rᵀ V̇_c,  ν̇_c₂ = 0,
//! and ν̇ = ν̇_r + ν̇_c. A constant current has V̇_c = 0.
//!
//! A transport delay has memory the state does not carry: the flyer keeps
//! the commands issued ([`DelayLine`]) and hands the plant the delayed one.

use nalgebra::{Matrix6, Vector3, Vector6};

use crate::forces::{coriolis_force, restoring_trig};
use crate::kinematics::{Trig, rotation_zyx};
use crate::vessel::Vessel;

/// A pure transport delay d of a zero-order-held command: the command issued
/// at t_k holds until the next one, and the hull sees τ_cmd(t − d), the
/// command issued last at or before t − d (`before` if none was). Queries
/// need not come in order.
///
/// Used by the flyer with the step's midpoint (each RK4 step of length h
/// from t_s holds τ_cmd(t_s + h/2 − d)): exact when d is a multiple of h
/// (the delayed jumps fall on step boundaries); otherwise each jump moves
/// to the nearest step boundary, an error of at most h/2 (2.5 ms at 200 Hz).
#[derive(Debug, Clone, PartialEq)]
pub struct DelayLine {
    delay_s: f64,
    before: Vector6<f64>,
    times: Vec<f64>,
    commands: Vec<Vector6<f64>>,
}

impl DelayLine {
    /// A delay of `delay_s` (s) that delivers `before` until the first
    /// command issued arrives.
    pub fn new(delay_s: f64, before: Vector6<f64>) -> Self {
        DelayLine {
            delay_s,
            before,
            times: Vec::new(),
            commands: Vec::new(),
        }
    }

    /// The delay d (s).
    pub fn delay_s(&self) -> f64 {
        self.delay_s
    }

    /// Records the command issued at `t`, held until the next one; `t` must
    /// not precede the last command's time.
    pub fn push(&mut self, t: f64, tau: Vector6<f64>) {
        debug_assert!(self.times.last().is_none_or(|&l| l <= t));
        self.times.push(t);
        self.commands.push(tau);
    }

    /// The command reaching the hull at time `t`: τ_cmd(t − d).
    pub fn at(&self, t: f64) -> Vector6<f64> {
        let s = t - self.delay_s;
        match self.times.partition_point(|&tk| tk <= s) {
            0 => self.before,
            n => self.commands[n - 1],
        }
    }
}

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
            has_current: vessel.has_current(),
        }
    }

    /// The vessel integrated.
    pub fn vessel(&self) -> &Vessel {
        &self.vessel
    }

    /// τ_cmd through the actuators' static map: the dead zone, then the
    /// limits (identity when neither is set).
    pub fn limit(&self, tau_cmd: &Vector6<f64>) -> Vector6<f64> {
        self.vessel.actuator.shape(tau_cmd)
    }

    /// The force on the hull at state `x` under command `tau_cmd` (the
    /// command that reaches the hull: already delayed, if there is a delay).
    pub fn applied_force(&self, x: &State, tau_cmd: &Vector6<f64>) -> Vector6<f64> {
        match self.vessel.actuator.lag_s {
            Some(_) => x.tau_act,
            None => self.limit(tau_cmd),
        }
    }

    /// ν_c = (Rᵀ V_c, 0) in the body frame at t = 0 (a constant current:
    /// at any time).
    pub fn current_body(&self, eta: &Vector6<f64>) -> Vector6<f64> {
        self.current_body_at(0.0, eta)
    }

    /// ν_c(t) = (R(Θ)ᵀ V_c(t), 0) in the body frame at control-clock time `t`.
    pub fn current_body_at(&self, t: f64, eta: &Vector6<f64>) -> Vector6<f64> {
        if !self.has_current {
            return Vector6::zeros();
        }
        let r = rotation_zyx(eta[3], eta[4], eta[5]);
        let c = r.transpose() * self.vessel.current_at(t);
        Vector6::new(c.x, c.y, c.z, 0.0, 0.0, 0.0)
    }

    /// ẋ = f(x, τ_cmd) at t = 0 (see [`Plant::derivative_at`]).
    pub fn derivative(&self, x: &State, tau_cmd: &Vector6<f64>) -> State {
        self.derivative_at(0.0, x, tau_cmd)
    }

    /// ẋ = f(t, x, τ_cmd), `tau_cmd` the command reaching the hull.
    pub fn derivative_at(&self, t: f64, x: &State, tau_cmd: &Vector6<f64>) -> State {
        let v = &self.vessel;
        let (tau, tau_act_dot) = match v.actuator.lag_s {
            Some(t_a) => (
                x.tau_act,
                (self.limit(tau_cmd) - x.tau_act).component_div(&t_a),
            ),
            None => (self.limit(tau_cmd), Vector6::zeros()),
        };
        let trig = Trig::new(x.eta[3], x.eta[4], x.eta[5]);
        let r = trig.rotation();
        let restoring = restoring_trig(v.w_minus_b, self.zg_w_minus_zb_b, &trig);
        let (nu_r, coriolis) = if self.has_current {
            let nu_r = x.nu - self.current_body_at(t, &x.eta);
            let c = coriolis_force(&self.m_rb, &x.nu) + coriolis_force(&self.m_a, &nu_r);
            (nu_r, c)
        } else {
            // ν_r = ν: C_RB(ν)ν + C_A(ν)ν = C(ν)ν with M (C is linear in M)
            (x.nu, coriolis_force(&self.m, &x.nu))
        };
        let hydro = coriolis + v.damping_force(&nu_r) + restoring;
        let pull = r.transpose() * v.tether_ned;
        let mut tether = v.tether + Vector6::new(pull.x, pull.y, pull.z, 0.0, 0.0, 0.0);
        if let Some(d) = &v.disturbance {
            tether += d.force(t);
        }
        // Fossen (2011, eq. 10.1): M_RB ν̇ + M_A ν̇_r + … = τ with
        // ν̇ = ν̇_r + ν̇_c, so M ν̇_r = τ − M_RB ν̇_c − …, and then ν̇ = ν̇_r + ν̇_c.
        let nu_c_dot = if self.has_current {
            // ν̇_c₁ = ν_c₁ × ω + Rᵀ V̇_c (module notes)
            let nu_c = x.nu - nu_r;
            let c1 = Vector3::new(nu_c[0], nu_c[1], nu_c[2]);
            let w = Vector3::new(x.nu[3], x.nu[4], x.nu[5]);
            let mut dc = c1.cross(&w);
            if v.current_drift.is_some() {
                dc += r.transpose() * v.current_rate_at(t);
            }
            Vector6::new(dc.x, dc.y, dc.z, 0.0, 0.0, 0.0)
        } else {
            Vector6::zeros()
        };
        let nu_dot = self.m_inv * (tau + tether - hydro - self.m_rb * nu_c_dot) + nu_c_dot;
        let p = r * x.nu.fixed_rows::<3>(0);
        let a = trig.attitude_transform() * x.nu.fixed_rows::<3>(3);
        State {
            eta: Vector6::new(p.x, p.y, p.z, a.x, a.y, a.z),
            nu: nu_dot,
            tau_act: tau_act_dot,
        }
    }

    /// One classical RK4 step of length `h` with `tau_cmd` held, from t = 0
    /// (see [`Plant::rk4_step_at`]).
    pub fn rk4_step(&self, x: &State, tau_cmd: &Vector6<f64>, h: f64) -> State {
        self.rk4_step_at(0.0, x, tau_cmd, h)
    }

    /// One classical RK4 step of length `h` from time `t` with `tau_cmd` held.
    pub fn rk4_step_at(&self, t: f64, x: &State, tau_cmd: &Vector6<f64>, h: f64) -> State {
        let t_half = t + 0.5 * h;
        let k1 = self.derivative_at(t, x, tau_cmd);
        let k2 = self.derivative_at(t_half, &x.axpy(&k1, 0.5 * h), tau_cmd);
        let k3 = self.derivative_at(t_half, &x.axpy(&k2, 0.5 * h), tau_cmd);
        let k4 = self.derivative_at(t + h, &x.axpy(&k3, h), tau_cmd);
        let mut out = *x;
        out = out.axpy(&k1, h / 6.0);
        out = out.axpy(&k2, h / 3.0);
        out = out.axpy(&k3, h / 3.0);
        out.axpy(&k4, h / 6.0)
    }

    /// Advances `x` by `dt` with `tau_cmd` held, in equal RK4 steps no
    /// longer than `h_max`, from t = 0 (see [`Plant::advance_with`]).
    pub fn advance(&self, x: &State, tau_cmd: &Vector6<f64>, dt: f64, h_max: f64) -> State {
        self.advance_with(0.0, x, |_| *tau_cmd, dt, h_max)
    }

    /// Advances `x` from time `t` by `dt` in equal RK4 steps no longer than
    /// `h_max`, each step holding `command(t_mid)`, the command reaching the
    /// hull at the step's midpoint (e.g. [`DelayLine::at`] of a delayed
    /// one).
    pub fn advance_with(
        &self,
        t: f64,
        x: &State,
        command: impl Fn(f64) -> Vector6<f64>,
        dt: f64,
        h_max: f64,
    ) -> State {
        if dt <= 0.0 {
            return *x;
        }
        let n = (dt / h_max - 1e-9).ceil().max(1.0) as usize;
        let h = dt / n as f64;
        let mut s = *x;
        for k in 0..n {
            let ts = t + k as f64 * h;
            s = self.rk4_step_at(ts, &s, &command(ts + 0.5 * h), h);
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
    use crate::forces::coriolis_force;
    use crate::vessel::{CurrentDrift, Disturbance};

    fn level_at_rest() -> State {
        State::new(
            Vector6::new(0.0, 0.0, 30.0, 0.0, 0.0, 0.4),
            Vector6::zeros(),
        )
    }

    #[test]
    fn a_delay_line_hands_on_the_command_issued_d_earlier() {
        let before = Vector6::repeat(-1.0);
        let mut line = DelayLine::new(0.3, before);
        for k in 0..10 {
            line.push(0.05 * k as f64, Vector6::repeat(k as f64));
        }
        // the hull sees τ_cmd(t − 0.3): command k from 0.05 k + 0.3 on
        assert_eq!(line.at(0.0), before);
        assert_eq!(line.at(0.2999), before);
        assert_eq!(line.at(0.3), Vector6::repeat(0.0));
        assert_eq!(line.at(0.3 + 0.05 * 4.0 + 0.0025), Vector6::repeat(4.0));
        assert_eq!(line.at(0.3 + 0.05 * 4.0 - 0.0025), Vector6::repeat(3.0));
        assert_eq!(line.at(100.0), Vector6::repeat(9.0));
    }

    #[test]
    fn a_delayed_command_acts_exactly_d_later_at_the_integrator_resolution() {
        // d = 0.285 s = 57 steps of 5 ms, not a whole number of 20 Hz
        // ticks. Flown through the delay line, step midpoints reading it,
        // the run equals the hand-made one: `before` over [0, d), then
        // command k held over [0.05 k + d, 0.05 (k + 1) + d).
        let v = Vessel::draw(3);
        let plant = Plant::new(&v);
        let (d, h) = (0.285, 0.005);
        let before = Vector6::new(20.0, 0.0, -10.0, 0.0, 0.0, 0.0);
        let cmd = |k: usize| {
            let s = k as f64;
            Vector6::new(
                60.0 * (0.7 * s).sin(),
                40.0 * (0.3 * s).cos(),
                -30.0 + 5.0 * s.sqrt(),
                2.0 * (1.1 * s).sin(),
                3.0 * (0.9 * s).cos(),
                10.0 * (0.5 * s).sin(),
            )
        };
        let ticks = 40;
        let mut line = DelayLine::new(d, before);
        for k in 0..ticks {
            line.push(0.05 * k as f64, cmd(k));
        }
        let x0 = level_at_rest();
        let t_end = d + 0.05 * ticks as f64;
        let delayed = plant.advance_with(0.0, &x0, |t| line.at(t), t_end, h);
        let mut by_hand = plant.advance(&x0, &before, d, h);
        for k in 0..ticks {
            by_hand = plant.advance(&by_hand, &cmd(k), 0.05, h);
        }
        let err = (delayed.nu - by_hand.nu).norm() + (delayed.eta - by_hand.eta).norm();
        assert!(err < 1e-10, "delayed vs by hand: {err:e}");
        // and it is not the undelayed run
        let mut undelayed = x0;
        for k in 0..ticks {
            undelayed = plant.advance(&undelayed, &cmd(k), 0.05, h);
        }
        undelayed = plant.advance(&undelayed, &cmd(ticks - 1), d, h);
        assert!((undelayed.nu - by_hand.nu).norm() > 1e3 * err.max(1e-12));
    }

    #[test]
    fn a_heave_dead_zone_shapes_the_force_on_the_hull() {
        // level, at rest, W = B: M ν̇ is the shaped command alone
        let mut v = Vessel::draw(2).without_restoring();
        v.actuator.dead_zone = Some(Vector6::new(0.0, 0.0, 20.0, 0.0, 0.0, 0.0));
        let plant = Plant::new(&v);
        let m = v.m();
        let x = level_at_rest();
        for (cmd, want) in [(50.0, 30.0), (15.0, 0.0), (-15.0, 0.0), (-50.0, -30.0)] {
            let tau = Vector6::new(7.0, 0.0, cmd, 0.0, 0.0, 0.0);
            let f = m * plant.derivative(&x, &tau).nu;
            assert!((f[2] - want).abs() < 1e-9, "τ_Z {cmd}: {}", f[2]);
            assert!((f[0] - 7.0).abs() < 1e-9, "surge untouched: {}", f[0]);
            assert_eq!(plant.applied_force(&x, &tau)[2], want);
        }
    }

    #[test]
    fn the_sway_disturbance_acts_at_the_plant_time() {
        let mut v = Vessel::draw(2).without_restoring();
        v.disturbance = Some(Disturbance {
            amplitude: Vector6::new(0.0, 40.0, 0.0, 0.0, 0.0, 0.0),
            frequency_hz: 0.1,
            phase: 0.5,
        });
        let plant = Plant::new(&v);
        let m = v.m();
        let x = level_at_rest();
        for t in [0.0, 2.5, 7.3, 613.25] {
            let f = m * plant.derivative_at(t, &x, &Vector6::zeros()).nu;
            let want = 40.0 * (std::f64::consts::TAU * 0.1 * t + 0.5).sin();
            assert!((f[1] - want).abs() < 1e-9, "t = {t}: {} vs {want}", f[1]);
            assert!(f[0].abs() < 1e-9 && f.rows(2, 4).norm() < 1e-9, "{f}");
        }
    }

    /// A drifting current in a turn: ν_c = Rᵀ V_c(t) along an integrated
    /// trajectory, and the plant's ν with it.
    fn drifting_trajectory() -> (Vessel, Vec<(f64, State)>, Vector6<f64>, f64) {
        let mut v = Vessel::draw(4);
        v.current_ned = Vector3::new(0.25, 0.15, 0.0);
        // fast for a test (periods of 20 and 15 s), so Rᵀ V̇_c is large
        v.current_drift = Some(CurrentDrift {
            amplitude: Vector3::new(0.2, 0.15, 0.05),
            period_s: Vector3::new(20.0, 15.0, 30.0),
            phase: Vector3::new(0.3, -1.0, 2.0),
        });
        let plant = Plant::new(&v);
        // thrust that rolls, pitches and turns the vehicle
        let tau = Vector6::new(60.0, 30.0, 10.0, 8.0, 12.0, 40.0);
        let h = 1e-3;
        let mut x = level_at_rest();
        let mut out = vec![(0.0, x)];
        for k in 0..6000 {
            let t = k as f64 * h;
            x = plant.rk4_step_at(t, &x, &tau, h);
            out.push((t + h, x));
        }
        (v, out, tau, h)
    }

    #[test]
    fn the_body_current_changes_as_r_transpose_v_dot_plus_nu_c_cross_omega() {
        // d/dt (R(Θ)ᵀ V_c(t)) by fourth-order central differences along
        // the trajectory against Rᵀ V̇_c + ν_c₁ × ω (module notes).
        let (v, traj, _, h) = drifting_trajectory();
        let plant = Plant::new(&v);
        let nu_c = |k: usize| {
            let (t, x) = &traj[k];
            plant
                .current_body_at(*t, &x.eta)
                .fixed_rows::<3>(0)
                .into_owned()
        };
        let (mut worst, mut rotating, mut drifting) = (0.0f64, 0.0f64, 0.0f64);
        for k in (500..traj.len() - 1).step_by(250) {
            let (t, x) = &traj[k];
            let fd = (nu_c(k - 2) - nu_c(k + 2) + 8.0 * (nu_c(k + 1) - nu_c(k - 1))) / (12.0 * h);
            let r = rotation_zyx(x.eta[3], x.eta[4], x.eta[5]);
            let w = Vector3::new(x.nu[3], x.nu[4], x.nu[5]);
            let turn = nu_c(k).cross(&w);
            let drift = r.transpose() * v.current_rate_at(*t);
            worst = worst.max((fd - turn - drift).norm());
            rotating = rotating.max(turn.norm());
            drifting = drifting.max(drift.norm());
        }
        assert!(worst < 1e-9, "finite difference off by {worst:e}");
        // both terms matter here
        assert!(
            rotating > 1e3 * worst && drifting > 1e3 * worst,
            "{rotating} {drifting}"
        );
    }

    #[test]
    fn under_a_drifting_current_the_relative_velocity_obeys_the_kinetics() {
        // Fossen (2011, eq. 10.1) along the trajectory, with ν̇ and ν̇_r
        // from (fourth-order) central differences of ν and ν_r = ν − ν_c:
        // M_RB ν̇ + M_A ν̇_r = τ − C_RB(ν)ν − C_A(ν_r)ν_r − D(ν_r)ν_r − g(η),
        // written here from the force functions, not through the plant's ν̇_c.
        let (v, traj, tau, h) = drifting_trajectory();
        let plant = Plant::new(&v);
        let nu = |k: usize| traj[k].1.nu;
        let nu_r = |k: usize| {
            let (t, x) = &traj[k];
            x.nu - plant.current_body_at(*t, &x.eta)
        };
        let mut worst = 0.0f64;
        let mut scale = 0.0f64;
        for k in (500..traj.len() - 1).step_by(250) {
            let x = &traj[k].1;
            let fd_r = (nu_r(k - 2) - nu_r(k + 2) + 8.0 * (nu_r(k + 1) - nu_r(k - 1))) / (12.0 * h);
            let fd = (nu(k - 2) - nu(k + 2) + 8.0 * (nu(k + 1) - nu(k - 1))) / (12.0 * h);
            let nr = nu_r(k);
            let lhs = v.m_rb() * fd + v.m_a() * fd_r;
            let rhs = tau
                - coriolis_force(&v.m_rb(), &x.nu)
                - coriolis_force(&v.m_a(), &nr)
                - v.damping_force(&nr)
                - v.restoring(&x.eta);
            worst = worst.max((lhs - rhs).norm());
            scale = scale.max(rhs.norm());
        }
        assert!(
            worst < 1e-8 * scale.max(1.0),
            "off by {worst:e} (scale {scale})"
        );
    }

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
