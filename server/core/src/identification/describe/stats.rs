//! Statistics of a record's columns over its valid blocks: means and
//! spreads, level switches and the share of steps, moving averages and
//! covariances.

use crate::timeseries::UniformRecord;

/// The valid samples of a column, block by block.
pub(super) fn blocks<'a>(
    rec: &'a UniformRecord,
    col: &'a [f64],
) -> impl Iterator<Item = &'a [f64]> + 'a {
    rec.valid
        .iter()
        .filter(|b| b.end <= col.len())
        .map(move |b| &col[b.clone()])
}

/// Mean and standard deviation over the valid samples.
pub(super) fn mean_std(rec: &UniformRecord, col: &[f64]) -> (f64, f64) {
    let (mut n, mut s) = (0usize, 0.0);
    for b in blocks(rec, col) {
        n += b.len();
        s += b.iter().sum::<f64>();
    }
    if n == 0 {
        return (0.0, 0.0);
    }
    let m = s / n as f64;
    let v = blocks(rec, col)
        .flat_map(|b| b.iter())
        .map(|x| (x - m).powi(2))
        .sum::<f64>()
        / n as f64;
    (m, v.sqrt())
}

/// Sample indices (within each block) where `x` switches between below
/// `lo` and above `hi`, per block.
pub(super) fn switch_times(rec: &UniformRecord, col: &[f64], lo: f64, hi: f64) -> Vec<Vec<usize>> {
    blocks(rec, col)
        .map(|b| {
            let mut state: Option<bool> = None;
            let mut out = Vec::new();
            for (k, &x) in b.iter().enumerate() {
                let now = if x > hi {
                    Some(true)
                } else if x < lo {
                    Some(false)
                } else {
                    None
                };
                if let Some(n) = now {
                    if state.is_some_and(|s| s != n) {
                        out.push(k);
                    }
                    state = Some(n);
                }
            }
            out
        })
        .collect()
}

/// Share of the variance of the valid samples of `col` explained by the best
/// single step (two constant levels, one breakpoint); O(N).
pub(super) fn step_share(rec: &UniformRecord, col: &[f64]) -> f64 {
    let x: Vec<f64> = blocks(rec, col).flatten().copied().collect();
    let n = x.len();
    if n < 2 {
        return 0.0;
    }
    let total: f64 = x.iter().sum();
    let mean = total / n as f64;
    let ss: f64 = x.iter().map(|v| (v - mean).powi(2)).sum();
    if ss <= 0.0 {
        return 0.0;
    }
    // Between-level sum of squares of a split after k samples:
    // k (m₁ − m)² + (n − k)(m₂ − m)².
    let (mut left, mut best) = (0.0, 0.0_f64);
    for (k, v) in x.iter().enumerate().take(n - 1) {
        left += v;
        let k = (k + 1) as f64;
        let m1 = left / k;
        let m2 = (total - left) / (n as f64 - k);
        best = best.max(k * (m1 - mean).powi(2) + (n as f64 - k) * (m2 - mean).powi(2));
    }
    best / ss
}

/// A centred moving average of `w` samples.
pub(super) fn moving_average(x: &[f64], w: usize) -> Vec<f64> {
    let half = w / 2;
    let mut prefix = vec![0.0; x.len() + 1];
    for (k, v) in x.iter().enumerate() {
        prefix[k + 1] = prefix[k] + v;
    }
    (0..x.len())
        .map(|k| {
            let (lo, hi) = (k.saturating_sub(half), (k + half + 1).min(x.len()));
            (prefix[hi] - prefix[lo]) / (hi - lo) as f64
        })
        .collect()
}

/// Covariance of two equally long series.
pub(super) fn covariance(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len() as f64;
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - ma) * (y - mb))
        .sum::<f64>()
        / n
}
