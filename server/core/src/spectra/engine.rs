//! Shared Welch machinery: segment slicing, detrend, window, real FFT and the
//! one-sided density scaling. One FFT plan and one set of buffers per call.

use std::sync::Arc;

use realfft::num_complex::Complex;
use realfft::{RealFftPlanner, RealToComplex};

use super::detrend::detrend_in_place;
use super::{Detrend, SpectraError, WelchConfig};

/// Windowed, detrended real FFTs of the successive segments of a signal.
///
/// Built once per estimate; [`SegmentFft::transform`] reuses the plan and the
/// internal buffers, so nothing is allocated per segment.
pub(crate) struct SegmentFft {
    fft: Arc<dyn RealToComplex<f64>>,
    window: Vec<f64>,
    window_power: f64,
    detrend: Detrend,
    nperseg: usize,
    step: usize,
    n_segments: usize,
    input: Vec<f64>,
    scratch: Vec<Complex<f64>>,
}

impl SegmentFft {
    /// Plans the FFT for a validated `cfg` applied to `n_samples` samples.
    pub(crate) fn new(cfg: &WelchConfig, n_samples: usize) -> Self {
        let fft = RealFftPlanner::<f64>::new().plan_fft_forward(cfg.nperseg);
        let window = cfg.window.coefficients(cfg.nperseg);
        let window_power = window.iter().map(|w| w * w).sum();
        let input = fft.make_input_vec();
        let scratch = fft.make_scratch_vec();
        SegmentFft {
            fft,
            window,
            window_power,
            detrend: cfg.detrend,
            nperseg: cfg.nperseg,
            step: cfg.step(),
            n_segments: cfg.n_segments(n_samples),
            input,
            scratch,
        }
    }

    /// A zeroed buffer of the right length (`nperseg / 2 + 1`) for
    /// [`SegmentFft::transform`].
    pub(crate) fn make_output(&self) -> Vec<Complex<f64>> {
        self.fft.make_output_vec()
    }

    /// Number of segments averaged.
    pub(crate) fn n_segments(&self) -> usize {
        self.n_segments
    }

    /// `out = rfft(window · detrend(signal[m·step .. m·step + nperseg]))`.
    pub(crate) fn transform(
        &mut self,
        signal: &[f64],
        segment: usize,
        out: &mut [Complex<f64>],
    ) -> Result<(), SpectraError> {
        let start = segment.saturating_mul(self.step);
        let end = start.saturating_add(self.nperseg);
        let Some(samples) = signal.get(start..end) else {
            return Err(SpectraError::parameter(
                "nperseg",
                format!(
                    "segment {segment} ({start}..{end}) lies outside the signal of length {}",
                    signal.len()
                ),
            ));
        };
        self.input.copy_from_slice(samples);
        detrend_in_place(self.detrend, &mut self.input);
        self.input
            .iter_mut()
            .zip(&self.window)
            .for_each(|(v, w)| *v *= w);
        self.fft_of_input(out)
    }

    /// `out = rfft(window · (samples − offset))` for one segment of
    /// exactly `nperseg` samples, in one pass into the FFT's input (the
    /// caller's constant detrend: `offset` is the segment mean).
    pub(crate) fn transform_offset(
        &mut self,
        samples: &[f64],
        offset: f64,
        out: &mut [Complex<f64>],
    ) -> Result<(), SpectraError> {
        if samples.len() != self.nperseg {
            return Err(SpectraError::parameter(
                "nperseg",
                format!(
                    "a segment of {} samples given for nperseg {}",
                    samples.len(),
                    self.nperseg
                ),
            ));
        }
        self.input
            .iter_mut()
            .zip(samples)
            .zip(&self.window)
            .for_each(|((v, x), w)| *v = (x - offset) * w);
        self.fft_of_input(out)
    }

