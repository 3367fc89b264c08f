//! Clock offset between two logs from a channel both recorded.
//!
//! Convention: **`offset_s` is added to navigation time stamps to put them on
//! the control clock**; the nav sample stamped `t_nav` corresponds to control
//! time `t_nav + offset_s`, so `nav_x(t − offset_s) ≈ control_x(t)`.
//!
//! Method:
//! 1. both records are resampled (linear interpolation) onto a uniform grid
//!    of step `h = 1 / rate_hz`, each from its own first stamp, and their mean
//!    and linear trend are removed;
//! 2. the normalized cross-correlation — Pearson's coefficient over the
//!    samples that overlap at each lag, each side's mean and linear trend
//!    over that overlap removed — is computed for every admissible lag from
//!    one zero-padded real FFT pair and prefix sums, O(n log n);
//! 3. the peak is the lag of highest *evidence* `ρ·√(overlap / shorter
//!    record)` (so a chance correlation over a short overlap does not win),
//!    refined to the highest `ρ` within its main lobe; the highest evidence
//!    outside that lobe gives the ambiguity ratio (see `xcorr.rs`);
//! 4. the offset is refined continuously within ±1.5 samples (of the grid
//!    or of the slower log, whichever is longer) by
//!    minimizing the mismatch between the two logs over the overlap only,
//!    both smoothed by the same zero-phase Gaussian prefilter whose width
//!    matches the band they share (coherence ≥ 0.5, Welch), the faster log
//!    interpolated at the slower log's own stamps (see `refine.rs`); this
//!    also yields the standard error and the residual.
//!
//! Parabolic interpolation of the correlation peak is not used: on broadband
//! signals it is biased by up to ~0.1 sample. Neither is a plain
//! interpolant in the refinement: its noise level depends on the fractional
//! position, which biases the minimum by ~0.1 sample at 30 dB SNR when the
//! rates are equal (see `kernel.rs`).

use serde::{Deserialize, Serialize};

use super::AlignError;
use super::ambiguity::{clear_anti_peak, plausible_lags};
use super::bandwidth::{shared_band_hz, sigma_for_cutoff};
use super::calibrate::{Evidence, calibrate};
use super::grid::{detrend_linear, grid_len, resample_uniform};
use super::refine::Pairing;
use super::validate::{SeriesLabels, check_options, check_series};
use super::xcorr::{analyze_peak, normalized_xcorr};
use crate::timeseries::median_dt;

/// Options of [`estimate_offset`].
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct OffsetOptions {
    /// Largest clock offset searched, `|offset_s| ≤ max_offset_s` (s). Default
    /// `None`: every offset at which the logs overlap by at least 10 % of the
    /// shorter log (and at least 16 samples of the slower log) — for logs
    /// started together that is ± (shorter length − 10 % overlap), and it
    /// also finds offsets between unrelated clock origins (epoch vs. boot).
    pub max_offset_s: Option<f64>,
    /// Rate of the common correlation grid (Hz). Default `None`: the higher
    /// of the two median sample rates. It sets the integer-lag resolution
    /// only; the refinement works on the samples at their own stamps.
    pub rate_hz: Option<f64>,
}

/// How far an offset estimate can be trusted.
///
/// With `dt` the median interval of the slower log:
/// - `High`: informative (see [`OffsetEstimate::informative`]),
///   correlation ≥ 0.95, peak ratio ≥ 1.2, standard deviation ≤ 0.1·dt;
/// - `Medium`: informative, correlation ≥ 0.7, peak ratio ≥ 1.05,
///   standard deviation ≤ 0.5·dt (an informative estimate has ≤ 0.25·dt);
/// - `Low`: anything else, in particular every uninformative estimate —
///   another offset fits about as well (`alternatives_s`, `reason`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum Confidence {
    /// Unambiguous, precise, strongly correlated.
    High,
    /// Usable, but check it.
    Medium,
    /// Ambiguous (e.g. a periodic shared channel), imprecise, weakly
    /// correlated, or at the edge of the search range.
    Low,
}

