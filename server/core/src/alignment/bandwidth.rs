//! Width of the refinement's Gaussian prefilter from the band the two logs
//! share: the coherence of the coarsely aligned shared channel (Welch,
//! [`crate::spectra::coherence`]) says up to which frequency both computers
//! saw the same signal; above it there is only noise, which the prefilter
//! should remove. Misalignment by the remaining fraction of a grid sample
//! rotates the cross-spectrum's phase but not its magnitude, so it does not
//! disturb the coherence.

use crate::spectra::{Detrend, WelchConfig, coherence};

/// Coherence above which a frequency counts as shared.
const SHARED_COHERENCE: f64 = 0.5;

/// The highest frequency (Hz) at which the overlapping parts `a` and `b`
/// (equal length, sampled at `fs`) have coherence ≥ 0.5, or `None` when
/// they are too short (< 128 samples) or share no band.
pub(crate) fn shared_band_hz(a: &[f64], b: &[f64], fs: f64) -> Option<f64> {
    let n = a.len().min(b.len());
    if n < 128 {
        return None;
    }
    // About 15 half-overlapping segments: enough averaging for a coherence
    // bias (~1/K) well below the threshold.
    let nperseg = (1usize << (usize::BITS - 1 - (n / 8).leading_zeros())).clamp(16, 4096);
    let cfg = WelchConfig::hann(fs, nperseg).with_detrend(Detrend::Linear);
    let coh = coherence(&a[..n], &b[..n], &cfg).ok()?;
    coh.freqs
        .iter()
        .zip(&coh.values)
        .skip(1)
        .filter(|(_, c)| **c >= SHARED_COHERENCE)
        .map(|(f, _)| *f)
        .next_back()
}

/// Gaussian width (s) whose power response is halved at `f_hz`:
/// `exp(−(2π f σ)²) = ½`.
pub(crate) fn sigma_for_cutoff(f_hz: f64) -> f64 {
    std::f64::consts::LN_2.sqrt() / (2.0 * std::f64::consts::PI * f_hz)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_band_of_a_shared_low_pass_signal() {
        // Shared sinusoids below 0.3 Hz, independent noise in each log.
        let fs = 10.0;
        let n = 6000;
        let mut state = 1u64;
        let mut noise = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.6
        };
        let s: Vec<f64> = (0..n)
            .map(|k| {
                let t = k as f64 / fs;
                (0..30)
                    .map(|i| {
                        (2.0 * std::f64::consts::PI * 0.01 * (i + 1) as f64 * t + i as f64).sin()
                    })
                    .sum::<f64>()
                    * 0.2
            })
            .collect();
        let a: Vec<f64> = s.iter().map(|v| v + noise()).collect();
        let b: Vec<f64> = s.iter().map(|v| v + noise()).collect();
        let f = shared_band_hz(&a, &b, fs).unwrap();
        assert!((0.25..0.4).contains(&f), "{f}");
        let sigma = sigma_for_cutoff(f);
        let h = (-(2.0 * std::f64::consts::PI * f * sigma).powi(2)).exp();
        assert!((h - 0.5).abs() < 1e-12);
        assert_eq!(shared_band_hz(&a[..100], &b[..100], fs), None);
    }
}