    /// `out = rfft(input)` (the input buffer is used as scratch).
    fn fft_of_input(&mut self, out: &mut [Complex<f64>]) -> Result<(), SpectraError> {
        self.fft
            .process_with_scratch(&mut self.input, out, &mut self.scratch)
            .map_err(|e| {
                SpectraError::parameter(
                    "nperseg",
                    format!("real FFT of length {} failed: {e}", self.nperseg),
                )
            })
    }

    /// Factor turning the per-bin *sum* over segments of `conj(X)·Y` into
    /// scipy's one-sided density: `c_k / (fs · Σw² · n_segments)` with
    /// `c_k = 2` except for DC and, when `nperseg` is even, Nyquist.
    pub(crate) fn density_factors(&self, fs: f64) -> Vec<f64> {
        let nf = self.nperseg / 2 + 1;
        let base = 1.0 / (fs * self.window_power) / self.n_segments.max(1) as f64;
        (0..nf)
            .map(|k| {
                let unpaired = k == 0 || (self.nperseg.is_multiple_of(2) && k == nf - 1);
                if unpaired { base } else { 2.0 * base }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transform_is_windowed_detrended_dft() {
        let cfg = WelchConfig::hann(1.0, 6).with_noverlap(2);
        let x: Vec<f64> = (0..14).map(|i| ((i * i) % 7) as f64 - 1.5).collect();
        let mut eng = SegmentFft::new(&cfg, x.len());
        assert_eq!(eng.n_segments(), 3);
        let mut out = eng.make_output();
        assert_eq!(out.len(), 4);
        let w = cfg.window.coefficients(6);
        for m in 0..3 {
            eng.transform(&x, m, &mut out).unwrap();
            let seg = &x[m * 4..m * 4 + 6];
            let mean = seg.iter().sum::<f64>() / 6.0;
            for (k, o) in out.iter().enumerate() {
                let mut acc = Complex::new(0.0, 0.0);
                for (n, s) in seg.iter().enumerate() {
                    let ang = -2.0 * std::f64::consts::PI * (k * n) as f64 / 6.0;
                    acc += Complex::from_polar(w[n] * (s - mean), ang);
                }
                assert!((o - acc).norm() < 1e-12, "seg {m} bin {k}: {o} vs {acc}");
            }
        }
    }

    #[test]
    fn out_of_range_segment_is_an_error_not_a_panic() {
        let cfg = WelchConfig::hann(1.0, 4);
        let x = [0.0; 8];
        let mut eng = SegmentFft::new(&cfg, x.len());
        let mut out = eng.make_output();
        assert!(eng.transform(&x, 2, &mut out).is_ok());
        assert_eq!(
            eng.transform(&x, 3, &mut out).unwrap_err().field(),
            "nperseg"
        );
    }

    #[test]
    fn density_factors_double_only_paired_bins() {
        let even = SegmentFft::new(&WelchConfig::hann(2.0, 8), 8);
        let f = even.density_factors(2.0);
        let base = 1.0 / (2.0 * 3.0); // Σw² = 3N/8 = 3, one segment
        assert_eq!(f.len(), 5);
        assert!((f[0] - base).abs() < 1e-15 && (f[4] - base).abs() < 1e-15);
        assert!(f[1..4].iter().all(|v| (v - 2.0 * base).abs() < 1e-15));

        let odd = SegmentFft::new(&WelchConfig::hann(1.0, 7), 7);
        let f = odd.density_factors(1.0);
        assert_eq!(f.len(), 4);
        assert!(f[1..].iter().all(|v| (v - 2.0 * f[0]).abs() < 1e-15));
    }

    #[test]
    fn length_one_segments_work() {
        let cfg = WelchConfig::hann(1.0, 1).with_detrend(Detrend::None);
        let x = [2.0, -3.0];
        let mut eng = SegmentFft::new(&cfg, x.len());
        assert_eq!(eng.n_segments(), 2);
        let mut out = eng.make_output();
        eng.transform(&x, 1, &mut out).unwrap();
        assert_eq!(out, vec![Complex::new(-3.0, 0.0)]);
    }
}
