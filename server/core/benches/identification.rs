//! λ-filter identification speed over a whole LPV campaign.
//!
//! Data: a 6-DOF ROV-like truth (SPD M with surge–pitch and sway–roll–yaw
//! coupling, D̄ growing with forward speed) at 7 grid speeds, 3 runs × 600 s
//! at 10 Hz per grid point (6,000 samples per run, 126,000 in all), random
//! binary excitation in every DOF and white noise on ν; simulated exactly
//! (ZOH) outside the timed region.
//!
//! Cases:
//! - `campaign_coupled`: [`identify_lpv`] with every entry of A and B free
//!   (72 parameters per grid point), robust covariance and delta-method σ;
//! - `campaign_diagonal`: the same with [`Structure::Diagonal`];
//! - `propose_coupling_grid_point`: the partial-coherence mask of one grid
//!   point's 3 runs.
//!
//! `cargo bench -p seatrial-core --bench identification`.

use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::{DMatrix, DVector};
use seatrial_core::estimation::NoProgress;
use seatrial_core::estimation::lambda::{
    CouplingMask, Experiment, LambdaSettings, Prior, Structure, ZohModel, identify_lpv,
    propose_coupling,
};
use seatrial_core::planning::Dof;
use seatrial_core::rng::{SplitMix64, mix};
use seatrial_core::signals::random_binary;

const H: f64 = 0.1;
const RUN_S: f64 = 600.0;
const RUNS: usize = 3;
const GRID: usize = 7;

fn mass() -> DMatrix<f64> {
    let mut m = DMatrix::from_diagonal(&DVector::from_vec(vec![
        4000.0, 5000.0, 6000.0, 1500.0, 1800.0, 1200.0,
    ]));
    for &(i, j, v) in &[(0, 4, 600.0), (1, 3, -600.0), (1, 5, 300.0), (3, 5, 100.0)] {
        m[(i, j)] = v;
        m[(j, i)] = v;
    }
    m
}

fn damping(u: f64) -> DMatrix<f64> {
    let mut d = DMatrix::from_diagonal(&DVector::from_vec(vec![
        800.0 + 600.0 * u,
        1200.0 + 900.0 * u,
        1500.0 + 1000.0 * u,
        600.0 + 200.0 * u,
        700.0 + 300.0 * u,
        500.0 + 400.0 * u,
    ]));
    for &(i, j, v) in &[
        (0, 4, 100.0 + 80.0 * u),
        (4, 0, 100.0 + 40.0 * u),
        (1, 5, 200.0 + 300.0 * u),
        (5, 1, 100.0 - 150.0 * u),
    ] {
        d[(i, j)] = v;
    }
    d
}

fn campaign() -> Vec<(f64, Vec<Experiment>)> {
    let m = mass();
    let binv = m.clone().try_inverse().unwrap();
    let amp = [400.0, 500.0, 500.0, 150.0, 150.0, 150.0];
    let sigma = [0.01, 0.01, 0.01, 0.004, 0.004, 0.004];
    (1..=GRID)
        .map(|g| {
            let speed = 0.257 * g as f64;
            let d = damping(speed);
            let a = -(&binv * &d);
            let model = ZohModel::new(&a, &binv, H).unwrap();
            let runs = (0..RUNS)
                .map(|r| {
                    let seed = mix((g * 100 + r) as u64);
                    let n = (RUN_S / H) as usize;
                    let mut gamma = DMatrix::zeros(n, 6);
                    for j in 0..6 {
                        let s = random_binary(
                            2.0,
                            amp[j],
                            d[(j, 0)] * speed,
                            seed ^ j as u64,
                            1.0 / H,
                            RUN_S,
                        )
                        .unwrap();
                        gamma.column_mut(j).copy_from_slice(&s);
                    }
                    let mut nu0 = DMatrix::zeros(n, 6);
                    nu0[(0, 0)] = speed;
                    let mut nu = model.simulate(&nu0, &gamma).unwrap();
                    let mut rng = SplitMix64::new(seed ^ 0xFFFF);
                    for j in 0..6 {
                        for k in 0..n {
                            nu[(k, j)] += sigma[j] * rng.normal();
                        }
                    }
                    Experiment::new(H, nu, gamma)
                })
                .collect();
            (speed, runs)
        })
        .collect()
}

fn settings(structure: Structure) -> LambdaSettings {
    let m = mass();
    LambdaSettings::new(
        Dof::ALL.to_vec(),
        1.0,
        structure,
        Prior::weak(
            DMatrix::from_diagonal(&(m.diagonal() * 0.6)),
            DMatrix::from_diagonal(&(damping(0.0).diagonal() * 0.5)),
        ),
    )
}

fn bench(c: &mut Criterion) {
    let points = campaign();
    let coupled = settings(Structure::Coupled(CouplingMask::full(6)));
    let diagonal = settings(Structure::Diagonal);
    let mut g = c.benchmark_group("identification");
    g.sample_size(20)
        .warm_up_time(Duration::from_secs(2))
        .measurement_time(Duration::from_secs(8));
    g.bench_function("campaign_coupled", |b| {
        b.iter(|| identify_lpv(black_box(&points), &coupled, &mut NoProgress).unwrap())
    });
    g.bench_function("campaign_diagonal", |b| {
        b.iter(|| identify_lpv(black_box(&points), &diagonal, &mut NoProgress).unwrap())
    });
    g.bench_function("propose_coupling_grid_point", |b| {
        b.iter(|| propose_coupling(black_box(&points[3].1), 0.1).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
