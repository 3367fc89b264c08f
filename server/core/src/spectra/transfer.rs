//! H1 transfer-function (frequency-response) estimate and its Bode helpers.

use realfft::num_complex::Complex;

use super::cross::{CrossSpectra, cross_spectra};
use super::phase::unwrap_phase;
use super::{SpectraError, WelchConfig};

/// A non-parametric frequency-response estimate `H(f)` from input `x` to
/// output `y`, on the one-sided Welch grid.
#[derive(Debug, Clone, PartialEq)]
pub struct TransferEstimate {
    /// Frequencies in Hz, `k · fs / nperseg` for `k = 0..=nperseg/2`.
    pub freqs: Vec<f64>,
    /// Complex response, one value per frequency (units of y per unit of x).
    pub values: Vec<Complex<f64>>,
}

impl TransferEstimate {
    /// `|H|` per frequency.
    pub fn magnitude(&self) -> Vec<f64> {
        self.values.iter().map(|h| h.norm()).collect()
    }

    /// `20·log10 |H|` in dB per frequency (`-inf` where `H == 0`).
    pub fn magnitude_db(&self) -> Vec<f64> {
        self.values
            .iter()
            .map(|h| 20.0 * h.norm().log10())
            .collect()
    }

    /// Wrapped phase `atan2(Im H, Re H)` in radians, in `[−π, π]`
    /// (numpy's `angle`).
    pub fn phase(&self) -> Vec<f64> {
        self.values.iter().map(|h| h.arg()).collect()
    }

    /// Unwrapped phase in radians (`numpy.unwrap(numpy.angle(H))`), starting
    /// from the DC bin's wrapped phase. For `y` delayed by `d` samples it
    /// follows `−2π f d / fs`.
    pub fn phase_unwrapped(&self) -> Vec<f64> {
        unwrap_phase(&self.phase())
    }
}

impl CrossSpectra {
    /// H1 estimate `Pxy / Pxx` (unbiased by noise on the output `y`). Bins
    /// where `Pxx == 0` (the input has no power, H undefined; scipy-style
    /// division gives NaN) are set to 0.
    pub fn h1(&self) -> TransferEstimate {
        let values = self
            .pxy
            .iter()
            .zip(&self.pxx)
            .map(|(pxy, &pxx)| {
                if pxx == 0.0 {
                    Complex::new(0.0, 0.0)
                } else {
                    pxy / pxx
                }
            })
            .collect();
        TransferEstimate {
            freqs: self.freqs.clone(),
            values,
        }
    }
}

/// H1 frequency-response estimate from input `x` to output `y`:
/// `H1 = Pxy / Pxx` with `Pxy` = `scipy.signal.csd(x, y, ...)` and `Pxx` =
/// `scipy.signal.welch(x, ...)` under the same configuration (MATLAB's
/// `tfestimate(x, y, ..., 'Estimator', 'H1')`).
///
/// # Errors
/// As [`super::cross_spectra`].
pub fn tfestimate_h1(
    x: &[f64],
    y: &[f64],
    cfg: &WelchConfig,
) -> Result<TransferEstimate, SpectraError> {
    cross_spectra(x, y, cfg).map(|s| s.h1())
}

#[cfg(test)]
mod tests {
    use std::f64::consts::PI;

    use super::super::test_support::{Gaussian, assert_rel_close, cross_fixture};
    use super::*;

    #[test]
    fn matches_scipy_fixtures() {
        let fx = cross_fixture();
        for case in &fx.cases {
            let name = &case.params.name;
            let (x, y) = (&fx.signals[&case.x], &fx.signals[&case.y]);
            let h = tfestimate_h1(x, y, &case.params.config()).unwrap();
            let re: Vec<f64> = h.values.iter().map(|v| v.re).collect();
            let im: Vec<f64> = h.values.iter().map(|v| v.im).collect();
            let scale = h.magnitude().into_iter().fold(0.0, f64::max);
            for k in 0..re.len() {
                let err = (re[k] - case.h1_re[k]).hypot(im[k] - case.h1_im[k]);
                assert!(err <= 1e-9 * scale, "{name} h1[{k}] err {err:e}");
            }
            assert_rel_close(
                &h.magnitude_db(),
                &case.h1_mag_db,
                1e-9,
                &format!("{name} dB"),
            );
            assert_rel_close(
                &h.phase_unwrapped(),
                &case.h1_phase_unwrapped,
                1e-9,
                &format!("{name} unwrapped phase"),
            );
        }
    }

