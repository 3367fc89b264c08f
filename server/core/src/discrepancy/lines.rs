//! Narrow spectral lines in residuals: a tone the model leaves in every
//! run, whatever the run excites — the signature of an exogenous periodic
//! force (waves on a vehicle near the surface, vortex shedding from a
//! tether, a pump) that no term of the library represents.
//!
//! A line at bin k of the runs' averaged Welch PSD P̄ (Hann, half overlap,
//! linear detrend) is a local maximum that
//! - stands [`LINE_RATIO`] above the local background B(k), the median of
//!   P̄ over [`BACKGROUND_BINS`] bins (or a third of k) either side with the
//!   line's main lobe left out;
//! - is narrow: 3–6 bins away P̄ has fallen 10 dB below the peak (a Hann
//!   window's side lobes are 31 dB down) or back to within 5 dB of the
//!   background, which a resonance of misfit dynamics does not;
//! - stands out ([`RUN_RATIO`] over the run's own background) in at least
//!   [`RUN_SHARE`] of the runs one by one, with one size in all of them
//!   (largest over smallest ≤ [`STEADY_RATIO`]). A misfit of the
//!   input–output dynamics puts lines at the excitation's frequencies, as
//!   large as each run's excitation there — large in the runs that excite
//!   the DOF, small in holds and in runs that excite others; an exogenous
//!   force is the same in every run.
//!
//! The tone's amplitude is √(2 Σ (P̄ − B) Δf) over its main lobe: with
//! density scaling the PSD integrates to the mean square, A²/2 for a
//! sinusoid of amplitude A.

use serde::{Deserialize, Serialize};

use crate::spectra::{Detrend, WelchConfig, welch};

/// Least height of a line over the local background in the averaged PSD
/// (7.8 dB; a tone between two bins shares its power between them).
pub const LINE_RATIO: f64 = 6.0;
/// A bin beside the main lobe within this factor of the background (5 dB)
/// counts as background when judging narrowness.
const NEAR_BACKGROUND: f64 = 3.0;
/// Least height over a single run's own background (6 dB) for the run to
/// count as showing the line.
pub const RUN_RATIO: f64 = 4.0;
/// Least share of the runs that must show the line one by one.
pub const RUN_SHARE: f64 = 0.8;
/// Half-width of the background window in bins (at least; a third of the
/// line's bin index at higher frequencies, about half an octave).
pub const BACKGROUND_BINS: usize = 8;
/// Half-width of the Hann window's main lobe in bins (a tone between two
/// bins spreads over ±2).
const LOBE: usize = 2;
/// Largest ratio of the line's amplitude in one run to that in another:
/// an exogenous force is the same in every run (the runs' own estimates
/// scatter by some 20 %), a misfit at an excitation frequency follows each
/// run's excitation (tenfold and more between runs).
pub const STEADY_RATIO: f64 = 3.0;
/// Fewest runs a line can be judged on.
const MIN_RUNS: usize = 2;
/// Fewest samples of a run that enters the analysis.
const MIN_SAMPLES: usize = 128;

/// A narrow line in a residual.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct SpectralLine {
    /// Frequency of the line (Hz): its largest bin, moved by the vertex of
    /// the log PSD's parabola through it and its neighbours.
    pub frequency_hz: f64,
    /// Bin spacing of the analysis (Hz).
    pub resolution_hz: f64,
    /// Height of the averaged PSD over its local background at the line (dB).
    pub excess_db: f64,
    /// Amplitude of the tone in the analysed signal (the signal's units).
    pub amplitude: f64,
    /// Smallest and largest amplitude of the line in a single run.
    pub run_amplitudes: [f64; 2],
    /// Runs that show the line on their own.
    pub runs_with_line: usize,
    /// Runs analysed.
    pub runs: usize,
}

/// The runs' Welch PSDs on one segment length, and their average.
struct RunSpectra {
    /// Bin spacing (Hz).
    df: f64,
    /// Per run its PSD and segment count (the average's weight).
    runs: Vec<(Vec<f64>, f64)>,
    /// Segment-weighted average PSD.
    mean: Vec<f64>,
}

