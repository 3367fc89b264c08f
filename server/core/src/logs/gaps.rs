//! Gaps in a log's time stamps and the bridging rule.
//!
//! With `dt₀` the median sample interval of the log, a step
//! `Δt = t[k+1] − t[k] > 1.5·dt₀` is a gap; it misses
//! `round(Δt/dt₀) − 1` samples. A gap of at most [`MAX_BRIDGE_SAMPLES`]
//! missing samples is *bridged*: resampling interpolates across it and the
//! samples count as measured. A longer gap splits the run: resampled samples
//! strictly inside it are not used for estimation. The rule counts samples of
//! the log itself, so it does not depend on the resampling rate.

use serde::Serialize;

/// Gaps of at most this many missing samples are interpolated (bridged);
/// longer gaps split the run.
pub const MAX_BRIDGE_SAMPLES: usize = 5;

/// A step longer than this many median intervals is a gap.
pub const GAP_FACTOR: f64 = 1.5;

/// A gap in the time stamps.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct Gap {
    /// Last time stamp before the gap (s).
    pub start_t: f64,
    /// First time stamp after the gap (s).
    pub end_t: f64,
    /// Samples missing at the median interval: `round(Δt/dt₀) − 1`.
    pub missing_samples: usize,
    /// True if the gap is short enough to be interpolated
    /// (`missing_samples ≤ MAX_BRIDGE_SAMPLES`).
    pub bridged: bool,
}

/// The gaps of strictly increasing time stamps `t` with nominal interval
/// `nominal_dt` (normally the median interval), in time order. Returns no
/// gaps when `nominal_dt` is not a finite positive number.
pub fn find_gaps(t: &[f64], nominal_dt: f64) -> Vec<Gap> {
    if !(nominal_dt.is_finite() && nominal_dt > 0.0) {
        return Vec::new();
    }
    t.windows(2)
        .filter_map(|w| {
            let dt = w[1] - w[0];
            if dt > GAP_FACTOR * nominal_dt {
                // `as` saturates: a huge jump cannot overflow.
                let missing = ((dt / nominal_dt).round() as usize).saturating_sub(1);
                Some(Gap {
                    start_t: w[0],
                    end_t: w[1],
                    missing_samples: missing,
                    bridged: missing <= MAX_BRIDGE_SAMPLES,
                })
            } else {
                None
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_missing_samples_and_bridges_short_gaps() {
        // 10 Hz with jitter, then gaps of 1, 5, 6 and 20 missing samples.
        let mut t = vec![0.0, 0.1, 0.2, 0.31, 0.4];
        t.extend([0.6, 0.7]); // 0.4 → 0.6: 1 missing
        t.extend([1.3, 1.4]); // 0.7 → 1.3: 5 missing
        t.extend([2.1, 2.2]); // 1.4 → 2.1: 6 missing
        t.extend([4.3, 4.4, 4.5]); // 2.2 → 4.3: 20 missing
        let gaps = find_gaps(&t, 0.1);
        let got: Vec<(f64, f64, usize, bool)> = gaps
            .iter()
            .map(|g| (g.start_t, g.end_t, g.missing_samples, g.bridged))
            .collect();
        assert_eq!(
            got,
            [
                (0.4, 0.6, 1, true),
                (0.7, 1.3, 5, true),
                (1.4, 2.1, 6, false),
                (2.2, 4.3, 20, false)
            ]
        );
    }

    #[test]
    fn jitter_below_one_and_a_half_steps_is_no_gap() {
        assert!(find_gaps(&[0.0, 0.1, 0.249, 0.3], 0.1).is_empty());
        assert_eq!(find_gaps(&[0.0, 0.151], 0.1)[0].missing_samples, 1);
        assert!(find_gaps(&[0.0, 1.0], 0.0).is_empty());
        assert!(find_gaps(&[0.0, 1.0], f64::NAN).is_empty());
        assert_eq!(
            find_gaps(&[0.0, 1e300], 1e-300)[0].missing_samples,
            usize::MAX - 1
        );
    }
}
