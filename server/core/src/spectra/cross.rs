//! Cross spectral density and magnitude-squared coherence
//! (scipy.signal.csd / scipy.signal.coherence), computed in one pass.

use realfft::num_complex::Complex;

use super::config::validate_inputs;
use super::engine::SegmentFft;
use super::{CrossSpectrum, SpectraError, Spectrum, WelchConfig};

/// The three Welch spectra of a pair of signals, from one pass over the
/// segments: `Pxx`, `Pyy` (as [`super::welch`]) and `Pxy` (as [`csd`]).
///
/// Use it when more than one of coherence, CSD and H1 is needed: each of
/// [`CrossSpectra::coherence`], [`CrossSpectra::csd`] and
/// [`CrossSpectra::h1`] is then free.
#[derive(Debug, Clone, PartialEq)]
pub struct CrossSpectra {
    /// Frequencies in Hz, `k · fs / nperseg` for `k = 0..=nperseg/2`.
    pub freqs: Vec<f64>,
    /// One-sided PSD of `x`.
    pub pxx: Vec<f64>,
    /// One-sided PSD of `y`.
    pub pyy: Vec<f64>,
    /// One-sided cross spectral density, `conj(X)·Y` convention.
    pub pxy: Vec<Complex<f64>>,
}

impl CrossSpectra {
    /// Magnitude-squared coherence `|Pxy|² / (Pxx · Pyy)` (scipy's
    /// expression, so values may exceed 1 by rounding). Bins where
    /// `Pxx · Pyy == 0` (then `Pxy == 0` too: scipy returns NaN) are 0.
    pub fn coherence(&self) -> Spectrum {
        let values = self
            .pxy
            .iter()
            .zip(self.pxx.iter().zip(&self.pyy))
            .map(|(pxy, (&pxx, &pyy))| {
                if pxx == 0.0 || pyy == 0.0 {
                    0.0
                } else {
                    let mag = pxy.norm();
                    mag * mag / pxx / pyy
                }
            })
            .collect();
        Spectrum {
            freqs: self.freqs.clone(),
            values,
        }
    }

    /// The cross spectral density alone.
    pub fn csd(&self) -> CrossSpectrum {
        CrossSpectrum {
            freqs: self.freqs.clone(),
            values: self.pxy.clone(),
        }
    }
}

/// Welch spectra `Pxx`, `Pyy` and `Pxy` of `x` and `y` in one pass (one FFT
/// per segment and signal).
///
/// # Errors
/// As [`super::welch`] for either signal, plus `y` when its length differs
/// from `x` (scipy would zero-pad the shorter one) or it holds a NaN/infinite
/// sample.
pub fn cross_spectra(
    x: &[f64],
    y: &[f64],
    cfg: &WelchConfig,
) -> Result<CrossSpectra, SpectraError> {
    validate_inputs(cfg, x, Some(y))?;
    let mut engine = SegmentFft::new(cfg, x.len());
    let mut sx = engine.make_output();
    let mut sy = engine.make_output();
    let nf = sx.len();
    let mut pxx = vec![0.0; nf];
    let mut pyy = vec![0.0; nf];
    let mut pxy = vec![Complex::new(0.0, 0.0); nf];
    for m in 0..engine.n_segments() {
        engine.transform(x, m, &mut sx)?;
        engine.transform(y, m, &mut sy)?;
        for k in 0..nf {
            pxx[k] += sx[k].norm_sqr();
            pyy[k] += sy[k].norm_sqr();
            pxy[k] += sx[k].conj() * sy[k];
        }
    }
    let factors = engine.density_factors(cfg.fs);
    for (k, f) in factors.into_iter().enumerate() {
        pxx[k] *= f;
        pyy[k] *= f;
        pxy[k] *= f;
    }
    Ok(CrossSpectra {
        freqs: cfg.frequencies(),
        pxx,
        pyy,
        pxy,
    })
}

/// One-sided cross spectral density of `x` and `y`, equal to
/// `scipy.signal.csd(x, y, fs, window='hann', nperseg, noverlap, detrend,
/// return_onesided=True, scaling='density', average='mean')`.
///
/// Convention (scipy's): `Pxy = c_k · mean(conj(X)·Y) / (fs Σw²)`, so for
/// `y` lagging `x` by `d` samples the phase is `−2π f d / fs`; all bins but DC
/// and (even `nperseg`) Nyquist are doubled.
///
/// # Errors
/// As [`cross_spectra`].
pub fn csd(x: &[f64], y: &[f64], cfg: &WelchConfig) -> Result<CrossSpectrum, SpectraError> {
    cross_spectra(x, y, cfg).map(|s| CrossSpectrum {
        freqs: s.freqs,
        values: s.pxy,
    })
}

