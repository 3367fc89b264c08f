//! Schroeder-phased multisines and random binary signals.
//!
//! A multisine puts equal power on a chosen set of harmonics of 1/P, so over
//! an integer number of periods its spectrum is exactly zero between the
//! lines (no leakage) and the frequency-response estimate at each line needs
//! no windowing (Pintelon & Schoukens, *System Identification: A Frequency
//! Domain Approach*, ch. 5). With all phases equal the sines add up at t = 0
//! and the crest factor (peak/RMS) is √(2K) for K lines, so the thrusters
//! spend their amplitude budget on one spike. Schroeder's phases
//! φᵢ = −π·i(i−1)/K (Schroeder 1970, "Synthesis of low-peak-factor signals")
//! spread the energy in time like a chirp and bring the crest factor down to
//! about 1.4–1.7, i.e. more power per unit of actuator range.
//!
//! The random binary signal is the non-periodic alternative to a PRBS: i.i.d.
//! ±1 chips held for a clock period, whose expected spectrum has the same
//! sinc² shape as a PRBS with the same clock.

use crate::rng::SplitMix64;
use realfft::RealFftPlanner;
use realfft::num_complex::Complex;

use super::{
    SignalError, check_clock_period, chip_index, require_finite, require_non_negative,
    require_positive, sample_count, try_vec,
};

/// Upper bound on `samples × lines` for direct (non-FFT) synthesis, used only
/// when a period is not an integer number of samples.
const MAX_DIRECT_OPS: f64 = 2e9;

/// Relative tolerance for deciding that `period_s · fs` is an integer.
const INTEGER_TOL: f64 = 1e-9;

/// Sample a Schroeder-phased multisine.
///
/// The lines are the harmonics k/`period_s` (k ≥ 1) inside
/// [`f_lo_hz`, `f_hi_hz`] (band edges inclusive, to within 10⁻⁹ of a
/// harmonic), all with equal amplitude and Schroeder phases
/// φᵢ = −π·i(i−1)/K, i = 1..K, numbering the K lines upward from the lowest.
/// The sum of cosines is then scaled so that the largest |x − offset| over
/// the returned samples equals `amplitude` (to rounding), and shifted by
/// `offset`. Returns `round(duration·fs)` samples.
///
/// Choose `period_s · sample_rate_hz` an integer and `duration_s` a whole
/// number of periods so that the DFT of the record has energy only at the
/// chosen lines; a non-integer period is accepted but synthesised directly
/// (slower) and leaks.
///
/// # Errors
/// With the offending field named: non-finite values; `sample_rate_hz`,
/// `duration_s` or `period_s` not positive; `period_s` longer than the run;
/// `f_lo_hz` negative; `f_hi_hz` below `f_lo_hz` or at/above Nyquist; no
/// harmonic of 1/`period_s` in the band; negative `amplitude`; an output too
/// large to compute.
pub fn multisine(
    f_lo_hz: f64,
    f_hi_hz: f64,
    period_s: f64,
    amplitude: f64,
    offset: f64,
    sample_rate_hz: f64,
    duration_s: f64,
) -> Result<Vec<f64>, SignalError> {
    let n = sample_count(sample_rate_hz, duration_s)?;
    require_positive("period_s", period_s)?;
    if period_s > duration_s {
        return Err(SignalError::invalid(
            "period_s",
            format!("period {period_s} s is longer than the run ({duration_s} s)"),
        ));
    }
    require_non_negative("f_lo_hz", f_lo_hz)?;
    require_finite("f_hi_hz", f_hi_hz)?;
    if f_hi_hz < f_lo_hz {
        return Err(SignalError::invalid(
            "f_hi_hz",
            format!("upper band edge {f_hi_hz} Hz is below the lower edge {f_lo_hz} Hz"),
        ));
    }
    let nyquist = sample_rate_hz / 2.0;
    if f_hi_hz >= nyquist {
        return Err(SignalError::invalid(
            "f_hi_hz",
            format!("upper band edge {f_hi_hz} Hz is not below the Nyquist frequency {nyquist} Hz"),
        ));
    }
    require_non_negative("amplitude", amplitude)?;
    require_finite("offset", offset)?;

    // Harmonic numbers in the band: f_lo ≤ k/P ≤ f_hi, k ≥ 1, k/P < fs/2.
    let k_lo = (f_lo_hz * period_s - INTEGER_TOL).ceil().max(1.0);
    let mut k_hi = (f_hi_hz * period_s + INTEGER_TOL).floor();
    if k_hi / period_s >= nyquist {
        k_hi -= 1.0;
    }
    if k_hi < k_lo {
        return Err(SignalError::invalid(
            "f_hi_hz",
            format!(
                "no harmonic of 1/period_s = {} Hz lies in [{f_lo_hz}, {f_hi_hz}] Hz; widen the band or lengthen the period",
                1.0 / period_s
            ),
        ));
    }
    // k_hi < P·fs/2 ≤ n, which is a valid usize, so these casts are exact.
    let harmonics: Vec<u64> = (k_lo as u64..=k_hi as u64).collect();
    let count = harmonics.len() as f64;
    let phases: Vec<f64> = (1..=harmonics.len())
        .map(|i| {
            let i = i as f64;
            -std::f64::consts::PI * i * (i - 1.0) / count
        })
        .collect();

    let samples_per_period = period_s * sample_rate_hz;
    let l = samples_per_period.round();
    let raw = if (samples_per_period - l).abs() <= INTEGER_TOL * samples_per_period.max(1.0) {
        // Integer period: synthesise one period with an inverse real FFT and
        // tile it (the record is at least one period long).
        let one = synthesize_period_fft(l as usize, &harmonics, &phases)?;
        let mut out = try_vec::<f64>("duration_s", n)?;
        out.extend((0..n).map(|k| one[k % one.len()]));
        out
    } else {
        synthesize_direct(n, samples_per_period, &harmonics, &phases)?
    };

    let peak = raw.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    if !(peak.is_finite() && peak > 0.0) {
        return Err(SignalError::invalid(
            "period_s",
            "the chosen lines sum to zero at every sample instant; change the band or sample rate",
        ));
    }
    let scale = amplitude / peak;
    Ok(raw.into_iter().map(|v| offset + v * scale).collect())
}

