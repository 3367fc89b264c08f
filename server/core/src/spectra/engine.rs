//! Shared Welch machinery: segment slicing, detrend, window, real FFT and the
//! one-sided density scaling. One FFT plan and one set of buffers per call.

use std::sync::{Arc, Mutex};

use realfft::num_complex::Complex;
use realfft::{RealFftPlanner, RealToComplex};

use super::detrend::detrend_in_place;
use super::{Detrend, SpectraError, WelchConfig, Window};
use crate::kernels::{fold8, has_avx2_fma, prefetch_line};

/// Windowed, detrended real FFTs of the successive segments of a signal.
///
/// Built once per estimate; [`SegmentFft::transform`] reuses the plan and the
/// internal buffers, so nothing is allocated per segment. A clone shares the
/// plan (for a second thread) and has buffers of its own.
#[derive(Clone)]
pub(crate) struct SegmentFft {
    plan: Arc<Plan>,
    detrend: Detrend,
    nperseg: usize,
    step: usize,
    n_segments: usize,
    input: Vec<f64>,
    scratch: Vec<Complex<f64>>,
}

/// What depends on the segment length and window only: the FFT plan, the
/// window and its DFT. Kept between calls (see [`plan`]).
struct Plan {
    nperseg: usize,
    window_kind: Window,
    fft: Arc<dyn RealToComplex<f64>>,
    window: Vec<f64>,
    window_power: f64,
    /// `W = rfft(window)` at the bins where it is not zero to rounding
    /// (bins 0 and 1 of a periodic Hann): what a constant shifts.
    window_dft: Vec<(usize, Complex<f64>)>,
}

/// Plans kept for the last few segment lengths: planning a 4096-point FFT,
/// its window and the window's DFT takes ~0.1 ms, a tenth of a 1-hour
/// report's spectra.
const KEPT_PLANS: usize = 8;

/// Longest segment whose plan is kept (~1.5 MB of window and twiddles).
const KEPT_NPERSEG: usize = 1 << 16;

static PLANS: Mutex<Vec<Arc<Plan>>> = Mutex::new(Vec::new());

/// The plan for `nperseg` and `window`, kept or made (and kept).
fn plan(nperseg: usize, window_kind: Window) -> Arc<Plan> {
    let found = |plans: &Vec<Arc<Plan>>| {
        plans
            .iter()
            .find(|p| p.nperseg == nperseg && p.window_kind == window_kind)
            .cloned()
    };
    // A poisoned lock only means another thread panicked while holding
    // it: the list itself is always whole.
    if let Some(p) = found(&PLANS.lock().unwrap_or_else(|e| e.into_inner())) {
        return p;
    }
    let fft = RealFftPlanner::<f64>::new().plan_fft_forward(nperseg);
    let window = window_kind.coefficients(nperseg);
    let window_power = window.iter().map(|w| w * w).sum();
    let mut input = fft.make_input_vec();
    let mut scratch = fft.make_scratch_vec();
    let window_dft = sparse_dft(&*fft, &window, &mut input, &mut scratch);
    let made = Arc::new(Plan {
        nperseg,
        window_kind,
        fft,
        window,
        window_power,
        window_dft,
    });
    if nperseg > KEPT_NPERSEG {
        return made;
    }
    let mut plans = PLANS.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(p) = found(&plans) {
        return p;
    }
    if plans.len() >= KEPT_PLANS {
        plans.remove(0);
    }
    plans.push(Arc::clone(&made));
    made
}

impl SegmentFft {
    /// Plans the FFT for a validated `cfg` applied to `n_samples` samples.
    pub(crate) fn new(cfg: &WelchConfig, n_samples: usize) -> Self {
        let plan = plan(cfg.nperseg, cfg.window);
        SegmentFft {
            input: plan.fft.make_input_vec(),
            scratch: plan.fft.make_scratch_vec(),
            plan,
            detrend: cfg.detrend,
            nperseg: cfg.nperseg,
            step: cfg.step(),
            n_segments: cfg.n_segments(n_samples),
        }
    }

