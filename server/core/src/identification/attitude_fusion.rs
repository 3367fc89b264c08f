//! The noise of the measured roll and pitch, estimated from each sample's
//! neighbours and the measured rates.
//!
//! g(η) evaluated at the measured attitude carries its noise into the λ
//! regression's γ and restoring shapes, a force the vehicle never felt
//! (see [`crate::estimation::lambda::RegressorNoise`]); its variance is
//! what the regression must discount. Each sample's noise e_k is the
//! measured φ, θ less what the neighbours predict through Fossen's
//! Euler-angle kinematics, φ̇ = p + (q sin φ + r cos φ) tan θ,
//! θ̇ = q cos φ − r sin φ: a complementary filter run forward and backward
//! (crossover [`CROSSOVER_S`]), each one step short of sample k, so the
//! estimate holds e_k in full and none of it in the prediction. An
//! attitude the INS already smooths shows little noise here and is
//! discounted little.

use nalgebra::DMatrix;

use super::attitude_loop::euler_rates;
use super::dataset::Segment;
use crate::timeseries::median;

/// The complementary filters' crossover T_c (s): the attitude below
/// 1/T_c rad/s, the integrated rates above (T_c = σ_φ/σ_p balances the two
/// noises for an INS-grade 2 mrad and 2 mrad/s).
pub(crate) const CROSSOVER_S: f64 = 1.0;

/// One-step predictions of (φ, θ) at every sample from the filter run
/// forward in time (`forward`) or backward: the filtered attitude one
/// sample before, moved over the step by the rates' trapezoid mean. The
/// first sample in that direction is its own measurement.
fn predictions(eta: &DMatrix<f64>, nu: &DMatrix<f64>, h: f64, forward: bool) -> DMatrix<f64> {
    let rows = eta.nrows();
    let gain = (h / CROSSOVER_S).min(1.0);
    let order: Vec<usize> = if forward {
        (0..rows).collect()
    } else {
        (0..rows).rev().collect()
    };
    let sign = if forward { 1.0 } else { -1.0 };
    let mut pred = DMatrix::zeros(rows, 2);
    let mut filtered = [eta[(order[0], 3)], eta[(order[0], 4)]];
    pred[(order[0], 0)] = filtered[0];
    pred[(order[0], 1)] = filtered[1];
    for w in order.windows(2) {
        let (from, to) = (w[0], w[1]);
        let rate =
            |k: usize| euler_rates(filtered[0], filtered[1], nu[(k, 3)], nu[(k, 4)], nu[(k, 5)]);
        let (a, b) = (rate(from), rate(to));
        let next = [
            filtered[0] + sign * h * 0.5 * (a.0 + b.0),
            filtered[1] + sign * h * 0.5 * (a.1 + b.1),
        ];
        for j in 0..2 {
            let measured = eta[(to, 3 + j)];
            pred[(to, j)] = next[j];
            filtered[j] = if next[j].is_finite() && measured.is_finite() {
                next[j] + gain * (measured - next[j])
            } else {
                measured
            };
        }
    }
    pred
}

/// The noise e_k of the measured φ and θ (N × 2, rad) of η (N × 6,
/// [x y z φ θ ψ]) with the rates `nu` (N × 6, [u v w p q r]) sampled every
/// `h` s: the measurement less the mean of the forward and backward
/// one-step predictions. `None` when the shapes do not fit, h is not
/// positive or fewer than three samples.
pub(crate) fn attitude_noise(
    eta: &DMatrix<f64>,
    nu: &DMatrix<f64>,
    h: f64,
) -> Option<DMatrix<f64>> {
    let rows = eta.nrows();
    if rows < 3
        || eta.ncols() != 6
        || nu.ncols() != 6
        || nu.nrows() != rows
        || h.is_nan()
        || h <= 0.0
    {
        return None;
    }
    let f = predictions(eta, nu, h, true);
    let b = predictions(eta, nu, h, false);
    Some(DMatrix::from_fn(rows, 2, |k, j| {
        let e = eta[(k, 3 + j)] - 0.5 * (f[(k, j)] + b[(k, j)]);
        if e.is_finite() { e } else { 0.0 }
    }))
}

/// Least samples for a noise estimate.
const MIN_SAMPLES: usize = 50;