const HIGH_CORRELATION: f64 = 0.95;
const HIGH_PEAK_RATIO: f64 = 1.2;
const HIGH_STD_SAMPLES: f64 = 0.1;
const MEDIUM_CORRELATION: f64 = 0.7;
const MEDIUM_PEAK_RATIO: f64 = 1.05;
const MEDIUM_STD_SAMPLES: f64 = 0.5;

/// Largest total number of grid samples of both records (memory bound of
/// the FFT, about 8.4 million: 24 h at 48 Hz each).
const MAX_GRID_SAMPLES: usize = 1 << 23;
/// Correlation below which (with more evidence than the best positive
/// peak) the shared channel is declared sign-flipped.
const ANTI_CORRELATION: f64 = 0.8;
/// Widest prefilter, in median intervals of the slower log (cost, and the
/// ends it must leave out).
const MAX_SIGMA_SAMPLES: f64 = 20.0;
/// Refinement half-width in grid samples or samples of the slower log,
/// whichever is longer: the integer peak of a fine grid may be off by more
/// than one grid sample when the shared signal is slow and noisy.
const REFINE_HALF_WIDTH: f64 = 1.5;

/// The estimated clock offset and how much to trust it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub struct OffsetEstimate {
    /// Seconds to add to navigation time stamps to put them on the control
    /// clock: the nav sample at `t_nav` was taken at control time
    /// `t_nav + offset_s`.
    pub offset_s: f64,
    /// Standard deviation of `offset_s` (s), calibrated so that the true
    /// offset lies within ±2σ on at least 95 % of seeded test runs, weak and
    /// ambiguous ones included: the local standard error combined with half
    /// the distance to the farthest offset that fits about as well
    /// (`alternatives_s`, see `ambiguity.rs`).
    pub std_error_s: f64,
    /// The sharpness of the chosen peak alone (s), Cramér–Rao style: the
    /// variance of the mismatch's slope (Newey–West) over the square of its
    /// curvature. Says nothing about other peaks; do not use it alone.
    pub local_std_error_s: f64,
    /// Normalized cross-correlation at the integer peak, in [−1, 1]: Pearson
    /// over the overlap of the two logs on the common grid, each side's mean
    /// and linear trend over the overlap removed.
    pub correlation: f64,
    /// Ambiguity: the peak's evidence `ρ·√(overlap / shorter record)` over
    /// the highest evidence outside its main lobe. Near 1 another offset fits
    /// as well (e.g. a periodic shared channel); capped at 1000.
    pub peak_ratio: f64,
    /// Duration during which both logs have data, after alignment (s).
    pub overlap_s: f64,
    /// Grade derived from the fields above (see [`Confidence`]).
    pub confidence: Confidence,
    /// The estimate stands on its own: no other offset in the search range
    /// fits about as well, the peak is not at the edge of the range, and
    /// `std_error_s` is at most a quarter of the slower log's interval. An
    /// uninformative estimate should give way to a campaign's pooled offset.
    pub informative: bool,
    /// Why the estimate is (or is not) informative, in words.
    pub reason: String,
    /// Other offsets that fit about as well as this one (s), best
    /// correlation first, at most five; empty for an unambiguous peak.
    pub alternatives_s: Vec<f64>,
    /// RMS of the shared-channel difference after alignment, mean difference
    /// (sensor zeros) removed, in the channel's unit.
    pub residual_rms: f64,
    /// `residual_rms` divided by the standard deviation of the shared channel
    /// (slower log) over the overlap: 0 is a perfect match, 1 no match.
    pub residual_relative: f64,
}

/// Names of the inputs in error messages.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Labels<'a> {
    pub control: SeriesLabels<'a>,
    pub nav: SeriesLabels<'a>,
    pub max_offset: &'a str,
    pub rate: &'a str,
}

const PARAMETER_LABELS: Labels<'static> = Labels {
    control: SeriesLabels {
        t: "control_t",
        x: "control_x",
        log: "control log",
        channel: None,
    },
    nav: SeriesLabels {
        t: "nav_t",
        x: "nav_x",
        log: "navigation log",
        channel: None,
    },
    max_offset: "max_offset_s",
    rate: "rate_hz",
};