/// [`RunSpectra`] of `runs` (samples at `fs` Hz; non-finite samples
/// dropped, runs shorter than 128 samples left out). Segment length: the
/// largest power of two within the median run length, 64 to 2048 samples
/// (a slow tone needs the resolution; the runs supply the averaging).
/// `None` below two usable runs.
fn run_spectra(runs: &[Vec<f64>], fs: f64) -> Option<RunSpectra> {
    let runs: Vec<Vec<f64>> = runs
        .iter()
        .map(|e| e.iter().copied().filter(|x| x.is_finite()).collect())
        .filter(|e: &Vec<f64>| e.len() >= MIN_SAMPLES)
        .collect();
    if runs.len() < MIN_RUNS || !(fs.is_finite() && fs > 0.0) {
        return None;
    }
    let mut lens: Vec<usize> = runs.iter().map(Vec::len).collect();
    lens.sort_unstable();
    let median = lens[lens.len() / 2];
    let mut nperseg = 64;
    while nperseg * 2 <= median && nperseg < 2048 {
        nperseg *= 2;
    }
    let cfg = WelchConfig {
        detrend: Detrend::Linear,
        ..WelchConfig::hann(fs, nperseg)
    };
    let spectra: Vec<(Vec<f64>, f64)> = runs
        .iter()
        .filter(|e| e.len() >= nperseg)
        .filter_map(|e| {
            let s = welch(e, &cfg).ok()?;
            Some((s.values, cfg.n_segments(e.len()) as f64))
        })
        .filter(|(v, _)| v.iter().all(|x| x.is_finite()))
        .collect();
    if spectra.len() < MIN_RUNS {
        return None;
    }
    let nf = spectra[0].0.len();
    let total: f64 = spectra.iter().map(|s| s.1).sum();
    let mean: Vec<f64> = (0..nf)
        .map(|k| spectra.iter().map(|(v, w)| v[k] * w).sum::<f64>() / total)
        .collect();
    Some(RunSpectra {
        df: fs / nperseg as f64,
        runs: spectra,
        mean,
    })
}

/// Amplitude of a tone at bin `k` of a PSD: √(2 Σ (P − B) Δf) over the main
/// lobe, B the local background.
fn amplitude_at(mean: &[f64], k: usize, b: f64, df: f64) -> f64 {
    let lo = k.saturating_sub(LOBE + 1);
    let hi = (k + LOBE + 1).min(mean.len() - 1);
    let power: f64 = (lo..=hi).map(|j| (mean[j] - b).max(0.0)).sum::<f64>() * df;
    (2.0 * power).sqrt()
}

/// The narrow lines of `runs` (samples at `fs` Hz; see [`RunSpectra`] for
/// what is read), strongest first.
pub fn spectral_lines(runs: &[Vec<f64>], fs: f64) -> Vec<SpectralLine> {
    let Some(RunSpectra {
        df,
        runs: spectra,
        mean,
    }) = run_spectra(runs, fs)
    else {
        return Vec::new();
    };
    let nf = mean.len();
    let mut lines: Vec<(usize, SpectralLine)> = Vec::new();
    for k in (LOBE + 2)..nf.saturating_sub(LOBE + 4) {
        let p = mean[k];
        if p.is_nan() || p <= 0.0 || p < mean[k - 1] || p < mean[k + 1] {
            continue;
        }
        let Some(b) = background(&mean, k) else {
            continue;
        };
        if b.is_nan() || b <= 0.0 || p < LINE_RATIO * b {
            continue;
        }
        let narrow = (LOBE + 1..=LOBE + 4)
            .flat_map(|d| [k.checked_sub(d), Some(k + d)])
            .flatten()
            .filter(|&j| j < nf)
            .all(|j| mean[j] < (p / 10.0).max(NEAR_BACKGROUND * b));
        if !narrow {
            continue;
        }
        let shown = spectra
            .iter()
            .filter(|(v, _)| {
                let peak = v[k - 1].max(v[k]).max(v[k + 1]);
                background(v, k).is_some_and(|bg| bg > 0.0 && peak >= RUN_RATIO * bg)
            })
            .count();
        if (shown as f64) < RUN_SHARE * spectra.len() as f64 {
            continue;
        }
        // An exogenous force has one size in every run, whatever the run
        // excites; a misfit at an excitation frequency scales with each
        // run's excitation there.
        let sizes: Vec<f64> = spectra
            .iter()
            .map(|(v, _)| background(v, k).map_or(0.0, |bg| amplitude_at(v, k, bg, df)))
            .collect();
        let smallest = sizes.iter().copied().fold(f64::INFINITY, f64::min);
        let largest = sizes.iter().copied().fold(0.0, f64::max);
        if !(smallest > 0.0 && largest <= STEADY_RATIO * smallest) {
            continue;
        }
        lines.push((
            k,
            SpectralLine {
                frequency_hz: (k as f64 + vertex(&mean, k)) * df,
                resolution_hz: df,
                excess_db: 10.0 * (p / b).log10(),
                amplitude: amplitude_at(&mean, k, b, df),
                run_amplitudes: [smallest, largest],
                runs_with_line: shown,
                runs: spectra.len(),
            },
        ));
    }
    // One line per main lobe: the strongest.
    lines.sort_by(|a, b| b.1.excess_db.total_cmp(&a.1.excess_db));
    let mut kept: Vec<(usize, SpectralLine)> = Vec::new();
    for (k, l) in lines {
        if kept.iter().all(|(j, _)| j.abs_diff(k) > 2 * LOBE) {
            kept.push((k, l));
        }
    }
    kept.into_iter().map(|(_, l)| l).collect()
}

