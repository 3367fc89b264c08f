//! Welch power spectral density (scipy.signal.welch).

use super::config::validate_inputs;
use super::engine::SegmentFft;
use super::{SpectraError, Spectrum, WelchConfig};

/// One-sided power spectral density of `x` by Welch's method, equal to
/// `scipy.signal.welch(x, fs, window='hann', nperseg, noverlap, detrend,
/// return_onesided=True, scaling='density', average='mean')`.
///
/// Units: (units of `x`)² / Hz; `Σ values · fs/nperseg ≈ variance(x)` for a
/// stationary signal with constant detrend.
///
/// # Errors
/// [`SpectraError`] naming `fs`, `nperseg`, `noverlap` (see
/// [`WelchConfig::validate`]), `x` when it is empty, or `x` with the index of
/// its first NaN/infinite sample.
pub fn welch(x: &[f64], cfg: &WelchConfig) -> Result<Spectrum, SpectraError> {
    validate_inputs(cfg, x, None)?;
    let mut engine = SegmentFft::new(cfg, x.len());
    let mut spec = engine.make_output();
    let mut acc = vec![0.0; spec.len()];
    for m in 0..engine.n_segments() {
        engine.transform(x, m, &mut spec)?;
        acc.iter_mut()
            .zip(&spec)
            .for_each(|(a, s)| *a += s.norm_sqr());
    }
    acc.iter_mut()
        .zip(engine.density_factors(cfg.fs))
        .for_each(|(a, f)| *a *= f);
    Ok(Spectrum {
        freqs: cfg.frequencies(),
        values: acc,
    })
}

#[cfg(test)]
mod tests {
    use super::super::test_support::{Gaussian, assert_rel_close, variance, welch_fixture};
    use super::super::{Detrend, Window};
    use super::*;

    #[test]
    fn matches_scipy_fixtures() {
        let fx = welch_fixture();
        assert!(fx.cases.len() >= 10);
        for case in &fx.cases {
            let x = &fx.signals[&case.x];
            let cfg = case.params.config();
            let s = welch(x, &cfg).unwrap_or_else(|e| panic!("{}: {e}", case.params.name));
            assert_rel_close(
                &s.freqs,
                &case.freqs,
                1e-12,
                &format!("{} freqs", case.params.name),
            );
            assert_rel_close(
                &s.values,
                &case.pxx,
                1e-9,
                &format!("{} pxx", case.params.name),
            );
        }
    }

    #[test]
    fn white_noise_level_is_two_sigma2_over_fs() {
        let (sigma, fs) = (1.7, 20.0);
        let x = Gaussian::new(42).vec(1 << 17, sigma);
        let s = welch(&x, &WelchConfig::hann(fs, 256)).unwrap();
        let expected = 2.0 * sigma * sigma / fs;
        // Bins 0 and 1 are excluded: the per-segment mean removal takes
        // |W(1)|²/(N Σw²) = 1/6 of the power out of bin 1 of a Hann window.
        let inner = &s.values[2..s.values.len() - 1];
        let level = inner.iter().sum::<f64>() / inner.len() as f64;
        assert!(
            (level / expected - 1.0).abs() < 0.02,
            "mean level {level} vs 2σ²/fs = {expected}"
        );
        // Every bin is within a generous statistical band (~1000 averages,
        // relative standard deviation ≈ 3 %).
        assert!(inner.iter().all(|v| (v / expected - 1.0).abs() < 0.25));
        assert!((s.values[1] / (expected * 5.0 / 6.0) - 1.0).abs() < 0.25);
        // Nyquist bin (even nperseg) is not doubled: half the level.
        let nyq = *s.values.last().unwrap();
        assert!((nyq / (expected / 2.0) - 1.0).abs() < 0.25, "nyquist {nyq}");
    }

    #[test]
    fn sinusoid_power_and_peak_frequency() {
        let fs = 50.0;
        let n = 20_000;
        let nperseg = 500; // df = 0.1 Hz
        for (amp, f0) in [(2.0, 6.0), (0.5, 13.37)] {
            let x: Vec<f64> = (0..n)
                .map(|i| amp * (2.0 * std::f64::consts::PI * f0 * i as f64 / fs + 0.3).sin())
                .collect();
            let cfg = WelchConfig::hann(fs, nperseg);
            let s = welch(&x, &cfg).unwrap();
            let df = cfg.df();
            let (kmax, _) =
                s.values.iter().enumerate().fold(
                    (0, f64::MIN),
                    |b, (k, v)| if *v > b.1 { (k, *v) } else { b },
                );
            assert!(
                (s.freqs[kmax] - f0).abs() <= df / 2.0 + 1e-12,
                "peak at {}",
                s.freqs[kmax]
            );
            let power: f64 = s.values[kmax - 6..=kmax + 6].iter().sum::<f64>() * df;
            let expected = amp * amp / 2.0;
            assert!(
                (power / expected - 1.0).abs() < 5e-3,
                "power {power} vs {expected}"
            );
        }
    }

