//! Running the truth: RK4 at a fine internal step with the commanded τ held
//! over each record interval (zero-order hold, as the logger sees a
//! controller that updates at the record rate), logged at the record rate
//! with optional Gaussian measurement noise on ν and η.

use nalgebra::{DMatrix, Matrix6, Vector3, Vector6};

use super::current::CurrentProcess;
use super::damping::{damping_force, nonlinear_damping_force};
use super::error::{SimError, finite, non_negative};
use super::kinematics::{eta_dot, rotation};
use super::params::RovTruth;
use super::record::RovRecord;
use crate::models::coriolis::coriolis_6dof;
use crate::planning::dof::Dof;
use crate::rng::SplitMix64;
use crate::simulation::integrate::rk4_step;

/// Record rate, integration step, initial state and measurement noise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimConfig {
    /// Record sample time h (s); thesis validation used 0.1 s.
    pub h: f64,
    /// RK4 steps per record sample (internal step h / substeps).
    pub substeps: usize,
    /// ν(0) over ground (m/s, rad/s).
    pub nu0: [f64; 6],
    /// η(0) (m, rad); |θ(0)| < 90°.
    pub eta0: [f64; 6],
    /// Standard deviation of the white noise on each measured ν channel.
    pub noise_nu: [f64; 6],
    /// Standard deviation of the white noise on each measured η channel.
    pub noise_eta: [f64; 6],
    /// Seed of the measurement noise.
    pub noise_seed: u64,
}

impl Default for SimConfig {
    fn default() -> Self {
        SimConfig {
            h: 0.1,
            substeps: 10,
            nu0: [0.0; 6],
            eta0: [0.0; 6],
            noise_nu: [0.0; 6],
            noise_eta: [0.0; 6],
            noise_seed: 0,
        }
    }
}

/// Smallest |cos θ| before the Euler-angle kinematics counts as singular.
const COS_THETA_MIN: f64 = 1e-6;

impl SimConfig {
    /// Checks the configuration; errors name the field.
    pub fn validate(&self) -> Result<(), SimError> {
        if !(self.h.is_finite() && self.h > 0.0) {
            return Err(SimError::InvalidParameter {
                name: "h".into(),
                value: self.h,
                requirement: "a positive finite sample time in s",
            });
        }
        if self.substeps == 0 {
            return Err(SimError::InvalidParameter {
                name: "substeps".into(),
                value: 0.0,
                requirement: "at least 1",
            });
        }
        finite("nu0", self.nu0.iter())?;
        finite("eta0", self.eta0.iter())?;
        if self.eta0[4].cos().abs() < COS_THETA_MIN {
            return Err(SimError::InvalidParameter {
                name: "eta0[theta]".into(),
                value: self.eta0[4],
                requirement: "away from ±π/2, where the Euler-angle kinematics is singular",
            });
        }
        for d in Dof::ALL {
            let i = d.index();
            non_negative(
                format!("noise_nu[{}]", d.velocity_symbol()),
                self.noise_nu[i],
                false,
            )?;
            non_negative(format!("noise_eta[{}]", d.name()), self.noise_eta[i], false)?;
        }
        Ok(())
    }
}

/// ν_c = [Rᵀ(Θ) V_c; 0₃] for the attitude in `eta`.
fn body_current(eta: &Vector6<f64>, v_ned: &Vector3<f64>) -> Vector6<f64> {
    let v = rotation(eta[3], eta[4], eta[5]).transpose() * v_ned;
    Vector6::new(v.x, v.y, v.z, 0.0, 0.0, 0.0)
}

/// ẋ = f(x, u) written into `dx`, as [`rk4_step`] takes it.
pub(crate) trait Rhs: FnMut(&[f64], &[f64], &mut [f64]) {}

impl<F: FnMut(&[f64], &[f64], &mut [f64])> Rhs for F {}

impl RovTruth {
    /// The right-hand side ẋ = f(x, u) of the truth, shared by every flight
    /// of it (open-loop [`RovTruth::simulate`], closed-loop trials):
    /// x = [ν_r (6), η (6), τ_a (6)], u = [τ shaped (6), V_c NED (3)].
    pub(crate) fn plant(&self) -> Result<impl Rhs + '_, SimError> {
        let m_inv: Matrix6<f64> =
            self.m
                .cholesky()
                .map(|c| c.inverse())
                .ok_or_else(|| SimError::InertiaNotSpd {
                    reason: "Cholesky factorization failed".into(),
                })?;
        let tether = self.tether.load();
        let acts = &self.actuators;
        let lagged: [bool; 6] = std::array::from_fn(|i| acts.lagged(i));
        Ok(move |x: &[f64], u: &[f64], dx: &mut [f64]| {
            let nu_r = Vector6::from_column_slice(&x[0..6]);
            let eta = Vector6::from_column_slice(&x[6..12]);
            let nu = nu_r + body_current(&eta, &Vector3::new(u[6], u[7], u[8]));
            let mut tau = Vector6::zeros();
            for i in 0..6 {
                if lagged[i] {
                    tau[i] = x[12 + i];
                    dx[12 + i] = (u[i] - x[12 + i]) / acts.time_constants[i];
                } else {
                    tau[i] = u[i];
                    dx[12 + i] = 0.0;
                }
            }
            let mut rhs = tau + tether
                - damping_force(&self.damping, &self.quadratic_damping, &nu_r)
                - nonlinear_damping_force(&self.cubic_damping, &self.cross_damping, &nu_r)
                - self.restoring.g(eta[3], eta[4]);
            if self.coriolis {
                rhs -= coriolis_6dof(&self.m, &nu_r) * nu_r;
            }
            let nu_dot = m_inv * rhs;
            let e_dot = eta_dot(&eta, &nu);
            dx[0..6].copy_from_slice(nu_dot.as_slice());
            dx[6..12].copy_from_slice(e_dot.as_slice());
        })
    }
}

