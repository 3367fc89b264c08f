//! Resampling rules of the merge, and gap detection.
//!
//! - Commands (control-log inputs) are piecewise constant: the controller
//!   issues a value and the actuator holds it until the next one. At or
//!   above the control rate they are sampled by **zero-order hold**
//!   ([`zero_order_hold`]): exact point samples of the held signal, never an
//!   invented ramp and never a value before it was issued (linear
//!   interpolation would do both, smearing a step half a sample early).
//!   Below the control rate they are **cell averages** of the held signal
//!   over `[t − h/2, t + h/2]` ([`cell_average`]): a boxcar anti-alias filter
//!   that keeps the impulse (∫τ dt) the vehicle integrates, where point
//!   samples would alias fast PRBS chips.
//! - Measurements (navigation channels, and the control log's copy of the
//!   shared channel) are interpolated linearly
//!   ([`crate::timeseries::interp_linear`]).

use std::ops::Range;

use crate::timeseries::median_dt;

/// An interval between two samples longer than this many median intervals
/// is a gap: merged samples inside it are marked invalid.
pub(crate) const GAP_FACTOR: f64 = 4.0;

/// Zero-order hold of `(t, x)` at the times `at` (ascending): the last
/// sample at or before each time; the first sample before the log starts.
pub(crate) fn zero_order_hold(t: &[f64], x: &[f64], at: &[f64]) -> Vec<f64> {
    at.iter()
        .map(|&s| x[t.partition_point(|&v| v <= s).saturating_sub(1)])
        .collect()
}

/// Average of the zero-order-held `(t, x)` over `[s − h/2, s + h/2]` for
/// each `s` in `at` (the first value held before the log starts).
pub(crate) fn cell_average(t: &[f64], x: &[f64], at: &[f64], h: f64) -> Vec<f64> {
    // Cumulative integral of the held signal at each sample time.
    let mut cum = Vec::with_capacity(t.len());
    let mut acc = 0.0;
    cum.push(0.0);
    for k in 1..t.len() {
        acc += x[k - 1] * (t[k] - t[k - 1]);
        cum.push(acc);
    }
    let integral = |s: f64| {
        let j = t.partition_point(|&v| v <= s).saturating_sub(1);
        cum[j] + x[j] * (s - t[j])
    };
    at.iter()
        .map(|&s| (integral(s + 0.5 * h) - integral(s - 0.5 * h)) / h)
        .collect()
}

/// Intervals `(start, end)` between consecutive stamps longer than
/// [`GAP_FACTOR`] median intervals.
pub(crate) fn gaps(t: &[f64]) -> Vec<(f64, f64)> {
    let Some(dt) = median_dt(t) else {
        return Vec::new();
    };
    t.windows(2)
        .filter(|w| w[1] - w[0] > GAP_FACTOR * dt)
        .map(|w| (w[0], w[1]))
        .collect()
}

/// Blocks of grid samples (`t0 + k·h`, `k < n`) not strictly inside any gap.
pub(crate) fn valid_blocks(t0: f64, h: f64, n: usize, gaps: &[(f64, f64)]) -> Vec<Range<usize>> {
    let mut valid = vec![true; n];
    for &(a, b) in gaps {
        let first = (((a - t0) / h).floor() + 1.0).max(0.0) as usize;
        let mut k = first.min(n);
        while k < n && t0 + k as f64 * h < b {
            if t0 + k as f64 * h > a {
                valid[k] = false;
            }
            k += 1;
        }
    }
    let mut blocks = Vec::new();
    let mut start = None;
    for (k, &ok) in valid.iter().enumerate() {
        match (ok, start) {
            (true, None) => start = Some(k),
            (false, Some(s)) => {
                blocks.push(s..k);
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start {
        blocks.push(s..n);
    }
    blocks
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hold_never_anticipates_a_step() {
        let t = [0.0, 1.0, 2.0, 3.0];
        let x = [0.0, 0.0, 5.0, 5.0];
        let at = [-0.5, 0.5, 1.99, 2.0, 2.01, 3.5];
        assert_eq!(
            zero_order_hold(&t, &x, &at),
            vec![0.0, 0.0, 0.0, 5.0, 5.0, 5.0]
        );
    }

    #[test]
    fn cell_average_keeps_the_impulse() {
        // 10 Hz chips of ±1, averaged onto 2 Hz cells.
        let t: Vec<f64> = (0..100).map(|k| k as f64 * 0.1).collect();
        let x: Vec<f64> = (0..100)
            .map(|k| if (k * 7) % 3 == 0 { 1.0 } else { -1.0 })
            .collect();
        let at: Vec<f64> = (1..19).map(|k| k as f64 * 0.5).collect();
        let y = cell_average(&t, &x, &at, 0.5);
        for (s, v) in at.iter().zip(&y) {
            // Midpoint rule on the held signal, 10 000 points per cell.
            let m = 10_000;
            let want = (0..m)
                .map(|i| {
                    let u = s - 0.25 + (i as f64 + 0.5) * 0.5 / m as f64;
                    x[t.partition_point(|&v| v <= u) - 1]
                })
                .sum::<f64>()
                / m as f64;
            assert!((v - want).abs() < 1e-3, "{s}: {v} vs {want}");
        }
        // The mean is kept: the impulse of the input is not changed.
        let total: f64 = y.iter().sum::<f64>() * 0.5;
        // Cells cover [0.25, 9.25]: half of the samples at 0.2 and 9.2.
        let direct = 0.05 * (x[2] + x[92]) + x[3..92].iter().sum::<f64>() * 0.1;
        assert!((total - direct).abs() < 1e-9, "{total} vs {direct}");
        // A straddling cell takes the fraction of each value.
        let y = cell_average(&[0.0, 1.0, 2.0], &[0.0, 4.0, 4.0], &[1.1], 0.4);
        assert!((y[0] - 3.0).abs() < 1e-12);
    }

    #[test]
    fn gaps_mark_grid_samples_invalid() {
        let t = [0.0, 0.1, 0.2, 0.3, 1.3, 1.4, 1.5];
        let g = gaps(&t);
        assert_eq!(g, vec![(0.3, 1.3)]);
        let blocks = valid_blocks(0.05, 0.1, 15, &g);
        // Grid 0.05, 0.15, ..., 1.45: samples at 0.35..1.25 are inside.
        assert_eq!(blocks, vec![0..3, 13..15]);
        assert_eq!(valid_blocks(0.0, 0.1, 4, &[]), vec![0..4]);
    }
}