    #[test]
    fn parseval_total_power_is_variance() {
        let fs = 8.0;
        let mut g = Gaussian::new(3);
        let x: Vec<f64> = (0..50_000)
            .map(|i| 5.0 + 0.8 * g.sample() + (0.7 * i as f64).sin())
            .collect();
        let cfg = WelchConfig::hann(fs, 1024);
        let s = welch(&x, &cfg).unwrap();
        let total = s.values.iter().sum::<f64>() * cfg.df();
        let var = variance(&x);
        assert!(
            (total / var - 1.0).abs() < 0.02,
            "Σ P df = {total}, var = {var}"
        );
    }

    #[test]
    fn parseval_is_exact_for_one_segment() {
        // One segment, no detrend: Σ P·df = Σ (w x)² / Σ w² to rounding.
        let x = Gaussian::new(9).vec(777, 2.0);
        for nperseg in [777, 776] {
            let cfg = WelchConfig::hann(3.0, nperseg)
                .with_noverlap(0)
                .with_detrend(Detrend::None);
            let s = welch(&x, &cfg).unwrap();
            let w = Window::Hann.coefficients(nperseg);
            let num: f64 = w.iter().zip(&x).map(|(w, x)| (w * x).powi(2)).sum();
            let den: f64 = w.iter().map(|w| w * w).sum();
            let total = s.values.iter().sum::<f64>() * cfg.df();
            assert!(
                (total - num / den).abs() < 1e-12 * total,
                "{total} vs {}",
                num / den
            );
        }
    }

    #[test]
    fn constant_detrend_kills_offset_and_linear_kills_ramp() {
        let x: Vec<f64> = (0..1000).map(|i| 3.0 + 0.01 * i as f64).collect();
        let lin = welch(
            &x,
            &WelchConfig::hann(1.0, 100).with_detrend(Detrend::Linear),
        )
        .unwrap();
        assert!(
            lin.values.iter().all(|v| *v < 1e-24),
            "{:?}",
            &lin.values[..3]
        );
        let offset = vec![4.0; 300];
        let c = welch(&offset, &WelchConfig::hann(1.0, 64)).unwrap();
        assert!(c.values.iter().all(|v| *v < 1e-26));
        let none = welch(
            &offset,
            &WelchConfig::hann(1.0, 64).with_detrend(Detrend::None),
        )
        .unwrap();
        assert!(none.values[0] > 1.0);
    }

    #[test]
    fn errors_are_reported_not_panicked() {
        let x = vec![1.0; 100];
        let err = |x: &[f64], cfg: &WelchConfig| welch(x, cfg).unwrap_err().field().to_owned();
        assert_eq!(err(&x, &WelchConfig::hann(1.0, 0)), "nperseg");
        assert_eq!(err(&x, &WelchConfig::hann(1.0, 101)), "nperseg");
        assert_eq!(
            err(&x, &WelchConfig::hann(1.0, 10).with_noverlap(10)),
            "noverlap"
        );
        assert_eq!(err(&x, &WelchConfig::hann(0.0, 10)), "fs");
        assert_eq!(err(&[], &WelchConfig::hann(1.0, 10)), "x");
        let mut bad = x.clone();
        bad[57] = f64::INFINITY;
        match welch(&bad, &WelchConfig::hann(1.0, 10)).unwrap_err() {
            SpectraError::NonFinite { field, index, .. } => {
                assert_eq!((field.as_str(), index), ("x", 57))
            }
            e => panic!("{e:?}"),
        }
    }

    #[test]
    fn shapes_for_even_odd_and_tiny_segments() {
        let x = Gaussian::new(5).vec(50, 1.0);
        for nperseg in [1, 2, 3, 49, 50] {
            let s = welch(&x, &WelchConfig::hann(2.0, nperseg)).unwrap();
            assert_eq!(s.values.len(), nperseg / 2 + 1);
            assert_eq!(s.freqs.len(), nperseg / 2 + 1);
            assert!(s.values.iter().all(|v| v.is_finite() && *v >= 0.0));
        }
    }
}