/// Magnitude-squared coherence of `x` and `y`, equal to
/// `scipy.signal.coherence(x, y, fs, window='hann', nperseg, noverlap,
/// detrend)` = `|Pxy|² / (Pxx · Pyy)`, except that bins with no power
/// (scipy: NaN) are 0.
///
/// # Errors
/// As [`cross_spectra`].
pub fn coherence(x: &[f64], y: &[f64], cfg: &WelchConfig) -> Result<Spectrum, SpectraError> {
    cross_spectra(x, y, cfg).map(|s| s.coherence())
}

#[cfg(test)]
mod tests {
    use super::super::test_support::{Gaussian, assert_rel_close, cross_fixture};
    use super::super::{Detrend, welch};
    use super::*;

    #[test]
    fn matches_scipy_fixtures() {
        let fx = cross_fixture();
        assert!(fx.cases.len() >= 4);
        for case in &fx.cases {
            let name = &case.params.name;
            let (x, y) = (&fx.signals[&case.x], &fx.signals[&case.y]);
            let cfg = case.params.config();
            let s = cross_spectra(x, y, &cfg).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_rel_close(&s.freqs, &case.freqs, 1e-12, &format!("{name} freqs"));
            assert_rel_close(&s.pxx, &case.pxx, 1e-9, &format!("{name} pxx"));
            assert_rel_close(&s.pyy, &case.pyy, 1e-9, &format!("{name} pyy"));
            // Complex Pxy: compare re and im against the max |Pxy|.
            let scale = case
                .pxy_re
                .iter()
                .zip(&case.pxy_im)
                .fold(0.0f64, |m, (r, i)| m.max(r.hypot(*i)));
            for (k, p) in s.pxy.iter().enumerate() {
                let err = (p - Complex::new(case.pxy_re[k], case.pxy_im[k])).norm();
                assert!(err <= 1e-9 * scale, "{name} pxy[{k}]: {p} err {err:e}");
            }
            let c = csd(x, y, &cfg).unwrap();
            assert_eq!(c.values, s.pxy);
            let coh = coherence(x, y, &cfg).unwrap();
            assert_rel_close(
                &coh.values,
                &case.coherence,
                1e-9,
                &format!("{name} coherence"),
            );
            assert_eq!(coh, s.coherence());
        }
    }

    #[test]
    fn csd_of_x_with_itself_is_welch() {
        let x = Gaussian::new(11).vec(3001, 1.3);
        let cfg = WelchConfig::hann(4.0, 200).with_detrend(Detrend::Linear);
        let c = csd(&x, &x, &cfg).unwrap();
        let w = welch(&x, &cfg).unwrap();
        assert_eq!(c.freqs, w.freqs);
        for (p, q) in c.values.iter().zip(&w.values) {
            assert_eq!(p.im, 0.0);
            assert_eq!(p.re, *q);
        }
        let coh = coherence(&x, &x, &cfg).unwrap();
        assert!(coh.values.iter().all(|v| (v - 1.0).abs() < 1e-12));
    }

    #[test]
    fn conjugation_convention_is_scipys() {
        // y lags x by one sample: Pxy = conj(X)·Y has phase −2π f/fs.
        let fs = 10.0;
        let x = Gaussian::new(2).vec(4097, 1.0);
        let y: Vec<f64> = std::iter::once(0.0)
            .chain(x[..4096].iter().copied())
            .collect();
        let cfg = WelchConfig::hann(fs, 128);
        let c = csd(&x, &y, &cfg).unwrap();
        let swapped = csd(&y, &x, &cfg).unwrap();
        for k in 1..c.values.len() - 1 {
            let expected = -2.0 * std::f64::consts::PI * c.freqs[k] / fs;
            assert!((c.values[k].arg() - expected).abs() < 0.05, "bin {k}");
            assert!((swapped.values[k] - c.values[k].conj()).norm() < 1e-12 * c.values[k].norm());
        }
    }

