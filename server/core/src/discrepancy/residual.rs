//! Residual analysis: whiteness (autocorrelation within ±2.576/√N, zero
//! crossings — thesis sec. 2.6) and the residual PSD per band against a
//! noise floor taken from the high-frequency part, where a low-pass vessel
//! leaves only sensor noise.

use serde::{Deserialize, Serialize};

use crate::spectra::{WelchConfig, welch};
use crate::validation::correlation::autocorrelation;
use crate::validation::residuals::zero_crossings;

/// Whiteness of one residual channel (pooled over runs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct Whiteness {
    /// Samples N.
    pub n: usize,
    /// 99 % bound 2.576/√N on the autocorrelation of a white sequence.
    pub bound: f64,
    /// Lags tested (1..=lags).
    pub lags: usize,
    /// Lags whose autocorrelation leaves the bound.
    pub lags_outside: usize,
    /// Largest |ρ(l)| over the tested lags.
    pub max_abs_autocorr: f64,
    /// Sign changes of the residual.
    pub zero_crossings: usize,
    /// 99 % range of zero crossings of a white sequence, (N−1)/2 ± 2.576·√(N−1)/2.
    pub expected_zero_crossings: [f64; 2],
    /// Fewer than 5 % of lags outside and crossings in range.
    pub white: bool,
}

/// Whiteness of residual runs `e` (NaN samples are dropped within a run),
/// pooled over runs: each run's autocorrelation and zero crossings come from
/// [`crate::validation::correlation::autocorrelation`] and
/// [`crate::validation::residuals::zero_crossings`] about the run's own
/// mean; ρ(l) is their energy-weighted mean.
pub fn whiteness(runs: &[Vec<f64>], lags: usize) -> Whiteness {
    let runs: Vec<Vec<f64>> = runs
        .iter()
        .map(|e| e.iter().copied().filter(|x| x.is_finite()).collect())
        .collect();
    let n: usize = runs.iter().map(Vec::len).sum();
    let mut num = vec![0.0; lags + 1];
    let mut energy = 0.0;
    let (mut zc, mut pairs) = (0, 0.0);
    for e in &runs {
        let mean = e.iter().sum::<f64>() / e.len().max(1) as f64;
        let c: Vec<f64> = e.iter().map(|x| x - mean).collect();
        if let Some(r) = autocorrelation(&c, lags) {
            let r0: f64 = c.iter().map(|x| x * x).sum();
            num.iter_mut().zip(&r).for_each(|(a, b)| *a += r0 * b);
            energy += r0;
        }
        let z = zero_crossings(&c);
        zc += z.count;
        pairs += 2.0 * z.expected;
    }
    let rho: Vec<f64> = num
        .iter()
        .map(|x| if energy > 0.0 { x / energy } else { 0.0 })
        .collect();
    let bound = 2.576 / (n.max(1) as f64).sqrt();
    let outside = rho.iter().skip(1).filter(|r| r.abs() > bound).count();
    let max_abs = rho.iter().skip(1).fold(0.0_f64, |m, r| m.max(r.abs()));
    let m = pairs.max(1.0);
    let expected = [
        m / 2.0 - 2.576 * m.sqrt() / 2.0,
        m / 2.0 + 2.576 * m.sqrt() / 2.0,
    ];
    let white = (outside as f64) <= 0.05 * lags as f64
        && (zc as f64) >= expected[0]
        && (zc as f64) <= expected[1];
    Whiteness {
        n,
        bound,
        lags,
        lags_outside: outside,
        max_abs_autocorr: max_abs,
        zero_crossings: zc,
        expected_zero_crossings: expected,
        white,
    }
}

/// Residual power of one band relative to the noise floor.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct BandPower {
    /// Lower edge (Hz).
    pub f_lo_hz: f64,
    /// Upper edge (Hz).
    pub f_hi_hz: f64,
    /// Mean PSD over the band / noise floor, in dB.
    pub excess_db: f64,
    /// Frequency of the band's largest PSD value (Hz).
    pub peak_hz: f64,
}

/// Residual spectrum of one channel in octave bands.
#[derive(Debug, Clone, PartialEq)]
pub struct ResidualSpectrum {
    /// White-noise level (units²/Hz) of the sensor noise: median of the
    /// whitened PSD above 70 % of Nyquist.
    pub floor: f64,
    /// Octave bands from Nyquist down to the lowest resolved frequency.
    pub bands: Vec<BandPower>,
    /// Log-log slope of the PSD over the lowest three octaves (−2 for a
    /// random walk, 0 for white).
    pub low_slope: f64,
}

