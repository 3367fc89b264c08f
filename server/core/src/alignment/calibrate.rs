//! From the local standard error and the set of offsets that fit as well
//! (`ambiguity.rs`) to the reported standard deviation, the `informative`
//! flag and its reason in words.
//!
//! `σ² = (κ·σ_local)² + (R/2)²`, with `R` the distance from the estimate to
//! the farthest plausible offset outside the refinement window: ±2σ then
//! covers every offset the data cannot rule out. `κ = 1.25` widens the local
//! error, whose root-mean-square ratio to the actual error was measured at
//! 1.14 on short noisy records (`tests/offset.rs`); with it the ±2σ
//! coverage of strong runs meets 95 % (`tests/calibration.rs`).

use super::ambiguity::{Plausible, Shape};

/// Widening of the local standard error (see the module documentation).
pub(crate) const LOCAL_STD_FACTOR: f64 = 1.25;
/// Largest standard deviation, in intervals of the slower log, of an
/// informative estimate.
pub(crate) const INFORMATIVE_STD_SAMPLES: f64 = 0.25;

/// What the estimate needs to be graded.
pub(crate) struct Evidence<'a> {
    /// Refined offset (s).
    pub offset_s: f64,
    /// The refinement's standard error (s).
    pub local_std_s: f64,
    /// The offset of integer lag 0 (s) and the grid step (s): lag `m` is
    /// offset `base_s + m·h`.
    pub base_s: f64,
    pub h: f64,
    /// Median interval of the slower log (s).
    pub dt_slow: f64,
    /// The peak (or its refinement) sits at the edge of the search.
    pub at_edge: bool,
    /// Correlation at the peak.
    pub rho: f64,
    /// Offsets that fit as well, `None` when the overlap is too short to test.
    pub plausible: Option<&'a Plausible>,
}

/// The calibrated part of an [`super::OffsetEstimate`].
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Calibrated {
    pub std_error_s: f64,
    pub informative: bool,
    pub reason: String,
    pub alternatives_s: Vec<f64>,
}

/// Combines the local error with the plausible set; see the module docs.
pub(crate) fn calibrate(e: &Evidence) -> Calibrated {
    let offset_of = |m: i64| e.base_s + m as f64 * e.h;
    let reach = e.plausible.map_or(0.0, |p| {
        p.lags
            .iter()
            .map(|&m| (offset_of(m) - e.offset_s).abs())
            .fold(0.0, f64::max)
    });
    let local = LOCAL_STD_FACTOR * e.local_std_s;
    let std_error_s = (local * local + 0.25 * reach * reach).sqrt();
    let alternatives_s: Vec<f64> = e
        .plausible
        .map(|p| p.alternatives.iter().map(|&m| offset_of(m)).collect())
        .unwrap_or_default();
    let limit = INFORMATIVE_STD_SAMPLES * e.dt_slow;
    let list = if alternatives_s.is_empty() {
        e.plausible.map_or(String::new(), |p| {
            let (lo, hi) = (p.lags.first(), p.lags.last());
            match (lo, hi) {
                (Some(&lo), Some(&hi)) => {
                    format!("from {:.3} to {:.3}", offset_of(lo), offset_of(hi))
                }
                _ => String::new(),
            }
        })
    } else {
        alternatives_s
            .iter()
            .map(|v| format!("{v:.3}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let (informative, reason) = match e.plausible.map(|p| (p, p.shape())) {
        _ if e.at_edge => (
            false,
            "the best offset lies at the edge of the search range: the true one may lie beyond it"
                .to_owned(),
        ),
        None => (
            false,
            "the logs overlap by too few samples to test the peak against other offsets".to_owned(),
        ),
        Some((p, Some(Shape::Flat))) => (
            false,
            format!(
                "flat correlation: {} of the {} offsets searched ({:.0} %) fit about as well as the best (correlation {:.2}); the shared channel varies too little to align on",
                p.lags.len(),
                p.admissible,
                100.0 * p.lags.len() as f64 / p.admissible.max(1) as f64,
                e.rho
            ),
        ),
        Some((_, Some(Shape::Ambiguous))) => (
            false,
            format!(
                "ambiguous: the offsets {list} s fit about as well (a periodic shared channel, or one that varies too little)"
            ),
        ),
        Some((_, Some(Shape::Broad))) => (
            false,
            format!(
                "broad peak: offsets up to {reach:.3} s away fit about as well; the shared channel varies too little or too slowly"
            ),
        ),
        Some((_, None)) if std_error_s > limit => (
            false,
            format!(
                "imprecise: ±{std_error_s:.3} s is more than a quarter of the slower log's {:.3} s sample interval",
                e.dt_slow
            ),
        ),
        Some((_, None)) => (
            true,
            format!(
                "one offset fits clearly best: no other in the search range fits as well (correlation {:.3}, ±{std_error_s:.4} s)",
                e.rho
            ),
        ),
    };
    Calibrated {
        std_error_s,
        informative,
        reason,
        alternatives_s,
    }
}
