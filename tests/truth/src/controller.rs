//! The other team's autopilot, a 20 Hz discrete controller on the measured
//! (noisy) state, as on the Surveyor ROV (thesis §1.4: SISO PID loops per
//! degree of freedom, automatic roll and pitch):
//! - PI loops on u, v, w, r: τᵢ = Kpᵢ eᵢ + Kiᵢ ∫eᵢ, e = ν_ref − ν_meas;
//! - PD attitude loops on φ, θ: τ = Kp (Θ_ref − Θ_meas) + Kd (ω_ref − ω_meas),
//!   with Kp = Î ω² + ½ ẑ_G W and Kd = 2ζ √(Kp Î); the rate feed-forward
//!   ω_ref = (p_ref, q_ref) is zero in the truth's own campaign (pure rate
//!   damping) and set only when an external schedule asks for roll/pitch rates;
//! - feed-forward of a NOMINAL ĝ(η_meas) (eq. 4.6 with the team's W − B and
//!   z_G W − z_B B, off the truth by 20–40 %);
//! - τ_cmd = feedback + ĝ(η), clipped at per-DOF limits, with conditional
//!   integration (no wind-up while a loop is saturated).

use nalgebra::Vector6;

use crate::forces::restoring_lumped;
use crate::rng::Rng;
use crate::vessel::Vessel;

/// Controller period (s): 20 Hz.
pub const CONTROL_DT: f64 = 0.05;

/// Loop bandwidths (rad/s): surge, sway, heave, roll, pitch, yaw.
const BANDWIDTH: [f64; 6] = [0.6, 0.8, 0.8, 1.2, 1.2, 0.8];

/// Damping ratio of the attitude loops.
const ATTITUDE_ZETA: f64 = 0.8;

/// DOFs under velocity PI control (u, v, w, r).
pub const VELOCITY_DOFS: [usize; 4] = [0, 1, 2, 5];

/// Set-points at one controller sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reference {
    /// Velocity set-points: entries 0, 1, 2, 5 (u, v, w, r) drive the PI
    /// loops; entries 3, 4 (p, q) are the attitude loops' rate feed-forward
    /// (zero: pure rate damping).
    pub nu: Vector6<f64>,
    /// Roll set-point φ_ref (rad).
    pub phi: f64,
    /// Pitch set-point θ_ref (rad).
    pub theta: f64,
}

/// Gains, limits and the team's nominal restoring model.
#[derive(Debug, Clone, PartialEq)]
pub struct ControllerConfig {
    /// Proportional gains (velocity loops: N per m/s; attitude: N·m per rad).
    pub kp: Vector6<f64>,
    /// Integral gains of the velocity loops (zero for roll, pitch).
    pub ki: Vector6<f64>,
    /// Rate gains of the attitude loops (zero elsewhere).
    pub kd: Vector6<f64>,
    /// |τ_cmd,i| ≤ `limits[i]`.
    pub limits: Vector6<f64>,
    /// The team's W − B (N).
    pub nominal_w_minus_b: f64,
    /// The team's z_G W − z_B B (N·m).
    pub nominal_zg_w_minus_zb_b: f64,
}

/// The speeds a campaign reaches, for sizing thrust limits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Envelope {
    /// Highest forward speed including excitation (m/s).
    pub u_max: f64,
    /// Excitation amplitude per DOF: u, v, w (m/s), φ, θ (rad), r (rad/s).
    pub amplitude: [f64; 6],
}

impl ControllerConfig {
    /// Gains from the team's nominal inertia (the true diagonal of M off by
    /// up to ±20 %), ĝ off by 20–40 % (random sign), and limits of twice the
    /// largest force the envelope needs, so normal runs rarely saturate.
    pub fn tune(vessel: &Vessel, envelope: &Envelope, rng: &mut Rng) -> Self {
        let m = vessel.m();
        let mut kp = Vector6::zeros();
        let mut ki = Vector6::zeros();
        let mut kd = Vector6::zeros();
        let mut off = || 1.0 + rng.sign() * rng.range(0.2, 0.4);
        let nominal_w_minus_b = vessel.w_minus_b * off();
        let nominal_zg_w_minus_zb_b = vessel.zg_w_minus_zb_b() * off();
        for i in 0..6 {
            let nominal = m[(i, i)] * rng.range(0.8, 1.2);
            let w = BANDWIDTH[i];
            if i == 3 || i == 4 {
                // The feed-forward cancels ĝ, so the loop's stiffness is
                // Kp + (z_G W − ẑ_G W): half the nominal righting moment in
                // Kp keeps it positive when ĝ overshoots the truth by 40 %.
                kp[i] = nominal * w * w + 0.5 * nominal_zg_w_minus_zb_b.abs();
                kd[i] = 2.0 * ATTITUDE_ZETA * (kp[i] * nominal).sqrt();
            } else {
                kp[i] = nominal * w;
                ki[i] = kp[i] * w / 3.0;
            }
        }
        ControllerConfig {
            kp,
            ki,
            kd,
            limits: thrust_limits(vessel, envelope),
            nominal_w_minus_b,
            nominal_zg_w_minus_zb_b,
        }
    }