/// Welch PSD of residual runs averaged over runs (same segment length),
/// split into octave bands against the noise floor.
///
/// The floor is shaped by the 1-step predictor: sensor noise n on ν leaves
/// e_{k+1} = n_{k+1} − Φ n_k, whose PSD is σ²·|1 − Φe^{−iω}|² (blue for Φ
/// near 1). σ² is taken from the part above 70 % of Nyquist, where a
/// low-pass vessel leaves nothing but that noise; `phi` = 0 gives a flat
/// floor.
pub fn residual_spectrum(runs: &[Vec<f64>], fs: f64, phi: f64) -> Option<ResidualSpectrum> {
    let runs: Vec<Vec<f64>> = runs
        .iter()
        .map(|e| {
            e.iter()
                .copied()
                .filter(|x| x.is_finite())
                .collect::<Vec<_>>()
        })
        .filter(|e| e.len() >= 64)
        .collect();
    let shortest = runs.iter().map(Vec::len).min()?;
    let mut nperseg = 16;
    while nperseg * 2 <= shortest / 4 && nperseg < 512 {
        nperseg *= 2;
    }
    let cfg = WelchConfig::hann(fs, nperseg);
    let mut psd: Option<(Vec<f64>, Vec<f64>)> = None;
    for e in &runs {
        let s = welch(e, &cfg).ok()?;
        match &mut psd {
            None => psd = Some((s.freqs, s.values)),
            Some((_, v)) => v.iter_mut().zip(&s.values).for_each(|(a, b)| *a += b),
        }
    }
    let (freqs, mut values) = psd?;
    values.iter_mut().for_each(|v| *v /= runs.len() as f64);
    let nyq = fs / 2.0;
    let shape = |f: f64| {
        let w = std::f64::consts::TAU * f / fs;
        (1.0 - 2.0 * phi * w.cos() + phi * phi).max(1e-12)
    };
    // Whitened PSD: the residual relative to the noise's own shape.
    values = freqs
        .iter()
        .zip(&values)
        .map(|(f, v)| v / shape(*f))
        .collect();
    let mut hi: Vec<f64> = freqs
        .iter()
        .zip(&values)
        .filter(|(f, _)| **f >= 0.7 * nyq)
        .map(|(_, v)| *v)
        .collect();
    hi.sort_by(|a, b| a.total_cmp(b));
    let floor = *hi.get(hi.len() / 2)?;
    let df = fs / nperseg as f64;
    let mut bands = Vec::new();
    let mut f_hi = nyq;
    while f_hi / 2.0 >= df {
        let f_lo = f_hi / 2.0;
        let inband: Vec<(f64, f64)> = freqs
            .iter()
            .zip(&values)
            .filter(|(f, _)| **f >= f_lo && **f < f_hi && **f > 0.0)
            .map(|(f, v)| (*f, *v))
            .collect();
        if !inband.is_empty() && floor > 0.0 {
            let mean = inband.iter().map(|x| x.1).sum::<f64>() / inband.len() as f64;
            let peak = inband
                .iter()
                .max_by(|a, b| a.1.total_cmp(&b.1))
                .map_or(f_lo, |x| x.0);
            bands.push(BandPower {
                f_lo_hz: f_lo,
                f_hi_hz: f_hi,
                excess_db: 10.0 * (mean / floor).log10(),
                peak_hz: peak,
            });
        }
        f_hi = f_lo;
    }
    bands.reverse();
    // Slope over the lowest three octaves (bins above DC).
    let f_top = df * 8.0;
    let pts: Vec<(f64, f64)> = freqs
        .iter()
        .zip(&values)
        .filter(|(f, v)| **f > 0.0 && **f <= f_top && **v > 0.0)
        .map(|(f, v)| (f.ln(), v.ln()))
        .collect();
    let low_slope = if pts.len() >= 3 {
        let mx = pts.iter().map(|p| p.0).sum::<f64>() / pts.len() as f64;
        let my = pts.iter().map(|p| p.1).sum::<f64>() / pts.len() as f64;
        let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
        let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
        if sxx > 0.0 { sxy / sxx } else { 0.0 }
    } else {
        0.0
    };
    Some(ResidualSpectrum {
        floor,
        bands,
        low_slope,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;

    #[test]
    fn white_noise_passes_and_a_random_walk_fails() {
        let mut r = SplitMix64::new(3);
        let e: Vec<f64> = (0..4000).map(|_| r.normal()).collect();
        let w = whiteness(std::slice::from_ref(&e), 30);
        assert!(w.white, "{w:?}");
        let mut acc = 0.0;
        let walk: Vec<f64> = e
            .iter()
            .map(|x| {
                acc += x;
                acc
            })
            .collect();
        let w = whiteness(std::slice::from_ref(&walk), 30);
        assert!(!w.white && w.lags_outside == 30);
        // The walk's spectrum rises ~20 dB/decade towards DC; white noise is flat.
        let s = residual_spectrum(&[walk], 10.0, 0.0).unwrap();
        assert!(s.low_slope < -1.5, "slope {}", s.low_slope);
        assert!(s.bands.first().unwrap().excess_db > 20.0);
        let s = residual_spectrum(std::slice::from_ref(&e), 10.0, 0.0).unwrap();
        assert!(
            s.bands.iter().all(|b| b.excess_db.abs() < 3.0),
            "{:?}",
            s.bands
        );
        // Differenced noise n_{k+1} − 0.95 n_k is blue, but white once shaped.
        let d: Vec<f64> = e.windows(2).map(|w| w[1] - 0.95 * w[0]).collect();
        let s = residual_spectrum(std::slice::from_ref(&d), 10.0, 0.95).unwrap();
        assert!(
            s.bands.iter().all(|b| b.excess_db.abs() < 3.0),
            "{:?}",
            s.bands
        );
        let s = residual_spectrum(&[d], 10.0, 0.0).unwrap();
        assert!(s.bands.first().unwrap().excess_db < -10.0);
    }
}
