//! The white noise of the measured velocities ν, estimated from each
//! sample against its neighbours.
//!
//! The λ regression ν_k = A_λ[λν]_k + … takes its regressor [λν]_k, the
//! filtered past of the measured ν, as exact. Its noise is a regressor
//! error (not the regressand's: the strictly causal filter keeps ν_k's own
//! noise out), and it shrinks the coefficients on ν toward zero. That
//! matters where a velocity moves little against its noise: the sway of a
//! vessel whose sway no run forces (an Otter's v_r of a few cm/s under
//! 1 cm/s of GNSS noise) carries the Munk moment into yaw, and an
//! attenuated N_v turns a course-unstable hull's heading in a free run.
//!
//! Each sample's noise is the measurement less the cubic through its four
//! neighbours, e_k = ν_k − (−ν_{k−2} + 4ν_{k−1} + 4ν_{k+1} − ν_{k+2})/6:
//! for white noise of variance σ², Var e = (1 + 34/36)σ²; the motion leaks
//! in only as h⁴ν⁗ (a manoeuvre's step in force, a kink in ν̇, moves a
//! few samples, which the median ignores). A velocity the logger already
//! smooths shows little noise here and is discounted little.

use nalgebra::DMatrix;

use super::dataset::Segment;
use crate::estimation::lambda::{LambdaSettings, RegressorNoise};
use crate::timeseries::median;

/// Least samples for a noise estimate.
const MIN_SAMPLES: usize = 50;

/// Var e_k / σ² of the neighbours' cubic for white noise: 1 + (1 + 16 + 16
/// + 1)/36.
const CUBIC_VARIANCE: f64 = 1.0 + 34.0 / 36.0;

/// The std of each output column's white noise over `segments` (same
/// columns in each): 1.4826 × the median |e_k| / √(70/36) over every
/// sample with two neighbours on each side. `None` without
/// [`MIN_SAMPLES`] such samples or with non-finite values.
pub(crate) fn velocity_noise_std(segments: &[&Segment]) -> Option<Vec<f64>> {
    let p = segments.first()?.y.ncols();
    let mut abs: Vec<Vec<f64>> = vec![Vec::new(); p];
    for s in segments.iter().filter(|s| s.y.ncols() == p) {
        for (j, col) in abs.iter_mut().enumerate() {
            let y = s.y.column(j);
            for k in 2..y.len().saturating_sub(2) {
                let cubic = (-y[k - 2] + 4.0 * (y[k - 1] + y[k + 1]) - y[k + 2]) / 6.0;
                col.push((y[k] - cubic).abs());
            }
        }
    }
    if abs.first().is_none_or(|c| c.len() < MIN_SAMPLES) {
        return None;
    }
    let sd: Vec<f64> = abs
        .iter_mut()
        .map(|c| 1.4826 * median(c) / CUBIC_VARIANCE.sqrt())
        .collect();
    sd.iter().all(|v| v.is_finite()).then_some(sd)
}

/// The settings' regressor noise with the white noise `sd` (if any) of
/// the n velocities added to its ν block, sized for its exogenous columns.
pub(crate) fn add_velocity_noise(settings: &mut LambdaSettings, sd: Option<&[f64]>) {
    let Some(sd) = sd else {
        return;
    };
    let q = settings.exogenous.as_ref().map_or(0, |x| x.names.len());
    let p = 2 * settings.dofs.len() + q;
    settings.regressor_noise = Some(with_velocity_noise(settings.regressor_noise.take(), sd, p));
}

/// `noise` (or none) with the white noise `sd` of the n velocities added
/// to its ν block (the first n of the 2n + q regressors).
fn with_velocity_noise(noise: Option<RegressorNoise>, sd: &[f64], p: usize) -> RegressorNoise {
    let mut noise = noise.unwrap_or_else(|| RegressorNoise {
        lag0: DMatrix::zeros(p, p),
        lag1: DMatrix::zeros(p, p),
    });
    for (j, s) in sd.iter().enumerate().take(p) {
        noise.lag0[(j, j)] += s * s;
    }
    noise
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fixed, reproducible N(0, 1) sequence.
    fn gaussian(seed: u64, n: usize) -> Vec<f64> {
        let mut rng = crate::rng::SplitMix64::new(seed);
        (0..n).map(|_| rng.normal()).collect()
    }

    fn segment(y: DMatrix<f64>) -> Segment {
        Segment {
            run_id: "r".into(),
            h: 0.1,
            t0: 0.0,
            u: DMatrix::zeros(y.nrows(), 1),
            y,
        }
    }

    /// At 10 Hz: a smooth oscillation with 0.01 of white noise (σ within
    /// 3 %), a first-order response to a ±1 square wave switching every
    /// 3 s with 0.005 (within 10 %: each switch kinks ν̇ and lifts the
    /// |e| of the four samples about it, a seventh of them here), and
    /// that response noise-free (below 1 % of the noisy ones: the
    /// motion's leak).
    #[test]
    fn the_noise_of_each_velocity_is_recovered_beside_its_motion() {
        let n = 6000;
        let (z1, z2) = (gaussian(3, n), gaussian(4, n));
        let mut y = DMatrix::zeros(n, 3);
        let mut x = 0.0;
        for k in 0..n {
            let f = if (k / 30) % 2 == 0 { 1.0 } else { -1.0 };
            x += 0.1 * (0.5 * f - 0.8 * x);
            y[(k, 0)] = 0.3 * (0.08 * k as f64).sin() + 0.01 * z1[k];
            y[(k, 1)] = 0.3 * x + 0.005 * z2[k];
            y[(k, 2)] = 0.3 * x;
        }
        let s = segment(y);
        let sd = velocity_noise_std(&[&s]).unwrap();
        assert!((sd[0] / 0.01 - 1.0).abs() < 0.03, "{sd:?}");
        assert!((sd[1] / 0.005 - 1.0).abs() < 0.1, "{sd:?}");
        assert!(sd[2] < 5e-5, "{sd:?}");
        // Too few samples: no estimate.
        let short = segment(DMatrix::zeros(40, 3));
        assert!(velocity_noise_std(&[&short]).is_none());
    }

    #[test]
    fn the_velocity_block_is_added_to_the_regressor_noise() {
        let base = RegressorNoise::held_over_step(DMatrix::identity(5, 5));
        let n = with_velocity_noise(Some(base), &[0.1, 0.2], 5);
        assert!((n.lag0[(0, 0)] - 0.51).abs() < 1e-15);
        assert!((n.lag0[(1, 1)] - 0.54).abs() < 1e-15);
        assert_eq!(n.lag0[(2, 2)], 0.5);
        assert_eq!(n.lag1[(0, 0)], 0.25);
        let fresh = with_velocity_noise(None, &[0.1], 3);
        assert!((fresh.lag0[(0, 0)] - 0.01).abs() < 1e-15);
        assert_eq!(fresh.lag1, DMatrix::zeros(3, 3));
    }
}