/// Estimates the clock offset between a control log and a navigation log
/// from a channel both recorded (e.g. depth).
///
/// `offset_s` is what must be **added to the navigation time stamps** to put
/// them on the control clock: nav sample at `t_nav` ↔ control time
/// `t_nav + offset_s`. Both logs may have any (jittery) sample rate; time
/// stamps must strictly increase. The shared channel may differ between
/// the logs by a constant (sensor zeros) and a moderate scale, but must have
/// the same sign convention. See the module documentation for the method and
/// [`Confidence`] for the grading.
///
/// # Errors
/// [`AlignError`] naming the parameter: lengths differ or fewer than 16
/// samples; NaN/infinite values; time not strictly increasing; a shared
/// channel that does not vary; options that are not finite and positive; no
/// lag within `max_offset_s` at which the logs overlap enough; a grid too
/// fine for memory; a shared channel that is anti-correlated between logs
/// (opposite sign conventions).
pub fn estimate_offset(
    control_t: &[f64],
    control_x: &[f64],
    nav_t: &[f64],
    nav_x: &[f64],
    opts: &OffsetOptions,
) -> Result<OffsetEstimate, AlignError> {
    estimate_labeled(control_t, control_x, nav_t, nav_x, opts, &PARAMETER_LABELS).map(|e| e.0)
}

