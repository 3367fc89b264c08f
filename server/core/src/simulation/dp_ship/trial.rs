//! Truth simulation of one DP sea trial: the momentum-form ship of
//! [`super::model`] driven by thruster commands, a slowly varying bias b_h
//! (seeded random walk, eq. 37) and Gaussian noise on the measured position
//! and heading (eq. 44–45).

use nalgebra::{DMatrix, Vector3};

use super::manoeuvres::{Manoeuvre, manoeuvre_inputs};
use super::model::{DpShip, rotation};
use super::paper;
use crate::rng::{SplitMix64, mix};
use crate::simulation::integrate::rk4_step;

/// Disturbance, noise and timing of a simulated trial (units of the ship
/// model; Bis for the supply vessel).
#[derive(Debug, Clone, PartialEq)]
pub struct TrialConfig {
    /// Sample time h.
    pub h: f64,
    /// RK4 steps per sample of the truth (inputs and bias held over a sample).
    pub substeps: usize,
    /// Standard deviation of the initial bias b_h(0), per DOF.
    pub bias_initial_std: [f64; 3],
    /// Standard deviation of the bias random-walk step per sample, per DOF.
    pub bias_walk_std: [f64; 3],
    /// Standard deviation of the measured x and y.
    pub position_noise_std: f64,
    /// Standard deviation of the measured heading ψ (rad).
    pub heading_noise_std: f64,
}

impl TrialConfig {
    /// The supply vessel's trials in Bis units: 1 Hz logging
    /// ([`paper::sample_time_bis`]), DGPS-class position noise of 1 m and a
    /// gyro compass of 0.2°, and a bias of the order of a few percent of full
    /// thrust: ≈ 3·10⁻⁴·m·g ≈ 12 kN in surge and sway, 5·10⁻⁵·m·g·L in yaw,
    /// wandering by a quarter of that over a 600-sample run.
    pub fn supply_vessel() -> Self {
        TrialConfig {
            h: paper::sample_time_bis(),
            substeps: 8,
            bias_initial_std: [3e-4, 3e-4, 5e-5],
            bias_walk_std: [3e-6, 3e-6, 6e-7],
            position_noise_std: 1.0 / paper::LENGTH_M,
            heading_noise_std: 0.2f64.to_radians(),
        }
    }
}

/// One simulated run, one row per sample k (time k·h).
#[derive(Debug, Clone, PartialEq)]
pub struct DpRun {
    /// Which manoeuvre this run flies.
    pub manoeuvre: Manoeuvre,
    /// Sample times.
    pub t: Vec<f64>,
    /// Inputs u (N × r: thruster commands, or τ for a vessel that logs
    /// forces), held from sample k to k + 1.
    pub u: DMatrix<f64>,
    /// Measured η = [x, y, ψ] with noise (N × 3).
    pub eta: DMatrix<f64>,
    /// True η (N × 3).
    pub eta_true: DMatrix<f64>,
    /// True body velocities ν = [u, v, r] (N × 3).
    pub nu: DMatrix<f64>,
    /// True bias b_h (N × 3).
    pub bias: DMatrix<f64>,
}

/// Simulates `ship` from rest at pose `eta0` under the inputs `u` (N × r,
/// one column per column of the ship's T).
pub fn simulate_trial(
    ship: &DpShip,
    manoeuvre: Manoeuvre,
    u: &DMatrix<f64>,
    eta0: [f64; 3],
    cfg: &TrialConfig,
    seed: u64,
) -> DpRun {
    let r = ship.k.len();
    assert_eq!(u.ncols(), r, "u must have one column per column of T");
    let n = u.nrows();
    let m_inv = ship.m_inv();
    let mut rng = SplitMix64::new(seed);
    let mut b = Vector3::from_fn(|i, _| cfg.bias_initial_std[i] * rng.normal());
    // State [h; η], inputs [u; b_h] held over a sample.
    let mut x = [0.0, 0.0, 0.0, eta0[0], eta0[1], eta0[2]];
    let mut f = |s: &[f64], w: &[f64], dx: &mut [f64]| {
        let h = Vector3::new(s[0], s[1], s[2]);
        let bias = Vector3::new(w[r], w[r + 1], w[r + 2]);
        let hd = ship.h_dot(&m_inv, &h, &w[..r], &bias);
        let eta_dot = rotation(s[5]) * (m_inv * h);
        dx[..3].copy_from_slice(hd.as_slice());
        dx[3..].copy_from_slice(eta_dot.as_slice());
    };
    let mut run = DpRun {
        manoeuvre,
        t: (0..n).map(|k| k as f64 * cfg.h).collect(),
        u: u.clone(),
        eta: DMatrix::zeros(n, 3),
        eta_true: DMatrix::zeros(n, 3),
        nu: DMatrix::zeros(n, 3),
        bias: DMatrix::zeros(n, 3),
    };
    let noise = [
        cfg.position_noise_std,
        cfg.position_noise_std,
        cfg.heading_noise_std,
    ];
    let dt = cfg.h / cfg.substeps.max(1) as f64;
    let mut w = vec![0.0; r + 3];
    for k in 0..n {
        let nu = m_inv * Vector3::new(x[0], x[1], x[2]);
        for j in 0..3 {
            run.eta_true[(k, j)] = x[3 + j];
            run.eta[(k, j)] = x[3 + j] + noise[j] * rng.normal();
            run.nu[(k, j)] = nu[j];
            run.bias[(k, j)] = b[j];
        }
        for j in 0..r {
            w[j] = u[(k, j)];
        }
        w[r..].copy_from_slice(b.as_slice());
        for _ in 0..cfg.substeps.max(1) {
            rk4_step(&mut f, &mut x, &w, dt);
        }
        for j in 0..3 {
            b[j] += cfg.bias_walk_std[j] * rng.normal();
        }
    }
    run
}

/// The six manoeuvres of sec. 4 (two per stage, SI1, SI1, SI2, SI2, SI3,
/// SI3) of `n` samples each, each run with its own excitation, bias and
/// noise drawn from `seed`.
pub fn simulate_campaign(ship: &DpShip, cfg: &TrialConfig, n: usize, seed: u64) -> Vec<DpRun> {
    let mut runs = Vec::with_capacity(6);
    for (s, kind) in Manoeuvre::ALL.iter().enumerate() {
        for rep in 0..2u64 {
            let k = 2 * s as u64 + rep;
            let u = manoeuvre_inputs(*kind, n, mix(seed ^ (2 * k + 1)));
            let eta0 = [0.0, 0.0, kind.initial_heading()];
            runs.push(simulate_trial(
                ship,
                *kind,
                &u,
                eta0,
                cfg,
                mix(seed ^ (2 * k + 2)),
            ));
        }
    }
    runs
}