    /// A zeroed buffer of the right length (`nperseg / 2 + 1`) for
    /// [`SegmentFft::transform`].
    pub(crate) fn make_output(&self) -> Vec<Complex<f64>> {
        self.plan.fft.make_output_vec()
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
            .zip(&self.plan.window)
            .for_each(|(v, w)| *v *= w);
        self.fft_of_input(out)
    }

    /// `out = rfft(window · (samples − mean(samples)))` for one segment of
    /// exactly `nperseg` samples, reading each sample once: the window is
    /// applied to `samples − shift` while `Σ (samples − shift)` is summed,
    /// and the constant `mean − shift` is then removed in the frequency
    /// domain (`out[k] −= (mean − shift)·W[k]`, W the window's DFT, nonzero
    /// at two bins for Hann). Returns `mean − shift`, non-finite when a
    /// sample is (or the sum overflows).
    ///
    /// `shift` should be close to the mean (the previous segment's mean,
    /// or a sample): the bins it corrects lose `|mean − shift| / σ` of
    /// their relative precision to cancellation. `prefetch` (may be empty)
    /// is asked into the cache meanwhile: the next segment's new samples.
    pub(crate) fn transform_centred(
        &mut self,
        samples: &[f64],
        shift: f64,
        prefetch: &[f64],
        out: &mut [Complex<f64>],
    ) -> Result<f64, SpectraError> {
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
        let sum = window_shifted(&mut self.input, samples, &self.plan.window, shift, prefetch);
        self.fft_of_input(out)?;
        let offset = sum / self.nperseg as f64;
        for &(k, w) in &self.plan.window_dft {
            out[k] -= w * offset;
        }
        Ok(offset)
    }

    /// `out = rfft(input)` (the input buffer is used as scratch).
    fn fft_of_input(&mut self, out: &mut [Complex<f64>]) -> Result<(), SpectraError> {
        self.plan
            .fft
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
        let base = 1.0 / (fs * self.plan.window_power) / self.n_segments.max(1) as f64;
        (0..nf)
            .map(|k| {
                let unpaired = k == 0 || (self.nperseg.is_multiple_of(2) && k == nf - 1);
                if unpaired { base } else { 2.0 * base }
            })
            .collect()
    }
}

/// The bins of `rfft(window)` that are not zero to rounding (all of them
/// but ~64 ε · Σ|w|), computed with the engine's own plan.
fn sparse_dft(
    fft: &dyn RealToComplex<f64>,
    window: &[f64],
    input: &mut [f64],
    scratch: &mut [Complex<f64>],
) -> Vec<(usize, Complex<f64>)> {
    input.copy_from_slice(window);
    let mut out = fft.make_output_vec();
    if fft.process_with_scratch(input, &mut out, scratch).is_err() {
        return Vec::new();
    }
    let noise = 64.0 * f64::EPSILON * window.iter().map(|w| w.abs()).sum::<f64>();
    out.into_iter()
        .enumerate()
        .filter(|(_, w)| w.norm() > noise)
        .collect()
}