/// [`estimate_offset`] with the inputs named by `labels` in errors; also
/// returns the refinement's pairing of the two logs (for the drift check).
pub(crate) fn estimate_labeled<'a>(
    control_t: &'a [f64],
    control_x: &'a [f64],
    nav_t: &'a [f64],
    nav_x: &'a [f64],
    opts: &OffsetOptions,
    labels: &Labels,
) -> Result<(OffsetEstimate, Pairing<'a>), AlignError> {
    check_options(opts).map_err(|e| relabel_option(e, labels))?;
    check_series(control_t, control_x, labels.control)?;
    check_series(nav_t, nav_x, labels.nav)?;
    let (dt_c, dt_n) = (
        median_dt(control_t).unwrap_or(1.0),
        median_dt(nav_t).unwrap_or(1.0),
    );
    let dt_slow = dt_c.max(dt_n);
    let h = opts.rate_hz.map_or(dt_c.min(dt_n), |r| 1.0 / r);

    let (tc0, tc1) = (control_t[0], control_t[control_t.len() - 1]);
    let (tn0, tn1) = (nav_t[0], nav_t[nav_t.len() - 1]);
    let (na, nb) = (grid_len(tc0, tc1, h), grid_len(tn0, tn1, h));
    if na.saturating_add(nb) > MAX_GRID_SAMPLES || !h.is_finite() {
        return Err(AlignError::invalid(
            labels.rate,
            format!(
                "a correlation grid at {:.4} Hz would need {} samples (limit {MAX_GRID_SAMPLES}); choose a lower rate",
                1.0 / h,
                na.saturating_add(nb)
            ),
        ));
    }
    if na.min(nb) < 16 {
        return Err(AlignError::invalid(
            labels.rate,
            format!(
                "a correlation grid at {:.4} Hz leaves fewer than 16 samples in a log; choose a higher rate",
                1.0 / h
            ),
        ));
    }

    // Admissible lags: enough overlap, and |offset| ≤ max_offset_s.
    let min_overlap_s = (0.1 * (tc1 - tc0).min(tn1 - tn0)).max(16.0 * dt_slow);
    let n_min = ((min_overlap_s / h).ceil() as i64).clamp(2, na.min(nb) as i64);
    let (na_i, nb_i) = (na as i64, nb as i64);
    let (mut lo, mut hi) = (-(nb_i - n_min), na_i - n_min);
    let base = tc0 - tn0; // offset at lag 0
    if let Some(max) = opts.max_offset_s {
        let m_lo = ((-max - base) / h).ceil();
        let m_hi = ((max - base) / h).floor();
        lo = lo.max(m_lo.clamp(lo as f64 - 1.0, hi as f64 + 1.0) as i64);
        hi = hi.min(m_hi.clamp(lo as f64 - 1.0, hi as f64 + 1.0) as i64);
        if lo > hi {
            return Err(AlignError::overlap(
                labels.max_offset,
                format!(
                    "within ±{max} s the logs never overlap by {min_overlap_s:.1} s (10 % of the shorter log, at least 16 samples); widen the search or check that both logs come from the same run"
                ),
            ));
        }
    }

    let mut a = resample_uniform(control_t, control_x, h);
    let mut b = resample_uniform(nav_t, nav_x, h);
    detrend_linear(&mut a);
    detrend_linear(&mut b);
    let corr = normalized_xcorr(&a, &b, lo, hi);
    let Some(peak) = analyze_peak(&corr) else {
        return Err(AlignError::overlap(
            labels.max_offset,
            "no admissible offset: the logs cannot overlap",
        ));
    };
    let dt_fast = dt_c.min(dt_n);
    let hw = REFINE_HALF_WIDTH * h.max(dt_slow);
    let window = (hw / h).ceil() as i64;
    if peak.min_rho <= -ANTI_CORRELATION
        && -peak.min_z > peak.z + 0.1
        && clear_anti_peak(&a, &b, &corr, window)
    {
        return Err(AlignError::anti_correlated(
            labels.nav.x,
            format!(
                "the shared channel is anti-correlated between the logs (correlation {:.2} at best, {:.2} at worst): one log appears to use the opposite sign convention (e.g. depth vs. height); negate it and retry",
                peak.rho, peak.min_rho
            ),
        ));
    }

    // Prefilter width from the band both logs share at the coarse lag.
    let m = peak.lag;
    let (k_lo, k_hi) = (m.max(0) as usize, na.min((nb_i + m) as usize));
    let j_lo = (k_lo as i64 - m) as usize;
    let band = shared_band_hz(&a[k_lo..k_hi], &b[j_lo..j_lo + (k_hi - k_lo)], 1.0 / h);
    let sigma_max = (MAX_SIGMA_SAMPLES * dt_slow).min((k_hi - k_lo) as f64 * h / 32.0);
    let sigma = band
        .map_or(dt_fast, sigma_for_cutoff)
        .min(sigma_max)
        .max(dt_fast);

    let d0 = base + peak.lag as f64 * h;
    let pairing = Pairing::new(control_t, control_x, nav_t, nav_x, sigma);
    let refined = pairing.refine(pairing.usable(d0, hw), d0, hw, labels.nav.x)?;
    let d = refined.offset_s;
    let refine_at_edge = (d - d0).abs() > 0.999 * hw;
    let overlap_s = tc1.min(tn1 + d) - tc0.max(tn0 + d);

    let at_edge = peak.at_edge || refine_at_edge;
    let plausible = plausible_lags(&a, &b, &corr, peak.lag, window);
    let cal = calibrate(&Evidence {
        offset_s: d,
        local_std_s: refined.std_error_s,
        base_s: base,
        h,
        dt_slow,
        at_edge,
        rho: peak.rho,
        plausible: plausible.as_ref(),
    });
    let std_samples = cal.std_error_s / dt_slow;
    let confidence = if !cal.informative {
        Confidence::Low
    } else if peak.rho >= HIGH_CORRELATION
        && peak.peak_ratio >= HIGH_PEAK_RATIO
        && std_samples <= HIGH_STD_SAMPLES
    {
        Confidence::High
    } else if peak.rho >= MEDIUM_CORRELATION
        && peak.peak_ratio >= MEDIUM_PEAK_RATIO
        && std_samples <= MEDIUM_STD_SAMPLES
    {
        Confidence::Medium
    } else {
        Confidence::Low
    };
    let estimate = OffsetEstimate {
        offset_s: d,
        std_error_s: cal.std_error_s,
        local_std_error_s: refined.std_error_s,
        correlation: peak.rho,
        peak_ratio: peak.peak_ratio,
        overlap_s,
        confidence,
        informative: cal.informative,
        reason: cal.reason,
        alternatives_s: cal.alternatives_s,
        residual_rms: refined.residual_rms,
        residual_relative: refined.residual_relative,
    };
    Ok((estimate, pairing))
}

fn relabel_option(e: AlignError, labels: &Labels) -> AlignError {
    match e {
        AlignError::InvalidInput { field, message } => AlignError::InvalidInput {
            field: match field.as_str() {
                "max_offset_s" => labels.max_offset.to_owned(),
                "rate_hz" => labels.rate.to_owned(),
                _ => field,
            },
            message,
        },
        other => other,
    }
}
