//! A small 6-DOF truth for the proof: M ν̇ + C(ν)ν + D(ν_r)ν_r + g(η) = τ_a
//! with η̇ = J(η)ν, and the effects a baseline may leave out. Temporary
//! stand-in until `simulation::rov` lands on main.

use nalgebra::DMatrix;

use crate::discrepancy::candidates::coriolis_force;
use crate::discrepancy::data::{Record, Restoring};
use crate::planning::{Dof, VesselProfile};
use crate::rng::SplitMix64;
use crate::simulation::integrate::rk4_step;

/// The true vessel and its concealed effects.
#[derive(Debug, Clone)]
pub struct Truth {
    pub m: [f64; 6],
    pub d: [f64; 6],
    pub restoring: Restoring,
    pub quad: [f64; 6],
    pub coriolis: bool,
    pub constant: [f64; 6],
    /// NED current (V_N, V_E), m/s.
    pub current: Option<[f64; 2]>,
    pub lag: [Option<f64>; 6],
    pub delay: [usize; 6],
    pub saturation: [Option<f64>; 6],
    pub noise_nu: f64,
}

impl Truth {
    /// A Surveyor-sized ROV from the vessel's limits: full force gives the
    /// velocity limit (D_i = F_i/V_i) and M_i = T_i·D_i.
    pub fn from_profile(p: &VesselProfile) -> Truth {
        let mut m = [0.0; 6];
        let mut d = [0.0; 6];
        for dof in Dof::ALL {
            let l = p.limit(dof);
            d[dof.index()] = l.max_force / l.max_velocity;
            m[dof.index()] = l.time_constant_s * d[dof.index()];
        }
        Truth {
            m,
            d,
            restoring: Restoring {
                w_minus_b: 500.0,
                zg_w_minus_zb_b: 20_000.0,
                tether_pitch_moment: 0.0,
            },
            quad: [0.0; 6],
            coriolis: false,
            constant: [0.0; 6],
            current: None,
            lag: [None; 6],
            delay: [0; 6],
            saturation: [None; 6],
            noise_nu: 1e-3,
        }
    }

    fn deriv(&self, x: &[f64], u: &[f64], dx: &mut [f64]) {
        let nu = &x[0..6];
        let eta = &x[6..12];
        let (sphi, cphi) = eta[3].sin_cos();
        let (sth, cth) = eta[4].sin_cos();
        let (spsi, cpsi) = eta[5].sin_cos();
        let mut nu_r = nu.to_vec();
        if let Some([vn, ve]) = self.current {
            nu_r[0] -= vn * cpsi + ve * spsi;
            nu_r[1] -= -vn * spsi + ve * cpsi;
        }
        let g = self
            .restoring
            .g(&[eta[0], eta[1], eta[2], eta[3], eta[4], eta[5]]);
        let cor = if self.coriolis {
            let mm = DMatrix::from_diagonal(&nalgebra::DVector::from_row_slice(&self.m));
            coriolis_force(&Dof::ALL, &mm, nu)
        } else {
            vec![0.0; 6]
        };
        for i in 0..6 {
            let tau_a = if self.lag[i].is_some() {
                x[12 + i]
            } else {
                u[i]
            };
            let f = tau_a
                - g[i]
                - self.d[i] * nu_r[i]
                - self.quad[i] * nu[i].abs() * nu[i]
                - cor[i]
                - self.constant[i];
            dx[i] = f / self.m[i];
            dx[12 + i] = match self.lag[i] {
                Some(t) => (u[i] - x[12 + i]) / t,
                None => 0.0,
            };
        }
        // η̇ = J(η)ν: R(φ,θ,ψ)·[u v w], T(φ,θ)·[p q r].
        let (u_, v_, w_, p_, q_, r_) = (nu[0], nu[1], nu[2], nu[3], nu[4], nu[5]);
        dx[6] = cpsi * cth * u_
            + (-spsi * cphi + cpsi * sth * sphi) * v_
            + (spsi * sphi + cpsi * cphi * sth) * w_;
        dx[7] = spsi * cth * u_
            + (cpsi * cphi + sphi * sth * spsi) * v_
            + (-cpsi * sphi + sth * spsi * cphi) * w_;
        dx[8] = -sth * u_ + cth * sphi * v_ + cth * cphi * w_;
        dx[9] = p_ + sphi * sth / cth * q_ + cphi * sth / cth * r_;
        dx[10] = cphi * q_ - sphi * r_;
        dx[11] = sphi / cth * q_ + cphi / cth * r_;
    }

