//! Parallel augmented EKF benchmarks (criterion medians).
//!
//! - `ekf/supply_vessel_si1_si3`: the staged identification of the supply
//!   vessel (Fossen et al. 1995): SI1 → SI2 → SI3, N = 2 runs of 600 samples
//!   per stage, two sweeps.
//! - `ekf/six_dof_48_params`: one run of ν ∈ ℝ⁶ with a full unknown 6 × 6 A,
//!   diagonal B and a constant bias c (48 parameters, augmented dimension 54),
//!   4,000 samples, ν measured — the same filter as `compare_filterpy.py` runs
//!   with filterpy's ExtendedKalmanFilter (`compare_filterpy.sh` prints both).
//!
//! With `EKF_COMPARE_OUT=path`, the 6-DOF final estimate is written there as
//! JSON for the side-by-side check.

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::DMatrix;
use seatrial_core::estimation::NoProgress;
use seatrial_core::estimation::ekf::{
    DpIdentConfig, DpStage, EkfSettings, RunData, RunModel, SI1_FREE, SI2_FREE, SI3_FREE,
    identify_dp_ship, parallel_ekf,
};
use seatrial_core::rng::SplitMix64;
use seatrial_core::simulation::dp_ship::{DpShip, TrialConfig, paper, simulate_campaign};
use std::hint::black_box;

/// Six states, 48 parameters: θ = [A (row-major, 36); b (6); c (6)].
const NX: usize = 6;
const NP: usize = 48;
const STEPS: usize = 4000;
const DT: f64 = 0.1;
const NOISE: f64 = 0.01;

/// ν(k+1) = ν + dt·(A·ν + b∘u + c) (forward Euler, the model both sides
/// implement), z = ν.
struct SixDof {
    h: DMatrix<f64>,
}

impl RunModel for SixDof {
    fn n_states(&self) -> usize {
        NX
    }
    fn n_params(&self) -> usize {
        NP
    }
    fn n_inputs(&self) -> usize {
        NX
    }
    fn measurement_matrix(&self) -> &DMatrix<f64> {
        &self.h
    }
    fn transition(
        &self,
        x: &[f64],
        u: &[f64],
        th: &[f64],
        xn: &mut [f64],
        fx: &mut DMatrix<f64>,
        ft: &mut DMatrix<f64>,
    ) {
        ft.fill(0.0);
        for i in 0..NX {
            let mut acc = 0.0;
            for j in 0..NX {
                acc += th[i * NX + j] * x[j];
                fx[(i, j)] = DT * th[i * NX + j] + if i == j { 1.0 } else { 0.0 };
                ft[(i, i * NX + j)] = DT * x[j];
            }
            acc += th[36 + i] * u[i];
            acc += th[42 + i];
            xn[i] = x[i] + DT * acc;
            ft[(i, 36 + i)] = DT * u[i];
            ft[(i, 42 + i)] = DT;
        }
    }
}

/// The data of the 6-DOF case, exactly as `compare_filterpy.py` makes them.
fn six_dof_data() -> (DMatrix<f64>, DMatrix<f64>) {
    let a = |i: usize, j: usize| {
        if i == j {
            -(0.4 + 0.1 * i as f64)
        } else {
            0.02 * (((i * 7 + j * 3) % 5) as f64 - 2.0)
        }
    };
    let mut rng = SplitMix64::new(42);
    let mut level = [1.0; NX];
    let mut u = DMatrix::zeros(STEPS, NX);
    for k in 0..STEPS {
        if k % 10 == 0 {
            for l in level.iter_mut() {
                if rng.uniform() < 0.5 {
                    *l = -*l;
                }
            }
        }
        for i in 0..NX {
            u[(k, i)] = level[i];
        }
    }
    let mut z = DMatrix::zeros(STEPS, NX);
    let mut nu = [0.0; NX];
    for k in 0..STEPS {
        for i in 0..NX {
            z[(k, i)] = nu[i] + NOISE * rng.normal();
        }
        let mut next = [0.0; NX];
        for i in 0..NX {
            let mut acc = 0.0;
            for (j, v) in nu.iter().enumerate() {
                acc += a(i, j) * v;
            }
            acc += (1.0 + 0.1 * i as f64) * u[(k, i)];
            acc += 0.01 * (i as f64 - 2.5);
            next[i] = nu[i] + DT * acc;
        }
        nu = next;
    }
    (u, z)
}

fn six_dof_settings() -> EkfSettings {
    let mut theta0 = vec![0.0; NP];
    for v in &mut theta0[36..42] {
        *v = 0.5;
    }
    EkfSettings {
        x0: vec![vec![0.0; NX]],
        theta0,
        p0_x: vec![1e-4; NX],
        p0_theta: vec![1.0; NP],
        q_x: vec![1e-8; NX],
        q_theta: vec![0.0; NP],
        r: vec![NOISE * NOISE; NX],
    }
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("ekf");
    g.sample_size(10);

    let trial = TrialConfig::supply_vessel();
    let runs = simulate_campaign(
        &DpShip::supply_vessel(),
        &trial,
        paper::SAMPLES_PER_RUN,
        2024,
    );
    let cfg = DpIdentConfig::supply_vessel(&trial);
    let data = |i: usize| RunData {
        u: &runs[i].u,
        z: &runs[i].eta,
    };
    let stages = vec![
        DpStage {
            name: "SI1".into(),
            free: SI1_FREE.to_vec(),
            runs: vec![data(0), data(1)],
        },
        DpStage {
            name: "SI2".into(),
            free: SI2_FREE.to_vec(),
            runs: vec![data(2), data(3)],
        },
        DpStage {
            name: "SI3".into(),
            free: SI3_FREE.to_vec(),
            runs: vec![data(4), data(5)],
        },
    ];
    g.bench_function("supply_vessel_si1_si3", |b| {
        b.iter(|| identify_dp_ship(black_box(&cfg), &stages, &mut NoProgress).unwrap())
    });

    let (u, z) = six_dof_data();
    let mut h = DMatrix::zeros(NX, NX);
    h.fill_with_identity();
    let model = SixDof { h };
    let settings = six_dof_settings();
    let run = [RunData { u: &u, z: &z }];
    let out = parallel_ekf(&model, &run, &settings, "6dof", &mut NoProgress).unwrap();
    if let Ok(path) = std::env::var("EKF_COMPARE_OUT") {
        let last = out.states[0].row(STEPS - 1);
        let json = serde_json::json!({
            "theta": out.theta.iter().collect::<Vec<_>>(),
            "x": last.iter().collect::<Vec<_>>(),
            "theta_cov_diag": out.theta_cov.diagonal().iter().collect::<Vec<_>>(),
        });
        std::fs::write(&path, json.to_string()).expect("write EKF_COMPARE_OUT");
    }
    g.bench_function("six_dof_48_params", |b| {
        b.iter(|| {
            parallel_ekf(&model, black_box(&run), &settings, "6dof", &mut NoProgress).unwrap()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