    #[test]
    fn pure_gain_without_noise_is_exact() {
        let g = -0.37; // negative gain: phase ±π
        let x = Gaussian::new(8).vec(5000, 1.0);
        for gain in [2.5, g] {
            let y: Vec<f64> = x.iter().map(|v| gain * v).collect();
            let h = tfestimate_h1(&x, &y, &WelchConfig::hann(10.0, 256)).unwrap();
            for v in &h.values {
                assert!((v.re - gain).abs() < 1e-12 * gain.abs(), "{v}");
                assert!(v.im.abs() < 1e-12 * gain.abs(), "{v}");
            }
            let db = 20.0 * gain.abs().log10();
            assert!(h.magnitude_db().iter().all(|d| (d - db).abs() < 1e-10));
            if gain > 0.0 {
                assert!(h.phase().iter().all(|p| p.abs() < 1e-12));
                assert!(h.phase_unwrapped().iter().all(|p| p.abs() < 1e-12));
            }
        }
    }

    #[test]
    fn pure_delay_has_linear_phase() {
        let (fs, d) = (4.0, 3usize);
        let n = 1 << 16;
        let w = Gaussian::new(99).vec(n + d, 1.0);
        let x = &w[d..];
        let y = &w[..n]; // y[i] = x[i − d]
        let h = tfestimate_h1(x, y, &WelchConfig::hann(fs, 256)).unwrap();
        let ph = h.phase_unwrapped();
        for (k, (f, p)) in h.freqs.iter().zip(&ph).enumerate() {
            let truth = -2.0 * PI * f * d as f64 / fs;
            assert!((p - truth).abs() < 0.03, "bin {k}: {p} vs {truth}");
        }
        // Magnitude ≈ 1 less the window-overlap loss Σ w[n]w[n−d] / Σ w².
        let mag = h.magnitude();
        let inner = &mag[1..mag.len() - 1];
        let avg = inner.iter().sum::<f64>() / inner.len() as f64;
        assert!((avg - 1.0).abs() < 0.02, "mean |H| {avg}");
        // The last bin reaches −3π: unwrapping went through several 2π wraps.
        assert!((ph.last().unwrap() + 3.0 * PI).abs() < 0.03);
    }

    #[test]
    fn first_order_filter_with_output_noise() {
        // H1 is unbiased by output noise: compare with b / (1 − a e^{−jω})
        // within 5 standard deviations of the estimate: its relative
        // variance is (1 − γ²) / (2 K γ²) in magnitude and as much in phase
        // for K averaged segments (Bendat & Piersol), plus 1 % for the
        // window's resolution bias.
        let (a, b, sn) = (0.6, 0.4, 0.3);
        let mut rng = Gaussian::new(5);
        let x = rng.vec(1 << 17, 1.0);
        let mut s = 0.0;
        let y: Vec<f64> = x
            .iter()
            .map(|v| {
                s = a * s + b * v;
                s + sn * rng.sample()
            })
            .collect();
        let cfg = WelchConfig::hann(1.0, 256);
        let k_avg = cfg.n_segments(x.len()) as f64;
        let h = tfestimate_h1(&x, &y, &cfg).unwrap();
        for (f, v) in h.freqs.iter().zip(&h.values) {
            let z = Complex::from_polar(1.0, -2.0 * PI * f);
            let truth = b / (1.0 - a * z);
            let h2 = truth.norm_sqr();
            let gamma2 = h2 / (h2 + sn * sn);
            let rel_sd = ((1.0 - gamma2) / (k_avg * gamma2)).sqrt();
            let tol = 5.0 * rel_sd + 0.01;
            assert!(
                (v - truth).norm() < tol * truth.norm(),
                "f {f}: {v} vs {truth} (tol {tol})"
            );
        }
    }

    #[test]
    fn zero_input_power_gives_zero_not_nan() {
        let x = vec![1.0; 64]; // constant, removed by the constant detrend
        let y: Vec<f64> = (0..64).map(|i| (i as f64).cos()).collect();
        let h = tfestimate_h1(&x, &y, &WelchConfig::hann(1.0, 16)).unwrap();
        assert!(h.values.iter().all(|v| *v == Complex::new(0.0, 0.0)));
        assert!(h.magnitude_db().iter().all(|d| *d == f64::NEG_INFINITY));
    }

    #[test]
    fn errors_propagate() {
        let e = tfestimate_h1(&[1.0; 10], &[1.0; 9], &WelchConfig::hann(1.0, 4)).unwrap_err();
        assert_eq!(e.field(), "y");
        let e = tfestimate_h1(&[1.0; 10], &[1.0; 10], &WelchConfig::hann(-2.0, 4)).unwrap_err();
        assert_eq!(e.field(), "fs");
    }
}
