//! Tests of N4SID against known truth systems.

mod errors;
mod identification;
mod memory;

use nalgebra::{Complex, DMatrix, DVector};

use super::model::{N4sidModel, NoiseCovariances};
use super::settings::Weighting;
use crate::rng::SplitMix64;

/// A 4th-order, 2-input, 2-output innovation model: poles 0.9 ± 0.2i, 0.7,
/// 0.5 in a non-modal basis; `d_nonzero` adds a feedthrough.
pub(super) fn truth(d_nonzero: bool) -> N4sidModel {
    let j = DMatrix::from_row_slice(
        4,
        4,
        &[
            0.9, 0.2, 0.0, 0.0, //
            -0.2, 0.9, 0.0, 0.0, //
            0.0, 0.0, 0.7, 0.0, //
            0.0, 0.0, 0.0, 0.5,
        ],
    );
    let t = DMatrix::from_row_slice(
        4,
        4,
        &[
            1.0, 0.3, 0.0, 0.2, //
            0.1, 1.0, 0.4, 0.0, //
            0.0, 0.2, 1.0, 0.3, //
            0.3, 0.0, 0.1, 1.0,
        ],
    );
    let a = &t * j * t.clone().try_inverse().unwrap();
    let b = DMatrix::from_row_slice(4, 2, &[1.0, 0.0, 0.5, 1.0, 0.0, 0.3, 0.2, -0.4]);
    let c = DMatrix::from_row_slice(2, 4, &[1.0, 0.0, 0.5, 0.0, 0.0, 1.0, 0.0, 0.7]);
    let d = if d_nonzero {
        DMatrix::from_row_slice(2, 2, &[0.2, 0.0, -0.1, 0.3])
    } else {
        DMatrix::zeros(2, 2)
    };
    let k = DMatrix::from_row_slice(4, 2, &[0.3, 0.0, 0.1, 0.2, 0.0, 0.1, 0.05, 0.0]);
    N4sidModel {
        a,
        b,
        c,
        d,
        k,
        h: 0.1,
        order: 4,
        horizon: 0,
        weighting: Weighting::Moesp,
        singular_values: Vec::new(),
        noise: NoiseCovariances {
            q: DMatrix::zeros(4, 4),
            s: DMatrix::zeros(4, 2),
            r: DMatrix::zeros(2, 2),
        },
        innovation_covariance: innovation_cov(1.0),
        state_covariance: DMatrix::zeros(4, 4),
        hankel_columns: 0,
        output_names: vec!["y0".into(), "y1".into()],
    }
}

/// Innovation covariance σ² [1 0.3; 0.3 1].
pub(super) fn innovation_cov(sigma: f64) -> DMatrix<f64> {
    DMatrix::from_row_slice(2, 2, &[1.0, 0.3, 0.3, 1.0]) * (sigma * sigma)
}

/// N samples of white unit inputs and the outputs of `sys` with innovation
/// e ~ N(0, innovation_cov(sigma)), from x0.
pub(super) fn simulate(
    sys: &N4sidModel,
    n: usize,
    seed: u64,
    sigma: f64,
    x0: &DVector<f64>,
) -> (DMatrix<f64>, DMatrix<f64>) {
    let mut rng = SplitMix64::new(seed);
    let chol = innovation_cov(1.0).cholesky().unwrap().l() * sigma;
    let u = DMatrix::from_fn(n, sys.inputs(), |_, _| rng.normal());
    let mut y = DMatrix::zeros(n, sys.outputs());
    let mut x = x0.clone();
    for t in 0..n {
        let e = &chol * DVector::from_fn(sys.outputs(), |_, _| rng.normal());
        let ut = u.row(t).transpose();
        let yt = &sys.c * &x + &sys.d * &ut + &e;
        y.row_mut(t).copy_from(&yt.transpose());
        x = &sys.a * &x + &sys.b * &ut + &sys.k * e;
    }
    (u, y)
}

/// Largest distance between the eigenvalues of two models, matched greedily.
pub(super) fn eigen_error(a: &[Complex<f64>], b: &[Complex<f64>]) -> f64 {
    assert_eq!(a.len(), b.len());
    let mut left: Vec<Complex<f64>> = b.to_vec();
    let mut worst: f64 = 0.0;
    for z in a {
        let (k, d) = left
            .iter()
            .enumerate()
            .map(|(k, w)| (k, (z - w).norm()))
            .min_by(|x, y| x.1.total_cmp(&y.1))
            .unwrap();
        worst = worst.max(d);
        left.remove(k);
    }
    worst
}

/// Largest Markov-parameter difference relative to the largest one.
pub(super) fn markov_error(a: &N4sidModel, b: &N4sidModel, count: usize) -> f64 {
    let ma = a.markov_parameters(count);
    let mb = b.markov_parameters(count);
    let scale = mb.iter().map(|m| m.amax()).fold(0.0, f64::max);
    ma.iter()
        .zip(&mb)
        .map(|(x, y)| (x - y).amax())
        .fold(0.0, f64::max)
        / scale
}

/// Noise-model Markov parameters C Aᵏ K (basis-free).
pub(super) fn noise_markov_error(a: &N4sidModel, b: &N4sidModel, count: usize) -> f64 {
    let seq = |s: &N4sidModel| {
        let mut ak = s.k.clone();
        (0..count)
            .map(|_| {
                let m = &s.c * &ak;
                ak = &s.a * &ak;
                m
            })
            .collect::<Vec<_>>()
    };
    let (ma, mb) = (seq(a), seq(b));
    let scale = mb.iter().map(|m| m.amax()).fold(0.0, f64::max);
    ma.iter()
        .zip(&mb)
        .map(|(x, y)| (x - y).amax())
        .fold(0.0, f64::max)
        / scale
}