/// The std (rad) of the measured φ and θ's white noise over `segments`
/// (six-DOF segments: ν = [u v w p q r] as outputs, η after the n = 6
/// force columns of the inputs): 1.4826 × the median |e_k| of every sample
/// not at a segment's end (robust to the kinks of a reference switch).
/// `None` without six-DOF segments or [`MIN_SAMPLES`] samples.
pub(crate) fn attitude_noise_std(segments: &[&Segment]) -> Option<[f64; 2]> {
    let mut abs: [Vec<f64>; 2] = [Vec::new(), Vec::new()];
    for s in segments {
        if s.y.ncols() != 6 || s.u.ncols() < 12 {
            continue;
        }
        let eta = s.u.columns(6, 6).into_owned();
        if let Some(e) = attitude_noise(&eta, &s.y, s.h) {
            for k in 1..e.nrows().saturating_sub(1) {
                for (j, v) in abs.iter_mut().enumerate() {
                    v.push(e[(k, j)].abs());
                }
            }
        }
    }
    if abs[0].len() < MIN_SAMPLES {
        return None;
    }
    let [a, b] = &mut abs;
    Some([1.4826 * median(a), 1.4826 * median(b)])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fixed, reproducible N(0, 1) sequence (Box–Muller on a 64-bit LCG).
    fn gaussian(seed: u64, n: usize) -> Vec<f64> {
        let mut state = seed;
        let mut u = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        };
        (0..n)
            .map(|_| {
                let (u1, u2) = (u(), u());
                (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
            })
            .collect()
    }

    /// Roll and pitch oscillating with their exact rates: noise-free the
    /// estimate is the trapezoid's error only; with 2 mrad of white noise on
    /// φ it recovers each sample's noise to within √(gain/2)·σ, regression
    /// slope on the true noise near 1, and it shares almost nothing with the
    /// motion.
    #[test]
    fn the_estimated_noise_is_each_samples_own() {
        let (h, n) = (0.1, 6000);
        let (a, w) = (0.05, 0.8);
        let mut clean = DMatrix::zeros(n, 6);
        let mut nu = DMatrix::zeros(n, 6);
        for k in 0..n {
            let t = k as f64 * h;
            clean[(k, 3)] = a * (w * t).sin();
            clean[(k, 4)] = 0.5 * a * (1.3 * w * t).cos();
            // level-ish attitude: p ≈ φ̇, q ≈ θ̇ (r = 0 keeps them exact)
            nu[(k, 3)] = a * w * (w * t).cos();
            nu[(k, 4)] = -0.65 * a * w * (1.3 * w * t).sin() / clean[(k, 3)].cos();
        }
        let e0 = attitude_noise(&clean, &nu, h).unwrap();
        let worst = e0.iter().skip(50).fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(worst < 2e-4, "noise-free estimate {worst}");

        let z = gaussian(7, n);
        let mut eta = clean.clone();
        for k in 0..n {
            eta[(k, 3)] += 0.002 * z[k];
        }
        let e = attitude_noise(&eta, &nu, h).unwrap();
        let (mut sxy, mut sxx, mut sr) = (0.0, 0.0, 0.0);
        for k in 50..n - 50 {
            let truth = 0.002 * z[k];
            sxy += e[(k, 0)] * truth;
            sxx += truth * truth;
            sr += (e[(k, 0)] - truth - e0[(k, 0)]).powi(2);
        }
        let slope = sxy / sxx;
        let rms = (sr / (n - 100) as f64).sqrt();
        assert!((slope - 1.0).abs() < 0.08, "slope {slope}");
        assert!(rms < 0.002 * (h / CROSSOVER_S).sqrt(), "rms {rms}");
    }

    #[test]
    fn shapes_that_do_not_fit_give_none() {
        let eta = DMatrix::from_element(3, 6, 0.1);
        assert!(attitude_noise(&eta, &DMatrix::zeros(3, 3), 0.1).is_none());
        assert!(attitude_noise(&eta, &DMatrix::zeros(3, 6), 0.0).is_none());
        assert!(attitude_noise(&eta.rows(0, 2).into_owned(), &DMatrix::zeros(2, 6), 0.1).is_none());
    }
}