/// `input = window · (samples − shift)`, returning `Σ (samples − shift)`
/// (eight partial sums), with prefetches of `prefetch` spread over the loop.
fn window_shifted(
    input: &mut [f64],
    samples: &[f64],
    window: &[f64],
    shift: f64,
    prefetch: &[f64],
) -> f64 {
    #[cfg(target_arch = "x86_64")]
    if has_avx2_fma() {
        // SAFETY: the CPU has the features the function is compiled for.
        return unsafe { window_shifted_avx2(input, samples, window, shift, prefetch) };
    }
    window_shifted_body(input, samples, window, shift, prefetch)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn window_shifted_avx2(
    input: &mut [f64],
    samples: &[f64],
    window: &[f64],
    shift: f64,
    prefetch: &[f64],
) -> f64 {
    window_shifted_body(input, samples, window, shift, prefetch)
}

/// Samples per cache line.
const LINE: usize = 8;

#[inline(always)]
fn window_shifted_body(
    input: &mut [f64],
    samples: &[f64],
    window: &[f64],
    shift: f64,
    prefetch: &[f64],
) -> f64 {
    let n = input.len().min(samples.len()).min(window.len());
    let full = n / LINE * LINE;
    // One prefetched line of `prefetch` per `stride` lines of samples.
    let lines = prefetch.len().div_ceil(LINE);
    let stride = (full / LINE)
        .checked_div(lines)
        .map_or(usize::MAX, |s| s.max(1));
    let mut acc = [0.0f64; LINE];
    let mut next = 0;
    for (line, ((v, x), w)) in input[..full]
        .chunks_exact_mut(LINE)
        .zip(samples[..full].chunks_exact(LINE))
        .zip(window[..full].chunks_exact(LINE))
        .enumerate()
    {
        if line % stride == 0 && next < prefetch.len() {
            prefetch_line(&prefetch[next]);
            next += LINE;
        }
        for k in 0..LINE {
            let d = x[k] - shift;
            acc[k] += d;
            v[k] = d * w[k];
        }
    }
    let mut tail = 0.0;
    for k in full..n {
        let d = samples[k] - shift;
        tail += d;
        input[k] = d * window[k];
    }
    fold8(acc) + tail
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plans_are_kept_per_segment_length() {
        // Lengths no other test uses: a plan is only dropped after eight
        // other lengths were planned since.
        let a = SegmentFft::new(&WelchConfig::hann(1.0, 96), 1000);
        let b = SegmentFft::new(&WelchConfig::hann(5.0, 96).with_noverlap(10), 500);
        let c = SegmentFft::new(&WelchConfig::hann(1.0, 98), 1000);
        let big = KEPT_NPERSEG + 2;
        let d = SegmentFft::new(&WelchConfig::hann(1.0, big), big);
        let e = SegmentFft::new(&WelchConfig::hann(1.0, big), big);
        assert!(!Arc::ptr_eq(&d.plan, &e.plan), "too long to keep");
        assert!(Arc::ptr_eq(&a.plan, &b.plan));
        assert!(!Arc::ptr_eq(&a.plan, &c.plan));
        assert_eq!(c.plan.window.len(), 98);
        assert_eq!((a.step, b.step, b.n_segments), (48, 86, 5));
    }

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
    fn centred_transform_is_the_dft_of_the_mean_removed_segment() {
        // Odd and even lengths; shifts at, near and far from the mean.
        for n in [6usize, 7, 64] {
            let cfg = WelchConfig::hann(1.0, n);
            let x: Vec<f64> = (0..n)
                .map(|i| 40.0 + ((i * i) % 7) as f64 - 0.3 * i as f64)
                .collect();
            let mean = x.iter().sum::<f64>() / n as f64;
            let w = cfg.window.coefficients(n);
            let mut eng = SegmentFft::new(&cfg, n);
            let mut out = eng.make_output();
            for shift in [mean, x[0], 0.0, -1e3] {
                let offset = eng.transform_centred(&x, shift, &x[..3], &mut out).unwrap();
                assert!((shift + offset - mean).abs() < 1e-12 * mean.abs());
                let scale: f64 = x.iter().map(|v| v.abs()).sum();
                for (k, o) in out.iter().enumerate() {
                    let mut acc = Complex::new(0.0, 0.0);
                    for (i, s) in x.iter().enumerate() {
                        let ang = -2.0 * std::f64::consts::PI * (k * i) as f64 / n as f64;
                        acc += Complex::from_polar(w[i] * (s - mean), ang);
                    }
                    // Rounding of the samples' size (the reference's own
                    // too), and cancellation at the corrected bins that
                    // grows with the shift's distance from the mean.
                    let tol = 1e-14 * (scale + n as f64 * (mean - shift).abs());
                    assert!(
                        (o - acc).norm() < tol,
                        "n {n} shift {shift} bin {k}: {o} vs {acc}"
                    );
                }
            }
            // A non-finite sample makes the returned offset non-finite.
            for bad in [f64::NAN, f64::INFINITY] {
                let mut y = x.clone();
                y[n - 1] = bad;
                let offset = eng.transform_centred(&y, y[0], &[], &mut out).unwrap();
                assert!(!offset.is_finite());
            }
            // The window's DFT is kept at Hann's two nonzero bins only.
            assert_eq!(
                eng.plan
                    .window_dft
                    .iter()
                    .map(|(k, _)| *k)
                    .collect::<Vec<_>>(),
                vec![0, 1]
            );
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
