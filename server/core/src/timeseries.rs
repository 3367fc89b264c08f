//! Shared time-series types: a parsed log ([`LogTable`], irregular time as
//! recorded) and a uniformly sampled record ([`UniformRecord`]) that the
//! alignment and quality modules work on.

use std::ops::Range;

/// A log as recorded: time column `t` (s, strictly increasing) and the other
/// numeric columns in file order.
#[derive(Debug, Clone, PartialEq)]
pub struct LogTable {
    /// Time stamps (s).
    pub t: Vec<f64>,
    /// Column names, without `t`.
    pub names: Vec<String>,
    /// One vector per name, each as long as `t`.
    pub data: Vec<Vec<f64>>,
}

impl LogTable {
    /// The column of a name.
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.names
            .iter()
            .position(|n| n == name)
            .map(|i| self.data[i].as_slice())
    }

    /// Median sample interval (s); `None` with fewer than two samples.
    pub fn median_dt(&self) -> Option<f64> {
        median_dt(&self.t)
    }
}

/// A uniformly sampled multichannel record: sample k is at `t0 + k/fs`.
/// `valid` lists the blocks that hold measured data; samples outside them
/// (long gaps) must not be used for estimation.
#[derive(Debug, Clone, PartialEq)]
pub struct UniformRecord {
    /// Sample rate (Hz).
    pub sample_rate_hz: f64,
    /// Time of sample 0 (s).
    pub t0: f64,
    /// Channel names.
    pub names: Vec<String>,
    /// One vector per name, all of equal length.
    pub data: Vec<Vec<f64>>,
    /// Contiguous blocks of valid samples, ascending and disjoint.
    pub valid: Vec<Range<usize>>,
}

impl UniformRecord {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.data.first().map_or(0, Vec::len)
    }

    /// True without samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The column of a name.
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.names
            .iter()
            .position(|n| n == name)
            .map(|i| self.data[i].as_slice())
    }

    /// Duration covered by valid samples (s).
    pub fn valid_duration_s(&self) -> f64 {
        self.valid.iter().map(|r| r.len()).sum::<usize>() as f64 / self.sample_rate_hz
    }
}

/// Median of the successive differences of `t`.
pub fn median_dt(t: &[f64]) -> Option<f64> {
    if t.len() < 2 {
        return None;
    }
    let mut d: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    let mid = d.len() / 2;
    d.select_nth_unstable_by(mid, f64::total_cmp);
    Some(d[mid])
}

/// Median of `v` (reordered in place); the mean of the two middle values
/// for an even count, NaN when `v` is empty.
pub fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let m = v.len() / 2;
    match v.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => v[m],
        _ => 0.5 * (v[m - 1] + v[m]),
    }
}

/// Linear interpolation of (t, x) at the times `at` (t strictly increasing).
/// Times outside [t₀, t_end] take the end values.
pub fn interp_linear(t: &[f64], x: &[f64], at: &[f64]) -> Vec<f64> {
    let n = t.len().min(x.len());
    if n == 0 {
        return vec![f64::NAN; at.len()];
    }
    let mut j = 0usize;
    at.iter()
        .map(|&s| {
            if s <= t[0] {
                return x[0];
            }
            if s >= t[n - 1] {
                return x[n - 1];
            }
            // `at` is usually ascending: walk forward, fall back to search.
            if j >= n - 1 || t[j] > s {
                j = t[..n].partition_point(|&v| v <= s).saturating_sub(1);
            }
            while j + 1 < n - 1 && t[j + 1] <= s {
                j += 1;
            }
            let (t0, t1) = (t[j], t[j + 1]);
            let w = (s - t0) / (t1 - t0);
            x[j] + w * (x[j + 1] - x[j])
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolation_is_exact_on_lines_and_holds_ends() {
        let t = [0.0, 0.5, 2.0, 3.0];
        let x: Vec<f64> = t.iter().map(|v| 2.0 * v - 1.0).collect();
        let at = [-1.0, 0.0, 0.25, 1.0, 2.5, 3.0, 4.0, 0.1];
        let y = interp_linear(&t, &x, &at);
        let want = [-1.0, -1.0, -0.5, 1.0, 4.0, 5.0, 5.0, -0.8];
        for (a, b) in y.iter().zip(want) {
            assert!((a - b).abs() < 1e-12, "{a} vs {b}");
        }
    }

    #[test]
    fn median_of_odd_even_and_empty_sets() {
        assert_eq!(median(&mut [3.0, -1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), 2.5);
        assert!(median(&mut []).is_nan());
    }

    #[test]
    fn median_dt_ignores_a_gap() {
        let m = median_dt(&[0.0, 0.1, 0.2, 5.0, 5.1, 5.2]).unwrap();
        assert!((m - 0.1).abs() < 1e-12);
        assert_eq!(median_dt(&[1.0]), None);
    }
}