    /// The team's ĝ(η) at roll `phi`, pitch `theta`.
    pub fn nominal_restoring(&self, phi: f64, theta: f64) -> Vector6<f64> {
        restoring_lumped(
            self.nominal_w_minus_b,
            self.nominal_zg_w_minus_zb_b,
            phi,
            theta,
        )
    }
}

/// Twice the largest |C(ν)ν + D(ν)ν|ᵢ over the envelope's corners (u_max plus
/// one excited DOF at 1.5× its amplitude, attitude DOFs at their rate), plus
/// Mᵢᵢ·speed·bandwidth for acceleration, the restoring force at 1.5× the
/// attitude amplitude, the tether and the disturbance's amplitude.
fn thrust_limits(vessel: &Vessel, env: &Envelope) -> Vector6<f64> {
    let m = vessel.m();
    let speed = |j: usize| {
        let a = 1.5 * env.amplitude[j];
        if j == 3 || j == 4 {
            a * BANDWIDTH[j]
        } else {
            a
        }
    };
    let mut worst = Vector6::<f64>::zeros();
    for j in 0..6 {
        for s in [-1.0, 1.0] {
            let mut nu = Vector6::zeros();
            nu[0] = env.u_max;
            if j > 0 {
                nu[j] = s * speed(j);
            }
            let f = vessel.hydrodynamic_force(&nu);
            worst = worst.zip_map(&f, |w, x| w.max(x.abs()));
        }
    }
    let tilt = 1.5 * env.amplitude[3].max(env.amplitude[4]).max(0.05);
    let g = vessel.restoring(&Vector6::new(0.0, 0.0, 0.0, tilt, tilt, 0.0));
    Vector6::from_fn(|i, _| {
        let accel = m[(i, i)] * speed(i) * BANDWIDTH[i];
        let limit = 2.0
            * (worst[i]
                + accel
                + g[i].abs().max(vessel.w_minus_b.abs())
                + (vessel.tether[i].abs() + vessel.tether_ned.norm()));
        match &vessel.disturbance {
            Some(d) => limit + 2.0 * d.amplitude[i].abs(),
            None => limit,
        }
    })
}

/// The controller's memory: the velocity loops' integrators.
#[derive(Debug, Clone, PartialEq)]
pub struct Controller {
    /// Configuration.
    pub cfg: ControllerConfig,
    integ: Vector6<f64>,
}

impl Controller {
    /// Integrators at zero.
    pub fn new(cfg: ControllerConfig) -> Self {
        Controller {
            cfg,
            integ: Vector6::zeros(),
        }
    }

    /// Sets the velocity integrators so that Kiᵢ ∫eᵢ = `force[i]` (a vehicle
    /// already flying in trim).
    pub fn preset(&mut self, force: &Vector6<f64>) {
        for i in VELOCITY_DOFS {
            self.integ[i] = force[i] / self.cfg.ki[i];
        }
    }

    /// One sample: τ_cmd from measured ν, η and the set-points; also which
    /// DOFs hit their limit.
    pub fn update(
        &mut self,
        nu: &Vector6<f64>,
        eta: &Vector6<f64>,
        r: &Reference,
    ) -> (Vector6<f64>, [bool; 6]) {
        let c = &self.cfg;
        let mut fb = Vector6::zeros();
        let mut e = Vector6::zeros();
        for i in VELOCITY_DOFS {
            e[i] = r.nu[i] - nu[i];
            fb[i] = c.kp[i] * e[i] + c.ki[i] * self.integ[i];
        }
        fb[3] = c.kp[3] * (r.phi - eta[3]) + c.kd[3] * (r.nu[3] - nu[3]);
        fb[4] = c.kp[4] * (r.theta - eta[4]) + c.kd[4] * (r.nu[4] - nu[4]);
        let raw = fb + c.nominal_restoring(eta[3], eta[4]);
        let mut sat = [false; 6];
        let tau = Vector6::from_fn(|i, _| {
            let l = c.limits[i];
            sat[i] = raw[i].abs() > l;
            raw[i].clamp(-l, l)
        });
        for i in VELOCITY_DOFS {
            // conditional integration: only when it does not push further out
            if !sat[i] || e[i] * raw[i] < 0.0 {
                self.integ[i] += e[i] * CONTROL_DT;
            }
        }
        (tau, sat)
    }
}
