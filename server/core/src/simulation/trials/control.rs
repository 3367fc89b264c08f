//! The vessel's controllers as the simulated pilot flies them: a velocity
//! PI per DOF, and for attitude holds an attitude loop that feeds it a rate
//! reference.

use crate::planning::vessel::DofLimits;
use crate::planning::{AutopilotLoop, Dof, RestoringFeedForward, VesselProfile};

/// Closed-loop bandwidth ω_c of the velocity PI in units of 1/T̂: the nominal
/// loop settles twice as fast as the open-loop DOF. Kept modest because the
/// profile's limits give the mass only roughly (for the Surveyor, m̂ over-
/// estimates the true roll inertia ≈ 9×, which raises the real loop gain).
pub const BANDWIDTH_PER_TIME_CONSTANT: f64 = 2.0;

/// Time constant of the attitude loop in units of the DOF's T̂: twice as
/// slow as T̂, four times slower than the rate loop below it, so a hold
/// settles (1 %) within ≈ 9·T̂ — inside the planner's allowance of 10·T̂
/// ([`crate::planning::statics::ATTITUDE_SETTLE_TIME_CONSTANTS`]). The
/// planner's assumption, which sets the clock of dynamic attitude
/// excitation ([`crate::planning::statics::ATTITUDE_LOOP_TIME_CONSTANTS`]).
pub const ATTITUDE_TIME_CONSTANTS: f64 = crate::planning::statics::ATTITUDE_LOOP_TIME_CONSTANTS;

/// The velocity controller of one DOF: a discrete PI designed on the nominal
/// first-order model m̂ ν̇ + d̂ ν = τ taken from the profile's limits alone
/// (truth-independent):
///
/// - d̂ = τ_max / ν_max (the force that holds the largest velocity),
///   m̂ = T̂ d̂ with T̂ the profile's time constant;
/// - τ = K_p e + K_i ∫e, e = ν_ref − ν, with K_p = m̂ ω_c and
///   K_i = K_p / T̂ = ω_c d̂: the integral zero cancels the nominal pole, so
///   the nominal loop is ω_c / s and ν follows a step in ν_ref as
///   1 − e^{−ω_c t}, with zero steady-state error for any constant
///   reference, ω_c = [`BANDWIDTH_PER_TIME_CONSTANT`] / T̂. The nominal
///   damping d̂ thus enters as the integral gain; there is no separate
///   feed-forward, which with a rough m̂ would only add overshoot;
/// - τ is slew-limited to `max_force_rate` and clipped to `max_force`; the
///   integrator is frozen while the output is limited in the direction e
///   pushes it (conditional-integration anti-windup).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VelocityPi {
    /// K_p (N·s/m or N·m·s/rad).
    pub kp: f64,
    /// K_i (N/m or N·m/rad).
    pub ki: f64,
    /// |τ| ≤ this (N or N·m).
    pub max_force: f64,
    /// |Δτ| ≤ this per controller interval (N or N·m).
    pub max_step: f64,
    /// Controller interval h = 1/f_c (s).
    pub h: f64,
    /// ∫e dt.
    integral: f64,
    /// τ of the previous interval.
    last: f64,
}

impl VelocityPi {
    /// The controller of a DOF with `limits` at controller interval `h`.
    pub fn design(limits: &DofLimits, h: f64) -> Self {
        let d_hat = limits.max_force / limits.max_velocity;
        let m_hat = limits.time_constant_s * d_hat;
        let omega_c = BANDWIDTH_PER_TIME_CONSTANT / limits.time_constant_s;
        let kp = m_hat * omega_c;
        VelocityPi {
            kp,
            ki: kp / limits.time_constant_s,
            max_force: limits.max_force,
            max_step: limits.max_force_rate * h,
            h,
            integral: 0.0,
            last: 0.0,
        }
    }

    /// Closed-loop bandwidth ω_c = K_i / d̂ of the nominal loop (rad/s).
    pub fn bandwidth(&self, limits: &DofLimits) -> f64 {
        self.ki * limits.max_velocity / limits.max_force
    }

    /// τ for this interval from the reference and the measured velocity.
    pub fn step(&mut self, nu_ref: f64, nu: f64) -> f64 {
        let e = nu_ref - nu;
        let wanted = self.kp * e + self.ki * self.integral;
        let tau = wanted
            .clamp(self.last - self.max_step, self.last + self.max_step)
            .clamp(-self.max_force, self.max_force);
        // Integrate unless limited and e would drive the output further out.
        if tau == wanted || e * (wanted - tau) < 0.0 {
            self.integral += e * self.h;
        }
        self.last = tau;
        tau
    }
}

/// The attitude loop of roll or pitch: a proportional law from the
/// attitude error to a rate reference, ν_ref = (η_ref − η)/(2T̂), limited to
/// the DOF's `max_velocity`, which the velocity PI then flies. In a steady
/// hold the rate is zero and the PI's integral carries the moment that
/// balances g(η) and any constant load: the steady state the restoring
/// estimate reads.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AttitudeLoop {
    /// Gain (1/s).
    pub gain: f64,
    /// |ν_ref| ≤ this (rad/s).
    pub max_rate: f64,
}