impl RovTruth {
    /// Simulates the commanded τ (`tau_commanded`, N × 6, columns
    /// τ_X … τ_N, row k held over [t_k, t_{k+1})) from `cfg`'s initial state.
    ///
    /// The integrated state is [ν_r, η, τ_a of the lagged DOFs]; actuators
    /// start idle (τ_a(0) = 0). Row k of the record is the state at
    /// t_k = k h; ψ is not wrapped.
    pub fn simulate(
        &self,
        tau_commanded: &DMatrix<f64>,
        cfg: &SimConfig,
    ) -> Result<RovRecord, SimError> {
        self.validate()?;
        cfg.validate()?;
        let n = tau_commanded.nrows();
        if tau_commanded.ncols() != 6 || n == 0 {
            return Err(SimError::Shape {
                name: "tau_commanded".into(),
                expected: "N×6 with N ≥ 1 (columns tau_X … tau_N)".into(),
                found: tau_commanded.shape(),
            });
        }
        finite("tau_commanded", tau_commanded.iter())?;

        let mut f = self.plant()?;
        let acts = &self.actuators;
        let lagged: [bool; 6] = std::array::from_fn(|i| acts.lagged(i));

        let mut current = CurrentProcess::new(&self.current);
        let eta0 = Vector6::from(cfg.eta0);
        let nu_r0 = Vector6::from(cfg.nu0) - body_current(&eta0, &current.ned());
        let mut x = [0.0; 18];
        x[0..6].copy_from_slice(nu_r0.as_slice());
        x[6..12].copy_from_slice(&cfg.eta0);

        let mut rec = RovRecord::zeros(n, cfg.h);
        rec.tau_commanded.copy_from(tau_commanded);
        let h_int = cfg.h / cfg.substeps as f64;
        let mut u = [0.0; 9];
        for k in 0..n {
            let shaped = acts.shaped(tau_commanded, k);
            let eta = Vector6::from_column_slice(&x[6..12]);
            let v_ned = current.ned();
            let nu = Vector6::from_column_slice(&x[0..6]) + body_current(&eta, &v_ned);
            for i in 0..6 {
                rec.nu_true[(k, i)] = nu[i];
                rec.eta_true[(k, i)] = eta[i];
                rec.tau_applied[(k, i)] = if lagged[i] { x[12 + i] } else { shaped[i] };
            }
            for i in 0..3 {
                rec.current_ned[(k, i)] = v_ned[i];
            }
            if k + 1 == n {
                break;
            }
            u[0..6].copy_from_slice(&shaped);
            for _ in 0..cfg.substeps {
                u[6..9].copy_from_slice(current.ned().as_slice());
                rk4_step(&mut f, &mut x, &u, h_int);
                current.advance(h_int);
            }
            let t = (k + 1) as f64 * cfg.h;
            if !x.iter().all(|v| v.is_finite()) {
                return Err(SimError::Diverged {
                    t,
                    reason: "the state is no longer finite (unstable parameters or too coarse an internal step)",
                });
            }
            if x[10].cos().abs() < COS_THETA_MIN {
                return Err(SimError::Diverged {
                    t,
                    reason: "pitch reached ±90°, where the Euler-angle kinematics T(Θ) is singular",
                });
            }
        }

        // Measurement noise: 12 draws per sample in a fixed order, so one
        // channel's noise does not depend on another channel's setting.
        let mut rng = SplitMix64::new(cfg.noise_seed);
        rec.nu.copy_from(&rec.nu_true);
        rec.eta.copy_from(&rec.eta_true);
        for k in 0..n {
            for i in 0..6 {
                rec.nu[(k, i)] += cfg.noise_nu[i] * rng.normal();
            }
            for i in 0..6 {
                rec.eta[(k, i)] += cfg.noise_eta[i] * rng.normal();
            }
        }
        Ok(rec)
    }
}
