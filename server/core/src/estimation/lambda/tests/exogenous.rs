//! Exogenous force terms M ν̇ + D ν + F e = γ estimated with M and D: a
//! constant load and a known slowly varying function (the shape of a
//! restoring force), simulated exactly and recovered within their reported
//! uncertainty.

use nalgebra::DMatrix;

use super::super::{Exogenous, Experiment, LambdaSettings, Prior, Structure, identify};
use super::truth::{excitation, noisy, simulate};
use crate::planning::dof::Dof;

const H: f64 = 0.1;

fn truth() -> (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>) {
    let m = DMatrix::from_row_slice(2, 2, &[400.0, 0.0, 0.0, 60.0]);
    let d = DMatrix::from_row_slice(2, 2, &[150.0, 0.0, 0.0, 40.0]);
    // F: column 0 the constant load, column 1 the coefficient of e₁.
    let f = DMatrix::from_row_slice(2, 2, &[-35.0, 0.0, 12.0, 90.0]);
    (m, d, f)
}

/// e = [1, sin(0.21 t + seed)], a slow known function like sin θ.
fn functions(len: usize, seed: u64) -> DMatrix<f64> {
    DMatrix::from_fn(len, 2, |k, j| {
        if j == 0 {
            1.0
        } else {
            0.3 * (0.21 * k as f64 * H + seed as f64).sin()
        }
    })
}

fn run(seed: u64) -> Experiment {
    let (m, d, f) = truth();
    let b = m.clone().try_inverse().unwrap();
    let a = -(&b * &d);
    let len = 3000;
    let gamma = excitation(len, H, &[2.0, 1.0], &[200.0, 30.0], &[50.0, 0.0], seed);
    let e = functions(len, seed);
    let applied = &gamma - &e * f.transpose();
    let nu = simulate(&a, &b, &applied, &[0.0, 0.0], H, 10);
    Experiment {
        h: H,
        nu: noisy(&nu, &[0.005, 0.003], seed ^ 0x55),
        gamma,
        exogenous: e,
    }
}

fn settings(pattern: DMatrix<bool>) -> LambdaSettings {
    let (m, d, _) = truth();
    let prior = Prior::weak(&m * 1.5, &d * 0.6);
    let mut s = LambdaSettings::new(
        vec![Dof::Surge, Dof::Pitch],
        0.5,
        Structure::Diagonal,
        prior,
    );
    s.exogenous = Some(Exogenous {
        names: vec!["1".into(), "e1".into()],
        pattern,
        force_std: vec![1e4, 1e4],
    });
    s
}

#[test]
fn constant_load_and_function_coefficients_are_recovered_within_their_std() {
    let (m, d, f) = truth();
    let mut worst: f64 = 0.0;
    for seed in 1..=6 {
        let runs: Vec<Experiment> = (0..3).map(|r| run(seed * 10 + r)).collect();
        let pattern = DMatrix::from_row_slice(2, 2, &[true, false, true, true]);
        let est = identify(&runs, &settings(pattern)).unwrap();
        assert_eq!(est.exogenous, vec!["1".to_string(), "e1".to_string()]);
        for (i, j) in [(0, 0), (1, 0), (1, 1)] {
            let z = (est.force[(i, j)] - f[(i, j)]) / est.std_force[(i, j)];
            worst = worst.max(z.abs());
            assert!(
                est.std_force[(i, j)] < 0.2 * f[(i, j)].abs(),
                "seed {seed}: F[{i},{j}] = {} ± {} is not determined",
                est.force[(i, j)],
                est.std_force[(i, j)]
            );
        }
        // Outside the pattern F stays exactly zero (diagonal B).
        assert_eq!(est.force[(0, 1)], 0.0);
        for i in 0..2 {
            let zm = (est.m[(i, i)] - m[(i, i)]) / est.std_m[(i, i)];
            let zd = (est.d_bar[(i, i)] - d[(i, i)]) / est.std_d_bar[(i, i)];
            worst = worst.max(zm.abs()).max(zd.abs());
        }
    }
    assert!(worst < 4.0, "largest |z| over 6 seeds: {worst:.2}");
}

#[test]
fn without_the_terms_a_constant_load_biases_the_damping() {
    // The same data fitted without e: the constant load must go somewhere,
    // so D of the loaded surge row is off by far more than its std.
    let (_, d, _) = truth();
    let runs: Vec<Experiment> = (0..3)
        .map(|r| {
            let x = run(70 + r);
            Experiment::new(x.h, x.nu, x.gamma)
        })
        .collect();
    let mut s = settings(DMatrix::from_element(2, 2, false));
    s.exogenous = None;
    let est = identify(&runs, &s).unwrap();
    let z = (est.d_bar[(0, 0)] - d[(0, 0)]) / est.std_d_bar[(0, 0)];
    assert!(z.abs() > 10.0, "z = {z:.1}");
}
