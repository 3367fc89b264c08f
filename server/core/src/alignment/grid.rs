//! The common grid of the coarse correlation: each record resampled at step
//! `h` from its own first time stamp (linear interpolation,
//! [`crate::timeseries::interp_linear`]), then mean and linear trend removed.

use crate::timeseries::interp_linear;

/// Number of grid samples of step `h` that fit in `[t_first, t_last]`.
pub(crate) fn grid_len(t_first: f64, t_last: f64, h: f64) -> usize {
    let span = t_last - t_first;
    // The tiny relative slack keeps an end that lies on the grid up to
    // rounding.
    // `as` saturates (NaN → 0), so absurd rates cannot overflow.
    ((span / h * (1.0 + 1e-12)).floor() as usize).saturating_add(1)
}

/// `x` linearly interpolated at `t[0] + k·h`, `k = 0..grid_len`.
pub(crate) fn resample_uniform(t: &[f64], x: &[f64], h: f64) -> Vec<f64> {
    let (Some(&first), Some(&last)) = (t.first(), t.last()) else {
        return Vec::new();
    };
    let n = grid_len(first, last, h);
    let at: Vec<f64> = (0..n).map(|k| first + k as f64 * h).collect();
    interp_linear(t, x, &at)
}

/// Removes the least-squares line over the sample index (mean and trend).
pub(crate) fn detrend_linear(x: &mut [f64]) {
    let n = x.len();
    if n == 0 {
        return;
    }
    let nf = n as f64;
    let mean = x.iter().sum::<f64>() / nf;
    if n < 2 {
        x.iter_mut().for_each(|v| *v -= mean);
        return;
    }
    let kc = (nf - 1.0) / 2.0;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (k, v) in x.iter().enumerate() {
        let d = k as f64 - kc;
        sxy += d * (v - mean);
        sxx += d * d;
    }
    let slope = sxy / sxx;
    for (k, v) in x.iter_mut().enumerate() {
        *v -= mean + slope * (k as f64 - kc);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn detrend_removes_a_line_exactly() {
        let mut x: Vec<f64> = (0..50).map(|k| 3.0 - 0.25 * k as f64).collect();
        detrend_linear(&mut x);
        assert!(x.iter().all(|v| v.abs() < 1e-12));
    }

    #[test]
    fn resampling_covers_the_span_on_the_step() {
        let t = [10.0, 10.3, 10.55, 11.0];
        let x = [0.0, 3.0, 5.5, 10.0];
        let y = resample_uniform(&t, &x, 0.25);
        assert_eq!(y.len(), 5);
        for (k, v) in y.iter().enumerate() {
            assert!((v - 2.5 * k as f64).abs() < 1e-12, "{k}: {v}");
        }
    }
}