    /// Tolerance for an estimated coherence around `truth` from `k`
    /// averaged segments: 5 standard deviations, `σ ≈ √2 γ (1 − γ²) / √k`
    /// (Bendat & Piersol), plus 0.01 for bias and overlap.
    fn coherence_tol(truth: f64, k: usize) -> f64 {
        5.0 * 2f64.sqrt() * truth.sqrt() * (1.0 - truth) / (k as f64).sqrt() + 0.01
    }

    #[test]
    fn coherence_of_gain_plus_noise_matches_analytic_value() {
        // y = g·x + n, white x (σx²) and n (σn²): γ² = g²σx² / (g²σx² + σn²)
        // at every frequency.
        let (g, sx, sn) = (2.0, 1.0, 2.0);
        let mut rng = Gaussian::new(77);
        let x = rng.vec(1 << 17, sx);
        let y: Vec<f64> = x.iter().map(|v| g * v + sn * rng.sample()).collect();
        let cfg = WelchConfig::hann(1.0, 256);
        let coh = coherence(&x, &y, &cfg).unwrap();
        let truth = g * g * sx * sx / (g * g * sx * sx + sn * sn); // 0.5
        let inner = &coh.values[1..coh.values.len() - 1];
        let avg = inner.iter().sum::<f64>() / inner.len() as f64;
        assert!(
            (avg - truth).abs() < 0.01,
            "mean coherence {avg} vs {truth}"
        );
        let tol = coherence_tol(truth, cfg.n_segments(x.len()));
        assert!(inner.iter().all(|v| (v - truth).abs() < tol));
    }

    #[test]
    fn coherence_of_first_order_filter_plus_noise_matches_analytic_curve() {
        // y[n] = a·s[n−1] + b·x[n] (state s = noiseless output), plus noise:
        // H(f) = b / (1 − a e^{−jω}), γ²(f) = |H|² σx² / (|H|² σx² + σn²).
        let (a, b, sx, sn) = (0.8, 0.5, 1.0, 0.7);
        let fs = 2.0;
        let mut rng = Gaussian::new(1234);
        let x = rng.vec(1 << 17, sx);
        let mut state = 0.0;
        let y: Vec<f64> = x
            .iter()
            .map(|v| {
                state = a * state + b * v;
                state + sn * rng.sample()
            })
            .collect();
        let cfg = WelchConfig::hann(fs, 512);
        let k_avg = cfg.n_segments(x.len());
        let coh = coherence(&x, &y, &cfg).unwrap();
        // Bins 0 and 1 are skipped: the constant detrend biases them.
        for (f, c) in coh.freqs.iter().zip(&coh.values).skip(2) {
            let w = 2.0 * std::f64::consts::PI * f / fs;
            let h2 = b * b / (1.0 - 2.0 * a * w.cos() + a * a);
            let truth = h2 * sx * sx / (h2 * sx * sx + sn * sn);
            let tol = coherence_tol(truth, k_avg);
            assert!((c - truth).abs() < tol, "f {f}: {c} vs {truth} (tol {tol})");
        }
    }

    #[test]
    fn zero_power_bins_give_zero_coherence_not_nan() {
        let x = vec![0.0; 64];
        let y: Vec<f64> = (0..64).map(|i| (i as f64).sin()).collect();
        let coh = coherence(&x, &y, &WelchConfig::hann(1.0, 16)).unwrap();
        assert!(coh.values.iter().all(|v| *v == 0.0));
    }

    #[test]
    fn errors_name_x_or_y() {
        let cfg = WelchConfig::hann(1.0, 8);
        let x = vec![0.5; 32];
        let e = csd(&x, &x[..31], &cfg).unwrap_err();
        assert!(matches!(e, SpectraError::InvalidInput { .. }));
        assert_eq!(e.field(), "y");
        let mut y = x.clone();
        y[20] = f64::NAN;
        match coherence(&x, &y, &cfg).unwrap_err() {
            SpectraError::NonFinite { field, index, .. } => {
                assert_eq!((field.as_str(), index), ("y", 20))
            }
            e => panic!("{e:?}"),
        }
        assert_eq!(
            cross_spectra(&x, &x, &WelchConfig::hann(1.0, 33))
                .unwrap_err()
                .field(),
            "nperseg"
        );
        assert_eq!(coherence(&[], &[], &cfg).unwrap_err().field(), "x");
    }
}