impl AttitudeLoop {
    /// The attitude loop of a DOF with `limits`.
    pub fn design(limits: &DofLimits) -> Self {
        AttitudeLoop {
            gain: 1.0 / (ATTITUDE_TIME_CONSTANTS * limits.time_constant_s),
            max_rate: limits.max_velocity,
        }
    }

    /// The rate reference for attitude reference `eta_ref` at attitude `eta`.
    pub fn rate_reference(&self, eta_ref: f64, eta: f64) -> f64 {
        (self.gain * (eta_ref - eta)).clamp(-self.max_rate, self.max_rate)
    }
}

/// What one DOF's declared loop is asked to fly this interval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Setpoint {
    /// A velocity (roll, pitch: rate) reference; an attitude loop flies
    /// η_ref = ∫ν_ref dt from the run's start with ν_ref fed forward.
    Velocity(f64),
    /// A roll or pitch attitude reference.
    Attitude(f64),
    /// Open loop or passive: the loop is idle.
    Idle,
}

/// The vessel's declared autopilot ([`Autopilot`](crate::planning::Autopilot)) in flight: every DOF's
/// loop on the measured state, the restoring feed-forward ĝ(η_measured),
/// τ clipped at the profile's `max_force` with conditional integration.
#[derive(Debug, Clone, PartialEq)]
pub struct DeclaredAutopilot {
    loops: [Option<AutopilotLoop>; 6],
    feed_forward: Option<RestoringFeedForward>,
    max_force: [f64; 6],
    /// The DOF's own attitude loop, for a roll/pitch attitude schedule
    /// flown by a declared velocity (rate) loop.
    outer: [Option<AttitudeLoop>; 6],
    h: f64,
    integral: [f64; 6],
    /// ∫ν_ref dt of a rate-driven attitude loop.
    attitude_ref: [f64; 6],
}

impl DeclaredAutopilot {
    /// The autopilot of `profile` (`None` without one) at interval `h`.
    pub fn of(profile: &VesselProfile, h: f64) -> Option<Self> {
        let a = profile.autopilot.as_ref()?;
        let loops = std::array::from_fn(|i| a.loops.get(&Dof::ALL[i]).copied());
        let max_force = std::array::from_fn(|i| {
            profile
                .limits
                .get(&Dof::ALL[i])
                .map_or(0.0, |l| l.max_force)
        });
        let outer =
            std::array::from_fn(|i| profile.limits.get(&Dof::ALL[i]).map(AttitudeLoop::design));
        Some(DeclaredAutopilot {
            loops,
            feed_forward: a.restoring_feed_forward,
            max_force,
            outer,
            h,
            integral: [0.0; 6],
            attitude_ref: [0.0; 6],
        })
    }

    /// τ of the DOFs with a set-point (`None` where idle) and the rate
    /// reference each loop flies, from the measured ν and η. `running`:
    /// past the lead-in (rate-driven attitude references integrate from
    /// the run's start).
    pub fn step(
        &mut self,
        setpoints: &[Setpoint; 6],
        nu_m: &[f64; 6],
        eta_m: &[f64; 6],
        running: bool,
    ) -> ([Option<f64>; 6], [f64; 6]) {
        let ff = self
            .feed_forward
            .map_or([0.0; 6], |g| g.force(eta_m[3], eta_m[4]));
        let mut tau = [None; 6];
        let mut rate = [0.0; 6];
        for i in 0..6 {
            let Some(l) = self.loops[i] else { continue };
            let attitude = if l.holds_attitude() {
                match setpoints[i] {
                    Setpoint::Velocity(w) => {
                        if running {
                            self.attitude_ref[i] += w * self.h;
                        }
                        Some((self.attitude_ref[i], if running { w } else { 0.0 }))
                    }
                    Setpoint::Attitude(a) => Some((a, 0.0)),
                    Setpoint::Idle => None,
                }
            } else {
                None
            };
            // e: the error the integral sums; raw: the loop's output.
            let (e, raw) = match (attitude, setpoints[i]) {
                (Some((eta_ref, w)), _) => {
                    rate[i] = w;
                    let e = eta_ref - eta_m[i];
                    let kd = l.kd.unwrap_or(0.0);
                    (e, l.kp * e + kd * (w - nu_m[i]) + l.ki * self.integral[i])
                }
                (None, Setpoint::Idle) => continue,
                (None, sp) => {
                    let nu_ref = match (sp, &self.outer[i]) {
                        (Setpoint::Attitude(a), Some(o)) => o.rate_reference(a, eta_m[i]),
                        (Setpoint::Velocity(v), _) => v,
                        _ => 0.0,
                    };
                    rate[i] = nu_ref;
                    let e = nu_ref - nu_m[i];
                    (e, l.kp * e + l.ki * self.integral[i])
                }
            };
            let wanted = raw + ff[i];
            let lim = self.max_force[i];
            let out = wanted.clamp(-lim, lim);
            if out == wanted || e * (wanted - out) < 0.0 {
                self.integral[i] += e * self.h;
            }
            tau[i] = Some(out);
        }
        (tau, rate)
    }
}
