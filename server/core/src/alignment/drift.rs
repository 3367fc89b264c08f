//! Clock-drift check: one offset assumes both clocks tick at the same rate.
//! Crystal clocks differ by tens of ppm (0.1–0.4 s per hour), which at 10 Hz
//! is several samples. The offset is re-estimated on the first and the last
//! third of the overlap; a difference beyond both noise and a tenth of a
//! sample means a single offset cannot align the whole run.

use super::refine::Pairing;

/// Offsets of the first and last third of the overlap.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Drift {
    /// Offset fitted on the first third (s).
    pub early_offset_s: f64,
    /// Offset fitted on the last third (s).
    pub late_offset_s: f64,
    /// Rate difference of the clocks, parts per million (positive: the
    /// navigation clock runs slow against the control clock).
    pub ppm: f64,
    /// The difference exceeds three standard errors and 0.1·`dt_slow`.
    pub significant: bool,
}

/// Compares the offsets of the first and last thirds of the overlap around
/// `offset_s`, with the pairing (and prefilter) of the whole-overlap
/// estimate; `None` when the thirds are too short or featureless to fit.
pub(crate) fn check_drift(pairing: &Pairing, offset_s: f64, dt_slow: f64) -> Option<Drift> {
    let hw = 3.0 * dt_slow;
    let full = pairing.usable(offset_s, hw);
    let third = full.len() / 3;
    if third < 16 {
        return None;
    }
    let early = pairing
        .refine(full.start..full.start + third, offset_s, hw, "shared")
        .ok()?;
    let late = pairing
        .refine(full.end - third..full.end, offset_s, hw, "shared")
        .ok()?;
    let diff = late.offset_s - early.offset_s;
    let span = late.t_mid - early.t_mid;
    let noise = (early.std_error_s.powi(2) + late.std_error_s.powi(2)).sqrt();
    Some(Drift {
        early_offset_s: early.offset_s,
        late_offset_s: late.offset_s,
        ppm: if span > 0.0 { diff / span * 1e6 } else { 0.0 },
        significant: diff.abs() > 3.0 * noise && diff.abs() > 0.1 * dt_slow,
    })
}
