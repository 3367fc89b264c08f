//! What a schedule offers the estimator: persistence-of-excitation order as
//! the logger will see it, power spectrum and usable band, the power the
//! logger cannot resolve, and the realised peak and slew.

use serde::{Deserialize, Serialize};

use crate::signals;
use crate::spectra::{self, Spectrum, WelchConfig};

/// Band rule: frequencies (DC excluded) whose PSD lies within this factor of
/// the peak, i.e. within 10 dB. For a PRBS with clock T_c the upper edge is
/// ≈ 0.74/T_c (sinc² = 0.1); for a square wave it spans the 1st to 3rd harmonic.
pub const BAND_FRACTION_OF_PEAK: f64 = 0.1;

/// Spectral and excitation figures of one channel.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct ChannelAnalysis {
    /// Persistence-of-excitation order of the deviation from the operating
    /// point, sampled at the logger rate, capped at `pe_cap`.
    pub pe_order: usize,
    /// Cap of the PE computation (`pe_order == pe_cap` means "at least").
    pub pe_cap: usize,
    /// PE order this experiment needs (2 per identified DOF; 1 for static runs).
    pub pe_required: usize,
    /// Usable band [low, high] in Hz (within 10 dB of the PSD peak); none for
    /// static runs, whose single step has no band to speak of.
    pub band_hz: Option<[f64; 2]>,
    /// Fraction of the signal power above the logger's Nyquist frequency.
    pub power_above_logger_nyquist: f64,
    /// Largest |deviation| from the operating point.
    pub peak_deviation: f64,
    /// Largest slew rate (unit/s).
    pub max_slew: f64,
}

/// One-sided PSD of a schedule channel: a Hann-windowed periodogram over the
/// whole run (Welch with one segment), so the resolution is 1/duration — a
/// schedule is deterministic, there is no noise to average.
pub fn schedule_spectrum(x: &[f64], fs: f64) -> Result<Spectrum, spectra::SpectraError> {
    spectra::welch(x, &WelchConfig::hann(fs, x.len()).with_noverlap(0))
}

/// Usable band of a spectrum by the rule of [`BAND_FRACTION_OF_PEAK`].
pub fn usable_band(s: &Spectrum) -> Option<[f64; 2]> {
    let peak = s.values.iter().skip(1).cloned().fold(0.0, f64::max);
    if peak <= 0.0 {
        return None;
    }
    let keep: Vec<usize> = (1..s.values.len())
        .filter(|&i| s.values[i] >= BAND_FRACTION_OF_PEAK * peak)
        .collect();
    Some([s.freqs[*keep.first()?], s.freqs[*keep.last()?]])
}

/// Analyses a sampled channel. `offset` is the operating point; the logger
/// sees every `decimation`-th sample.
pub fn analyse(
    x: &[f64],
    offset: f64,
    fs: f64,
    decimation: usize,
    logger_rate_hz: f64,
    pe_required: usize,
    pe_cap: usize,
) -> ChannelAnalysis {
    let dev: Vec<f64> = x.iter().map(|v| v - offset).collect();
    let logged: Vec<f64> = dev.iter().step_by(decimation.max(1)).cloned().collect();
    let cap = pe_cap.min(logged.len() / 2).max(1);
    let pe_order = signals::pe_order(&logged, cap, signals::DEFAULT_PE_TOL).unwrap_or(0);
    let peak_deviation = dev.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let max_slew = x
        .windows(2)
        .fold(0.0_f64, |m, w| m.max((w[1] - w[0]).abs() * fs));
    let (band_hz, power_above_logger_nyquist) = match schedule_spectrum(x, fs) {
        Ok(s) if x.len() >= 8 && pe_required > 1 => {
            let total: f64 = s.values.iter().skip(1).sum();
            let above: f64 = s
                .freqs
                .iter()
                .zip(&s.values)
                .skip(1)
                .filter(|(f, _)| **f > logger_rate_hz / 2.0)
                .map(|(_, v)| v)
                .sum();
            let frac = if total > 0.0 { above / total } else { 0.0 };
            (usable_band(&s), frac)
        }
        _ => (None, 0.0),
    };
    ChannelAnalysis {
        pe_order,
        pe_cap: cap,
        pe_required,
        band_hz,
        power_above_logger_nyquist,
        peak_deviation,
        max_slew,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prbs_band_edge_follows_sinc_squared() {
        // One period of an order-9 m-sequence, clock 1 s, sampled at 20 Hz:
        // the envelope sinc²(f·T_c) falls to 0.1 at f ≈ 0.74 Hz.
        let seq = signals::mls(9, 1).unwrap();
        let fs = 20.0;
        let x: Vec<f64> = (0..seq.len() * 20)
            .map(|k| f64::from(seq[k / 20]))
            .collect();
        let s = schedule_spectrum(&x, fs).unwrap();
        let [lo, hi] = usable_band(&s).unwrap();
        assert!(lo < 0.01, "lower edge {lo}");
        assert!((hi - 0.74).abs() < 0.06, "upper edge {hi}");
    }

    #[test]
    fn square_band_spans_first_to_third_harmonic() {
        // Period 10 s for 200 s at 10 Hz: lines at 0.1, 0.3 (−9.5 dB), 0.5 (−14 dB) Hz.
        let fs = 10.0;
        let x: Vec<f64> = (0..2000)
            .map(|k| if (k / 50) % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let s = schedule_spectrum(&x, fs).unwrap();
        let [lo, hi] = usable_band(&s).unwrap();
        assert!((lo - 0.1).abs() < 0.011, "lower {lo}");
        assert!((hi - 0.3).abs() < 0.011, "upper {hi}");
    }

    #[test]
    fn analysis_sees_the_logger() {
        // A signal alternating every controller sample has all its power above
        // the Nyquist frequency of a logger at half the rate, and the logger
        // sees a constant: PE order 1.
        let x: Vec<f64> = (0..400)
            .map(|k| if k % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let a = analyse(&x, 0.0, 20.0, 2, 10.0, 2, 10);
        assert_eq!(a.pe_order, 1);
        assert!(a.power_above_logger_nyquist > 0.99);
        assert_eq!(a.peak_deviation, 1.0);
        assert!((a.max_slew - 40.0).abs() < 1e-9);
    }
}