/// One period of Σᵢ cos(2π kᵢ t/L + φᵢ), t = 0..L−1, by inverse real FFT:
/// bin kᵢ set to ½·e^{jφᵢ} (its Hermitian mirror is implied), since the
/// unnormalised inverse DFT of that spectrum is exactly the sum of cosines.
fn synthesize_period_fft(
    l: usize,
    harmonics: &[u64],
    phases: &[f64],
) -> Result<Vec<f64>, SignalError> {
    let mut spectrum = try_vec::<Complex<f64>>("period_s", l / 2 + 1)?;
    spectrum.resize(l / 2 + 1, Complex::new(0.0, 0.0));
    for (&k, &phi) in harmonics.iter().zip(phases) {
        // k < L/2 because every line is below Nyquist.
        let bin = spectrum.get_mut(k as usize).ok_or_else(|| {
            SignalError::invalid("f_hi_hz", "a line falls outside the one-period spectrum")
        })?;
        *bin = Complex::from_polar(0.5, phi);
    }
    let mut out = try_vec::<f64>("period_s", l)?;
    out.resize(l, 0.0);
    let mut planner = RealFftPlanner::<f64>::new();
    let ifft = planner.plan_fft_inverse(l);
    ifft.process(&mut spectrum, &mut out)
        .map_err(|e| SignalError::invalid("period_s", format!("inverse FFT failed: {e}")))?;
    Ok(out)
}

/// Direct synthesis of Σᵢ cos(2π kᵢ k/L + φᵢ) for a non-integer period L
/// (in samples). The cycle count is reduced modulo 1 before multiplying by
/// 2π so that long records keep full phase accuracy.
fn synthesize_direct(
    n: usize,
    samples_per_period: f64,
    harmonics: &[u64],
    phases: &[f64],
) -> Result<Vec<f64>, SignalError> {
    if n as f64 * harmonics.len() as f64 > MAX_DIRECT_OPS {
        return Err(SignalError::too_large(
            "period_s",
            format!(
                "{n} samples × {} lines is too much work for a period that is not a whole number of samples ({samples_per_period}); choose period_s·sample_rate_hz an integer",
                harmonics.len()
            ),
        ));
    }
    let two_pi = 2.0 * std::f64::consts::PI;
    let mut out = try_vec::<f64>("duration_s", n)?;
    out.extend((0..n).map(|k| {
        let cycles_per_harmonic = (k as f64 / samples_per_period).rem_euclid(1.0);
        harmonics
            .iter()
            .zip(phases)
            .map(|(&h, &phi)| {
                (two_pi * (h as f64 * cycles_per_harmonic).rem_euclid(1.0) + phi).cos()
            })
            .sum::<f64>()
    }));
    Ok(out)
}