/// Offset (bins, within ±½) of a peak at bin `k` from the vertex of the
/// parabola through the log PSD at k − 1, k, k + 1: a tone between two bins
/// is placed to a fraction of a bin (a Hann window's lobe is near Gaussian,
/// whose log is a parabola).
fn vertex(v: &[f64], k: usize) -> f64 {
    let (a, b, c) = (v[k - 1].ln(), v[k].ln(), v[k + 1].ln());
    let curvature = a - 2.0 * b + c;
    if !curvature.is_finite() || curvature >= 0.0 {
        return 0.0;
    }
    (0.5 * (a - c) / curvature).clamp(-0.5, 0.5)
}

/// Median of `v` over the background window of bin `k`: ±max(8, k/3)
/// bins, the line's main lobe ±(LOBE + 1) and DC left out.
fn background(v: &[f64], k: usize) -> Option<f64> {
    let w = BACKGROUND_BINS.max(k / 3);
    let lo = k.saturating_sub(w).max(1);
    let hi = (k + w).min(v.len() - 1);
    let mut around: Vec<f64> = (lo..=hi)
        .filter(|j| j.abs_diff(k) > LOBE + 1)
        .map(|j| v[j])
        .collect();
    if around.len() < 4 {
        return None;
    }
    around.sort_by(f64::total_cmp);
    Some(around[around.len() / 2])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;

    fn noise(rng: &mut SplitMix64, n: usize, sigma: f64) -> Vec<f64> {
        (0..n).map(|_| sigma * rng.normal()).collect()
    }

    /// Coloured noise: white noise through a first-order low-pass, as a
    /// misfit residual looks.
    fn coloured(rng: &mut SplitMix64, n: usize, sigma: f64, a: f64) -> Vec<f64> {
        let mut y = 0.0;
        (0..n)
            .map(|_| {
                y = a * y + sigma * rng.normal();
                y
            })
            .collect()
    }

    #[test]
    fn a_tone_in_every_run_is_found_with_its_frequency_and_amplitude() {
        let mut rng = SplitMix64::new(7);
        let fs = 10.0;
        let (f0, amp) = (0.0973, 0.05);
        let runs: Vec<Vec<f64>> = (0..8)
            .map(|r| {
                let n = 2400 + 300 * r;
                let phase = r as f64;
                coloured(&mut rng, n, 0.02, 0.9)
                    .into_iter()
                    .enumerate()
                    .map(|(k, e)| {
                        e + amp * (std::f64::consts::TAU * f0 * k as f64 / fs + phase).sin()
                    })
                    .collect()
            })
            .collect();
        let lines = spectral_lines(&runs, fs);
        assert!(!lines.is_empty(), "no line found");
        let l = &lines[0];
        assert!(
            (l.frequency_hz - f0).abs() <= 0.25 * l.resolution_hz,
            "line at {} Hz, resolution {}",
            l.frequency_hz,
            l.resolution_hz
        );
        assert!(
            (l.amplitude / amp - 1.0).abs() < 0.15,
            "amplitude {} against {amp}",
            l.amplitude
        );
        assert_eq!(l.runs, 8);
        assert!(l.runs_with_line >= 7, "{} runs show it", l.runs_with_line);
        assert_eq!(lines.len(), 1, "{lines:?}");
    }

    #[test]
    fn white_and_coloured_noise_give_no_line() {
        let mut rng = SplitMix64::new(11);
        for seed_runs in 0..20 {
            let runs: Vec<Vec<f64>> = (0..6)
                .map(|r| {
                    if (r + seed_runs) % 2 == 0 {
                        noise(&mut rng, 3000, 1.0)
                    } else {
                        coloured(&mut rng, 3000, 1.0, 0.95)
                    }
                })
                .collect();
            let lines = spectral_lines(&runs, 10.0);
            assert!(lines.is_empty(), "case {seed_runs}: {lines:?}");
        }
    }

    #[test]
    fn a_line_in_one_run_only_is_not_a_disturbance() {
        // A square-wave misfit: lines at one run's own harmonics.
        let mut rng = SplitMix64::new(3);
        let fs = 10.0;
        let runs: Vec<Vec<f64>> = (0..6)
            .map(|r| {
                let mut e = noise(&mut rng, 3000, 0.01);
                if r == 0 {
                    for (k, x) in e.iter_mut().enumerate() {
                        *x += 0.2 * (std::f64::consts::TAU * 0.05 * k as f64 / fs).sin();
                    }
                }
                e
            })
            .collect();
        assert!(spectral_lines(&runs, fs).is_empty());
    }

    #[test]
    fn a_line_whose_size_follows_each_runs_excitation_is_not_a_disturbance() {
        // The same frequency in every run (a shared square-wave clock), as
        // large as each run's excitation: 0.02 to 0.5.
        let mut rng = SplitMix64::new(13);
        let fs = 10.0;
        let sizes = [0.5, 0.02, 0.04, 0.3, 0.03, 0.05];
        let runs: Vec<Vec<f64>> = sizes
            .iter()
            .map(|a| {
                noise(&mut rng, 3000, 0.002)
                    .into_iter()
                    .enumerate()
                    .map(|(k, e)| e + a * (std::f64::consts::TAU * 0.039 * k as f64 / fs).sin())
                    .collect()
            })
            .collect();
        assert!(spectral_lines(&runs, fs).is_empty());
        // The same runs with one size: a disturbance.
        let steady: Vec<Vec<f64>> = (0..6)
            .map(|_| {
                noise(&mut rng, 3000, 0.002)
                    .into_iter()
                    .enumerate()
                    .map(|(k, e)| e + 0.1 * (std::f64::consts::TAU * 0.039 * k as f64 / fs).sin())
                    .collect()
            })
            .collect();
        let lines = spectral_lines(&steady, fs);
        assert_eq!(lines.len(), 1, "{lines:?}");
        assert!(lines[0].run_amplitudes[1] <= 1.3 * lines[0].run_amplitudes[0]);
    }

    #[test]
    fn a_broad_resonance_is_not_a_line() {
        // Noise through a lightly damped second-order filter at 0.5 Hz
        // (ζ = 0.1): a bump some 0.1 Hz wide, far above its surroundings.
        let mut rng = SplitMix64::new(5);
        let fs = 10.0;
        let w = std::f64::consts::TAU * 0.5 / fs;
        let r = (-0.1 * w).exp();
        let (a1, a2) = (2.0 * r * w.cos(), -r * r);
        let runs: Vec<Vec<f64>> = (0..6)
            .map(|_| {
                let (mut y1, mut y2) = (0.0, 0.0);
                (0..3000)
                    .map(|_| {
                        let y = a1 * y1 + a2 * y2 + rng.normal();
                        y2 = y1;
                        y1 = y;
                        y
                    })
                    .collect()
            })
            .collect();
        assert!(spectral_lines(&runs, fs).is_empty());
    }

    #[test]
    fn too_few_or_too_short_runs_give_nothing() {
        let tone: Vec<f64> = (0..4000).map(|k| (0.3 * k as f64).sin()).collect();
        assert!(spectral_lines(std::slice::from_ref(&tone), 10.0).is_empty());
        assert!(spectral_lines(&[tone[..100].to_vec(), tone[..100].to_vec()], 10.0).is_empty());
        assert!(spectral_lines(&[tone.clone(), tone], f64::NAN).is_empty());
    }
}
