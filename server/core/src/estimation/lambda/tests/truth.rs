//! Known truths for the proof tests: linear M ν̇ + D ν = γ simulated with
//! fine-step RK4 under ZOH inputs, excitation and measurement noise.

use nalgebra::DMatrix;

use super::super::Experiment;
use crate::rng::SplitMix64;
use crate::signals::random_binary;
use crate::simulation::integrate::rk4_step;

/// ν at the sample instants of ν̇ = Aν + Bγ, γ held over each h, by RK4 at
/// h/`substeps`, from ν(0) = `nu0`.
pub fn simulate(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    gamma: &DMatrix<f64>,
    nu0: &[f64],
    h: f64,
    substeps: usize,
) -> DMatrix<f64> {
    let (len, n) = gamma.shape();
    let mut nu = DMatrix::zeros(len, n);
    let mut x = nu0.to_vec();
    let mut u = vec![0.0; n];
    let mut f = |x: &[f64], u: &[f64], dx: &mut [f64]| {
        for i in 0..n {
            let mut s = 0.0;
            for j in 0..n {
                s += a[(i, j)] * x[j] + b[(i, j)] * u[j];
            }
            dx[i] = s;
        }
    };
    for k in 0..len {
        for i in 0..n {
            nu[(k, i)] = x[i];
            u[i] = gamma[(k, i)];
        }
        for _ in 0..substeps {
            rk4_step(&mut f, &mut x, &u, h / substeps as f64);
        }
    }
    nu
}

/// Independent random binary signals per DOF (clock periods `clock_s[i]`,
/// amplitudes `amp[i]`, offsets `mean[i]`), from `seed`.
pub fn excitation(
    len: usize,
    h: f64,
    clock_s: &[f64],
    amp: &[f64],
    mean: &[f64],
    seed: u64,
) -> DMatrix<f64> {
    let n = amp.len();
    let mut g = DMatrix::zeros(len, n);
    for i in 0..n {
        let s = random_binary(
            clock_s[i],
            amp[i],
            mean[i],
            crate::rng::mix(seed ^ (i as u64 + 1)),
            1.0 / h,
            len as f64 * h,
        )
        .unwrap();
        for k in 0..len {
            g[(k, i)] = s[k];
        }
    }
    g
}

/// ν plus white Gaussian noise of std `sigma[i]` per column.
pub fn noisy(nu: &DMatrix<f64>, sigma: &[f64], seed: u64) -> DMatrix<f64> {
    let mut rng = SplitMix64::new(seed);
    let mut out = nu.clone();
    for i in 0..nu.ncols() {
        for k in 0..nu.nrows() {
            out[(k, i)] += sigma[i] * rng.normal();
        }
    }
    out
}

/// One simulated run.
#[allow(clippy::too_many_arguments)]
pub fn run(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    h: f64,
    len: usize,
    clock_s: &[f64],
    amp: &[f64],
    mean_gamma: &[f64],
    nu0: &[f64],
    sigma: &[f64],
    seed: u64,
) -> Experiment {
    let gamma = excitation(len, h, clock_s, amp, mean_gamma, seed);
    let clean = simulate(a, b, &gamma, nu0, h, 10);
    Experiment::new(
        h,
        noisy(&clean, sigma, crate::rng::mix(seed ^ 0xABCD)),
        gamma,
    )
}

/// max |x − y| / max |y|.
pub fn rel_err(x: &DMatrix<f64>, y: &DMatrix<f64>) -> f64 {
    (x - y).amax() / y.amax()
}