/// Crest factor: peak |x − x̄| divided by the RMS of x − x̄.
///
/// The mean is removed first so the figure describes the excitation about
/// its operating point (a sine has √2, a binary signal 1). Returns NaN for an
/// empty or constant input, where the ratio is undefined.
pub fn crest_factor(x: &[f64]) -> f64 {
    if x.is_empty() {
        return f64::NAN;
    }
    let n = x.len() as f64;
    let mean = x.iter().sum::<f64>() / n;
    let peak = x.iter().fold(0.0_f64, |m, v| m.max((v - mean).abs()));
    let rms = (x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt();
    if rms > 0.0 { peak / rms } else { f64::NAN }
}

/// One fair coin flip from the best-mixed (top) bit of a SplitMix64 stream.
fn next_bit(rng: &mut SplitMix64) -> bool {
    rng.next_u64() >> 63 == 1
}

/// Sample a random binary signal: i.i.d. fair chips of `offset ± amplitude`,
/// each held for `clock_period_s`, drawn from a SplitMix64 stream seeded by
/// `seed` (deterministic: the same arguments always give the same signal).
///
/// Sample k holds chip `floor(k·h/T_c + 10⁻⁹)`, as in
/// [`prbs`](super::prbs::prbs). Returns `round(duration·fs)` samples.
///
/// # Errors
/// With the offending field named: non-finite values; `sample_rate_hz` or
/// `duration_s` not positive; `clock_period_s` shorter than one sample or
/// longer than the run; negative `amplitude`.
pub fn random_binary(
    clock_period_s: f64,
    amplitude: f64,
    offset: f64,
    seed: u64,
    sample_rate_hz: f64,
    duration_s: f64,
) -> Result<Vec<f64>, SignalError> {
    let n = sample_count(sample_rate_hz, duration_s)?;
    check_clock_period(clock_period_s, sample_rate_hz, duration_s)?;
    require_non_negative("amplitude", amplitude)?;
    require_finite("offset", offset)?;

    let samples_per_chip = clock_period_s * sample_rate_hz;
    let high = offset + amplitude;
    let low = offset - amplitude;
    let mut rng = SplitMix64::new(seed);
    let mut current_bit = next_bit(&mut rng);
    let mut current_chip: u64 = 0;
    let mut out = try_vec::<f64>("duration_s", n)?;
    for k in 0..n {
        let idx = chip_index(k, samples_per_chip);
        while current_chip < idx {
            current_bit = next_bit(&mut rng);
            current_chip += 1;
        }
        out.push(if current_bit { high } else { low });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// Naive DFT magnitudes |X[m]|, m = 0..L−1.
    fn dft_mag(x: &[f64]) -> Vec<f64> {
        let l = x.len();
        (0..l)
            .map(|m| {
                let (mut re, mut im) = (0.0, 0.0);
                for (t, &v) in x.iter().enumerate() {
                    let a = -2.0 * PI * ((m * t) % l) as f64 / l as f64;
                    re += v * a.cos();
                    im += v * a.sin();
                }
                re.hypot(im)
            })
            .collect()
    }

    fn zero_phase_multisine(harmonics: std::ops::RangeInclusive<usize>, l: usize) -> Vec<f64> {
        (0..l)
            .map(|t| {
                harmonics
                    .clone()
                    .map(|k| (2.0 * PI * (k * t) as f64 / l as f64).cos())
                    .sum()
            })
            .collect()
    }

    #[test]
    fn schroeder_multisine_has_low_crest_factor_and_zero_phase_does_not() {
        // Period 20 s at 10 Hz = 200 samples; band 0.1..1.0 Hz = harmonics 2..=20 (19 lines).
        let x = multisine(0.1, 1.0, 20.0, 1.0, 0.0, 10.0, 20.0).unwrap();
        let cf = crest_factor(&x);
        assert!(cf < 2.0, "Schroeder crest factor {cf}");
        let z = zero_phase_multisine(2..=20, 200);
        let cz = crest_factor(&z);
        // Equal phases: peak K at t = 0, RMS √(K/2) → √(2K) = √38 ≈ 6.2.
        assert!(
            (cz - (38.0_f64).sqrt()).abs() < 1e-9,
            "zero-phase crest factor {cz}"
        );
        assert!(cz > 2.0 * cf);

        // Ten lines exactly, starting from the fundamental.
        let x = multisine(0.0, 1.0, 10.0, 1.0, 0.0, 10.0, 10.0).unwrap();
        assert!(crest_factor(&x) < 2.0, "{}", crest_factor(&x));
        assert!(crest_factor(&zero_phase_multisine(1..=10, 100)) > 4.0);
    }

    #[test]
    fn multisine_dft_has_equal_energy_only_at_the_chosen_lines() {
        // 200 samples per period, band [0.15, 0.82] Hz with f0 = 0.05 Hz → k = 3..=16.
        let x = multisine(0.15, 0.82, 20.0, 2.0, 5.0, 10.0, 20.0).unwrap();
        assert_eq!(x.len(), 200);
        let mean = x.iter().sum::<f64>() / 200.0;
        assert!((mean - 5.0).abs() < 1e-12, "mean {mean}");
        let mag = dft_mag(&x.iter().map(|v| v - 5.0).collect::<Vec<_>>());
        let line_mag = mag[3];
        assert!(line_mag > 1.0);
        for (m, &a) in mag.iter().enumerate().take(101) {
            if (3..=16).contains(&m) {
                assert!(
                    (a - line_mag).abs() < 1e-9 * line_mag,
                    "line {m}: {a} vs {line_mag}"
                );
            } else {
                assert!(a < 1e-9 * line_mag, "off-line bin {m} has {a}");
            }
        }
    }

    #[test]
    fn multisine_matches_the_schroeder_formula_and_scaling() {
        // 3 periods of 64 samples; band covers harmonics 2..=6 (K = 5).
        let (l, fs) = (64usize, 8.0);
        let x = multisine(0.25, 0.75, 8.0, 3.0, -1.0, fs, 24.0).unwrap();
        assert_eq!(x.len(), 3 * l);
        let k_count = 5.0;
        let raw: Vec<f64> = (0..3 * l)
            .map(|t| {
                (2..=6)
                    .enumerate()
                    .map(|(i, k)| {
                        let i = (i + 1) as f64;
                        let phi = -PI * i * (i - 1.0) / k_count;
                        (2.0 * PI * (k * t) as f64 / l as f64 + phi).cos()
                    })
                    .sum()
            })
            .collect();
        let peak = raw.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        for (t, (&a, &r)) in x.iter().zip(&raw).enumerate() {
            assert!((a - (-1.0 + 3.0 * r / peak)).abs() < 1e-12, "sample {t}");
        }
        let dev_peak = x.iter().fold(0.0_f64, |m, v| m.max((v + 1.0).abs()));
        assert!((dev_peak - 3.0).abs() < 1e-12, "peak deviation {dev_peak}");
        // Periodic: the three periods are identical.
        assert_eq!(x[..l], x[l..2 * l]);
    }

    #[test]
    fn non_integer_period_is_synthesised_directly_and_scaled_exactly() {
        // 10.5 samples per period; harmonics 1..=3.
        let x = multisine(0.0, 0.3, 10.5, 2.0, 0.0, 1.0, 42.0).unwrap();
        assert_eq!(x.len(), 42);
        let peak = x.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        assert!((peak - 2.0).abs() < 1e-12);
        // Periodic over two periods (21 samples).
        for t in 0..21 {
            assert!((x[t] - x[t + 21]).abs() < 1e-9, "sample {t}");
        }
    }

    #[test]
    fn multisine_reports_each_invalid_field() {
        let f = |lo: f64, hi: f64, p: f64, a: f64, fs: f64, d: f64| {
            multisine(lo, hi, p, a, 0.0, fs, d)
                .unwrap_err()
                .field()
                .to_owned()
        };
        assert_eq!(f(-0.1, 1.0, 10.0, 1.0, 10.0, 10.0), "f_lo_hz");
        assert_eq!(f(1.0, 0.5, 10.0, 1.0, 10.0, 10.0), "f_hi_hz");
        assert_eq!(f(0.1, 5.0, 10.0, 1.0, 10.0, 10.0), "f_hi_hz"); // at Nyquist
        assert_eq!(f(0.11, 0.19, 10.0, 1.0, 10.0, 10.0), "f_hi_hz"); // no harmonic of 0.1 Hz
        assert_eq!(f(0.1, f64::NAN, 10.0, 1.0, 10.0, 10.0), "f_hi_hz");
        assert_eq!(f(0.1, 1.0, 0.0, 1.0, 10.0, 10.0), "period_s");
        assert_eq!(f(0.1, 1.0, 20.0, 1.0, 10.0, 10.0), "period_s"); // longer than run
        assert_eq!(f(0.1, 1.0, 10.0, -1.0, 10.0, 10.0), "amplitude");
        assert_eq!(f(0.1, 1.0, 10.0, 1.0, 0.0, 10.0), "sample_rate_hz");
        assert_eq!(f(0.1, 1.0, 10.0, 1.0, 10.0, -10.0), "duration_s");
        assert_eq!(
            multisine(0.1, 1.0, 10.0, 1.0, f64::NAN, 10.0, 10.0)
                .unwrap_err()
                .field(),
            "offset"
        );
        // Band edges exactly on harmonics are included.
        let x = multisine(0.1, 0.1, 10.0, 1.0, 0.0, 10.0, 10.0).unwrap();
        let expected: Vec<f64> = (0..100)
            .map(|t| (2.0 * PI * t as f64 / 100.0).cos())
            .collect();
        for (a, b) in x.iter().zip(&expected) {
            assert!((a - b).abs() < 1e-12);
        }
    }

    #[test]
    fn crest_factor_of_known_signals() {
        let sine: Vec<f64> = (0..1000)
            .map(|t| 3.0 + (2.0 * PI * t as f64 / 100.0).sin())
            .collect();
        assert!((crest_factor(&sine) - 2f64.sqrt()).abs() < 1e-3);
        let binary: Vec<f64> = (0..100)
            .map(|t| if t % 2 == 0 { 4.0 } else { -4.0 })
            .collect();
        assert!((crest_factor(&binary) - 1.0).abs() < 1e-12);
        assert!(crest_factor(&[]).is_nan());
        assert!(crest_factor(&[2.0, 2.0, 2.0]).is_nan());
    }

    #[test]
    fn random_binary_is_two_valued_deterministic_and_balanced() {
        let x = random_binary(0.1, 1.5, 2.0, 77, 10.0, 2000.0).unwrap();
        assert_eq!(x.len(), 20_000);
        assert!(x.iter().all(|&v| v == 3.5 || v == 0.5));
        assert_eq!(x, random_binary(0.1, 1.5, 2.0, 77, 10.0, 2000.0).unwrap());
        assert_ne!(x, random_binary(0.1, 1.5, 2.0, 78, 10.0, 2000.0).unwrap());
        // Fair coin over 20 000 chips: the share of highs is within 4σ (σ ≈ 0.0035).
        let highs = x.iter().filter(|&&v| v == 3.5).count() as f64 / 20_000.0;
        assert!((highs - 0.5).abs() < 0.015, "share of highs {highs}");
        // Independent chips: lag-1 correlation of the ±1 sequence is near 0.
        let s: Vec<f64> = x
            .iter()
            .map(|&v| if v > 2.0 { 1.0 } else { -1.0 })
            .collect();
        let r1 = s.windows(2).map(|w| w[0] * w[1]).sum::<f64>() / 19_999.0;
        assert!(r1.abs() < 0.03, "lag-1 correlation {r1}");
    }

    #[test]
    fn random_binary_holds_chips_for_the_clock_period() {
        // 4 samples per chip: values change only at multiples of 4, and the
        // held chips equal the one-sample-per-chip sequence of the same seed.
        let x = random_binary(0.4, 1.0, 0.0, 5, 10.0, 100.0).unwrap();
        let chips = random_binary(0.1, 1.0, 0.0, 5, 10.0, 25.0).unwrap();
        assert_eq!(x.len(), 1000);
        for (k, &v) in x.iter().enumerate() {
            assert_eq!(v, chips[k / 4], "sample {k}");
        }
    }

    #[test]
    fn random_binary_reports_each_invalid_field() {
        let f = |tc: f64, a: f64, fs: f64, d: f64| {
            random_binary(tc, a, 0.0, 1, fs, d)
                .unwrap_err()
                .field()
                .to_owned()
        };
        assert_eq!(f(0.05, 1.0, 10.0, 10.0), "clock_period_s");
        assert_eq!(f(11.0, 1.0, 10.0, 10.0), "clock_period_s");
        assert_eq!(f(f64::INFINITY, 1.0, 10.0, 10.0), "clock_period_s");
        assert_eq!(f(0.5, -1.0, 10.0, 10.0), "amplitude");
        assert_eq!(f(0.5, 1.0, -10.0, 10.0), "sample_rate_hz");
        assert_eq!(f(0.5, 1.0, 10.0, 0.0), "duration_s");
        assert_eq!(
            random_binary(0.5, 1.0, f64::NAN, 1, 10.0, 10.0)
                .unwrap_err()
                .field(),
            "offset"
        );
    }
}