    /// Runs the truth on commands `tau` (N × 6, held over each step h);
    /// with `noise`, ν and η get measurement noise. Heading starts at `psi0`.
    pub fn run(
        &self,
        name: &str,
        tau: &DMatrix<f64>,
        h: f64,
        psi0: f64,
        seed: Option<u64>,
    ) -> Record {
        let n = tau.nrows();
        // The applied command after delay and saturation, still held.
        let applied = DMatrix::from_fn(n, 6, |k, i| {
            let kk = k.saturating_sub(self.delay[i]);
            let v = tau[(kk, i)];
            match self.saturation[i] {
                Some(l) => v.clamp(-l, l),
                None => v,
            }
        });
        let mut x = vec![0.0; 18];
        x[11] = psi0;
        // Start at rest on the first command's lag state.
        for i in 0..6 {
            x[12 + i] = applied[(0, i)];
        }
        let mut nu = DMatrix::zeros(n, 6);
        let mut eta = DMatrix::zeros(n, 6);
        let sub = 2;
        let mut f = |x: &[f64], u: &[f64], dx: &mut [f64]| self.deriv(x, u, dx);
        for k in 0..n {
            for i in 0..6 {
                nu[(k, i)] = x[i];
                eta[(k, i)] = x[6 + i];
            }
            let u: Vec<f64> = (0..6).map(|i| applied[(k, i)]).collect();
            for _ in 0..sub {
                rk4_step(&mut f, &mut x, &u, h / sub as f64);
            }
        }
        if let Some(s) = seed {
            let mut r = SplitMix64::new(s);
            nu.iter_mut().for_each(|v| *v += self.noise_nu * r.normal());
            eta.iter_mut().for_each(|v| *v += 1e-3 * r.normal());
        }
        Record {
            name: name.into(),
            h,
            tau: tau.clone(),
            nu,
            eta,
        }
    }
}

/// Random-level excitation: levels uniform in offset ± amplitude, held for a
/// clock period (amplitude variety separates ν- from τ-dependent effects).
pub fn random_levels(
    n: usize,
    h: f64,
    clock_s: f64,
    offset: f64,
    amplitude: f64,
    rng: &mut SplitMix64,
) -> Vec<f64> {
    let per = (clock_s / h).round().max(1.0) as usize;
    let mut out = Vec::with_capacity(n);
    let mut level = 0.0;
    for k in 0..n {
        if k % per == 0 {
            level = offset + amplitude * rng.uniform_in(-1.0, 1.0);
        }
        out.push(level);
    }
    out
}

/// Commands for run `run` of a campaign: each DOF excited with random
/// levels at half its force limit, surge offset stepping with the run (the
/// forward-speed grid) and a yaw offset that turns the vessel through
/// several headings.
pub fn commands(p: &VesselProfile, n: usize, h: f64, run: usize, seed: u64) -> DMatrix<f64> {
    let mut rng = SplitMix64::new(crate::rng::mix(seed ^ (run as u64 * 7919)));
    let mut tau = DMatrix::zeros(n, 6);
    let surge_offsets = [0.15, 0.35, 0.55, 0.25, 0.45];
    let yaw_offsets = [0.12, -0.1, 0.08, -0.12, 0.1];
    for dof in Dof::ALL {
        let l = p.limit(dof);
        let f = l.max_force;
        let (offset, amp) = match dof {
            Dof::Surge => (surge_offsets[run % 5] * f, 0.35 * f),
            Dof::Yaw => (yaw_offsets[run % 5] * f, 0.35 * f),
            _ => (0.0, 0.45 * f),
        };
        let clock = (0.8 * l.time_constant_s).max(2.0 * h);
        let x = random_levels(n, h, clock, offset, amp, &mut rng);
        for k in 0..n {
            tau[(k, dof.index())] = x[k];
        }
    }
    tau
}
