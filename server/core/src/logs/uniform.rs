//! Resampling a log onto a uniform grid, and the gap rule the service tells
//! the supervisor: **gaps up to 5 samples are interpolated; longer gaps split
//! the run and their samples are not used.**
//!
//! The grid starts at the first time stamp `t[0]` and runs at `rate_hz`
//! (default: the log's own rate `1/dt₀`, `dt₀` the median interval) up to the
//! last time stamp; every column is linearly interpolated onto it
//! ([`interp_linear`]). Gaps are found as in [`super::gaps`] — counted in
//! samples of the log itself, at `dt₀`, whatever the resampling rate:
//! a gap missing at most [`MAX_BRIDGE_SAMPLES`] samples is bridged by the
//! interpolation and its grid samples are valid; grid samples strictly inside
//! a longer gap (more than 1/1000 of a grid step away from both measured
//! ends) are interpolated too, but left out of [`UniformRecord::valid`],
//! which then has one block per stretch of the run between long gaps.
//!
//! Linear interpolation is not an anti-aliasing filter: resample below the
//! log's own rate only after low-pass filtering.

use std::ops::Range;

use super::error::{LogError, LogErrorKind};
pub use super::gaps::MAX_BRIDGE_SAMPLES;
use super::gaps::{Gap, find_gaps};
use crate::timeseries::{LogTable, UniformRecord, interp_linear, median_dt};

/// Largest resampled record, in values (samples × channels, time included):
/// 1.6 GB of `f64`.
pub const MAX_UNIFORM_VALUES: usize = 200_000_000;

/// Grid samples this close (in grid steps) to a measured end of a long gap
/// count as measured.
const EDGE_TOLERANCE: f64 = 1e-3;

/// The logger's nominal rate from its median interval: time stamps such as
/// 100.1, 100.2 … carry rounding noise (1/dt = 9.9999999999977), so a rate
/// within 1 ppm of a whole number of hertz (or of 1/n Hz) is snapped to it.
pub fn nominal_rate(median_dt: f64) -> f64 {
    let fs = 1.0 / median_dt;
    let snap = |v: f64| (v - v.round()).abs() <= 1e-6 * v.max(1.0);
    if fs >= 1.0 && snap(fs) {
        fs.round()
    } else if fs < 1.0 && snap(median_dt) {
        1.0 / median_dt.round()
    } else {
        fs
    }
}

/// Lowest resampling rate that can be requested (Hz): one sample per 100 s.
pub const MIN_RATE_HZ: f64 = 0.01;
/// Highest resampling rate that can be requested (Hz).
pub const MAX_RATE_HZ: f64 = 1000.0;

/// Checks a requested resampling rate: finite and within
/// [`MIN_RATE_HZ`] … [`MAX_RATE_HZ`]; the reason, without the field name.
pub fn check_rate_hz(rate_hz: f64) -> Result<(), String> {
    if rate_hz.is_finite() && (MIN_RATE_HZ..=MAX_RATE_HZ).contains(&rate_hz) {
        Ok(())
    } else {
        Err(format!(
            "the resampling rate must be between {MIN_RATE_HZ} and {MAX_RATE_HZ} Hz (got {})",
            crate::numbers::echoed(rate_hz)
        ))
    }
}

/// Resamples `table` onto a uniform grid from `t[0]` at `rate_hz` (default
/// `1/median dt`), and returns it with the gaps of the log (see the module
/// documentation for the rule).
///
/// Errors name the file `"file"` (set [`LogError::file`] to the role when
/// resampling a control or nav log): [`LogErrorKind::TooFewRows`] (fewer than
/// 2 samples), `RaggedRow` (a column of another length than `t`),
/// `NonFinite`, `NonMonotonicTime`, `DuplicateTime` (a table not built by
/// [`super::parse::parse_log`]), `InvalidRate` (a rate that is not finite
/// and positive), `TooLarge` (more than [`MAX_UNIFORM_VALUES`] values).
pub fn to_uniform(
    table: &LogTable,
    rate_hz: Option<f64>,
) -> Result<(UniformRecord, Vec<Gap>), LogError> {
    check_table(table)?;
    let t = &table.t;
    let (Some(&t0), Some(&t_end), Some(dt0)) = (t.first(), t.last(), median_dt(t)) else {
        return Err(too_few(t.len()));
    };
    if let Some(r) = rate_hz {
        check_rate_hz(r).map_err(|m| LogError::new("file", LogErrorKind::InvalidRate, m))?;
    }
    let fs = rate_hz.unwrap_or_else(|| nominal_rate(dt0));
    if !(fs.is_finite() && fs > 0.0) {
        return Err(LogError::new(
            "file",
            LogErrorKind::InvalidRate,
            format!(
                "the resampling rate must be a finite number of Hz above zero (got {})",
                crate::numbers::echoed(fs)
            ),
        ));
    }
    // Number of grid steps; the end is included when it falls on the grid.
    let steps = ((t_end - t0) * fs + EDGE_TOLERANCE).floor();
    let channels = table.names.len() + 1;
    let max_len = MAX_UNIFORM_VALUES / channels;
    if !(steps.is_finite() && steps < max_len as f64) {
        return Err(LogError::new(
            "file",
            LogErrorKind::TooLarge,
            format!(
                "resampling {} s at {fs} Hz would give {} samples of {channels} channels, more \
                 than the limit of {MAX_UNIFORM_VALUES} values (is a time stamp wrong?)",
                t_end - t0,
                steps + 1.0
            ),
        ));
    }
    let len = steps as usize + 1;
    let grid: Vec<f64> = (0..len).map(|j| t0 + j as f64 / fs).collect();
    let data: Vec<Vec<f64>> = table
        .data
        .iter()
        .map(|x| interp_linear(t, x, &grid))
        .collect();

    let gaps = find_gaps(t, dt0);
    let valid = valid_blocks(&gaps, t0, fs, len);
    let record = UniformRecord {
        sample_rate_hz: fs,
        t0,
        names: table.names.clone(),
        data,
        valid,
    };
    Ok((record, gaps))
}

/// The grid blocks outside the long (unbridged) gaps.
fn valid_blocks(gaps: &[Gap], t0: f64, fs: f64, len: usize) -> Vec<Range<usize>> {
    let mut blocks = Vec::new();
    let mut start = 0usize;
    for g in gaps.iter().filter(|g| !g.bridged) {
        // First grid index after the gap start, first at or after its end.
        let lo = ((g.start_t - t0) * fs + EDGE_TOLERANCE).floor() + 1.0;
        let hi = ((g.end_t - t0) * fs - EDGE_TOLERANCE).ceil();
        let lo = lo.clamp(0.0, len as f64) as usize;
        let hi = hi.clamp(0.0, len as f64) as usize;
        if lo >= hi {
            continue; // the grid is coarser than the gap: nothing inside
        }
        if lo > start {
            blocks.push(start..lo);
        }
        start = start.max(hi);
    }
    if start < len {
        blocks.push(start..len);
    }
    blocks
}

/// Zero-order hold of (t, x) at the times `at` (t strictly increasing): the
/// last sample at or before each time; times before `t[0]` take `x[0]`. For
/// command signals that are piecewise constant. NaN everywhere when `t` or
/// `x` is empty.
pub fn zoh(t: &[f64], x: &[f64], at: &[f64]) -> Vec<f64> {
    let n = t.len().min(x.len());
    if n == 0 {
        return vec![f64::NAN; at.len()];
    }
    let t = &t[..n];
    let mut j = 0usize;
    at.iter()
        .map(|&s| {
            // `at` is usually ascending: walk forward, fall back to search.
            if t[j] > s {
                j = t.partition_point(|&v| v <= s).saturating_sub(1);
            }
            while j + 1 < n && t[j + 1] <= s {
                j += 1;
            }
            x[j]
        })
        .collect()
}

/// Checks what `to_uniform` relies on: equal lengths, finite values,
/// strictly increasing time.
fn check_table(table: &LogTable) -> Result<(), LogError> {
    let n = table.t.len();
    if n < 2 {
        return Err(too_few(n));
    }
    if table.names.len() != table.data.len() {
        return Err(LogError::new(
            "file",
            LogErrorKind::RaggedRow,
            format!(
                "the table has {} column names but {} columns",
                table.names.len(),
                table.data.len()
            ),
        ));
    }
    for (k, w) in table.t.windows(2).enumerate() {
        if !(w[0].is_finite() && w[1].is_finite()) {
            return Err(LogError::new(
                "file",
                LogErrorKind::NonFinite,
                format!(
                    "time stamp {} is not finite",
                    if w[0].is_finite() { k + 1 } else { k }
                ),
            )
            .in_column("t"));
        }
        if w[1] <= w[0] {
            let kind = if w[1] == w[0] {
                LogErrorKind::DuplicateTime
            } else {
                LogErrorKind::NonMonotonicTime
            };
            return Err(LogError::new(
                "file",
                kind,
                format!(
                    "t = {} (sample {}) is not after the previous {} (time must strictly increase)",
                    w[1],
                    k + 1,
                    w[0]
                ),
            )
            .in_column("t"));
        }
    }
    for (name, x) in table.names.iter().zip(&table.data) {
        if x.len() != n {
            return Err(LogError::new(
                "file",
                LogErrorKind::RaggedRow,
                format!("column {name} has {} values, t has {n}", x.len()),
            )
            .in_column(name.as_str()));
        }
        if let Some(k) = x.iter().position(|v| !v.is_finite()) {
            return Err(LogError::new(
                "file",
                LogErrorKind::NonFinite,
                format!("value {k} of {name} is not finite ({})", x[k]),
            )
            .in_column(name.as_str()));
        }
    }
    Ok(())
}

/// The error of a table with fewer than two samples.
fn too_few(n: usize) -> LogError {
    LogError::new(
        "file",
        LogErrorKind::TooFewRows,
        format!("the log has {n} samples; at least 2 are needed to resample"),
    )
}

#[cfg(test)]
mod nominal_rate_tests {
    use super::nominal_rate;

    #[test]
    fn rounding_noise_is_snapped_and_odd_rates_are_kept() {
        assert_eq!(nominal_rate(100.2 - 100.1), 10.0);
        assert_eq!(nominal_rate(0.05), 20.0);
        assert_eq!(nominal_rate(2.0), 0.5);
        assert!((nominal_rate(0.0123) - 1.0 / 0.0123).abs() < 1e-9);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(t: Vec<f64>, cols: &[(&str, &dyn Fn(f64) -> f64)]) -> LogTable {
        LogTable {
            names: cols.iter().map(|(n, _)| n.to_string()).collect(),
            data: cols
                .iter()
                .map(|(_, f)| t.iter().map(|&v| f(v)).collect())
                .collect(),
            t,
        }
    }

    /// 10 Hz from 0 with the samples in `missing` (indices) left out.
    fn ten_hz(last: usize, missing: Range<usize>) -> Vec<f64> {
        (0..=last)
            .filter(|k| !missing.contains(k))
            .map(|k| k as f64 * 0.1)
            .collect()
    }

    #[test]
    fn linear_signal_with_jitter_is_resampled_exactly() {
        // Jittered 10 Hz time stamps, a line through them.
        let t: Vec<f64> = (0..200)
            .map(|k| k as f64 * 0.1 + if k % 3 == 1 { 0.02 } else { 0.0 })
            .collect();
        let line = |v: f64| 3.0 * v - 2.0;
        let tab = table(t, &[("u", &line), ("x", &|v| -v)]);
        let (rec, gaps) = to_uniform(&tab, None).unwrap();
        assert!(gaps.is_empty());
        assert!(
            (rec.sample_rate_hz - 10.0).abs() < 1e-9,
            "{}",
            rec.sample_rate_hz
        );
        assert_eq!(rec.t0, 0.0);
        assert_eq!(rec.len(), 200);
        assert_eq!(rec.valid, vec![0..200]);
        assert_eq!(rec.names, ["u", "x"]);
        let u = rec.column("u").unwrap();
        for (j, &y) in u.iter().enumerate() {
            let tj = j as f64 / rec.sample_rate_hz;
            assert!(
                (y - line(tj)).abs() < 1e-9,
                "sample {j}: {y} vs {}",
                line(tj)
            );
        }
        // An explicit rate: 25 Hz over 19.92 s, the end on the grid.
        let (rec, _) = to_uniform(&tab, Some(25.0)).unwrap();
        assert_eq!(rec.len(), 499);
        assert!((rec.column("x").unwrap()[498] + 19.92).abs() < 1e-9);
    }

    #[test]
    fn a_three_sample_gap_is_bridged() {
        let t = ten_hz(99, 40..43); // 4.0, 4.1, 4.2 missing
        let tab = table(t, &[("u", &|v| v * v)]);
        let (rec, gaps) = to_uniform(&tab, None).unwrap();
        assert_eq!(gaps.len(), 1);
        assert_eq!((gaps[0].missing_samples, gaps[0].bridged), (3, true));
        assert_eq!(rec.len(), 100);
        assert_eq!(rec.valid, vec![0..100]);
        // Interpolated across: between 3.9² and 4.3².
        let u = rec.column("u").unwrap();
        let want = 3.9 * 3.9 + (4.3 * 4.3 - 3.9 * 3.9) * 0.25;
        assert!((u[40] - want).abs() < 1e-9);
    }

    #[test]
    fn a_twenty_sample_gap_splits_valid_into_two_blocks() {
        let t = ten_hz(99, 50..70); // 5.0 … 6.9 missing
        let tab = table(t, &[("u", &|v| v)]);
        let (rec, gaps) = to_uniform(&tab, None).unwrap();
        assert_eq!(gaps.len(), 1);
        assert_eq!((gaps[0].start_t, gaps[0].end_t), (4.9, 7.0));
        assert_eq!((gaps[0].missing_samples, gaps[0].bridged), (20, false));
        assert_eq!(rec.len(), 100);
        assert_eq!(rec.valid, [0..50, 70..100]);
        assert!((rec.valid_duration_s() - 8.0).abs() < 1e-9);
        // Inside the gap the values are interpolated, not NaN.
        assert!((rec.column("u").unwrap()[60] - 6.0).abs() < 1e-9);

        // At 4 Hz (grid 0, 0.25, …): inside (4.9, 7.0) lie 5.0 … 6.75.
        let (rec, _) = to_uniform(&tab, Some(4.0)).unwrap();
        assert_eq!(rec.len(), 40);
        assert_eq!(rec.valid, [0..20, 28..40]);
    }

    #[test]
    fn gaps_at_the_edges_and_several_long_gaps() {
        let mut t = ten_hz(30, 1..9); // 8 missing after t = 0
        t.extend((40..=60).map(|k| k as f64 * 0.1)); // 9 missing after 3.0
        let tab = table(t, &[("u", &|v| v)]);
        let (rec, gaps) = to_uniform(&tab, None).unwrap();
        assert_eq!(
            gaps.iter().map(|g| g.missing_samples).collect::<Vec<_>>(),
            [8, 9]
        );
        assert_eq!(rec.valid, [0..1, 9..31, 40..61]);
    }

    #[test]
    fn bad_tables_and_rates_are_errors() {
        let tab = table(vec![0.0, 0.1, 0.2], &[("u", &|v| v)]);
        for r in [
            0.0,
            -1.0,
            f64::NAN,
            f64::INFINITY,
            1e-308,
            0.009,
            1000.1,
            1e12,
        ] {
            assert_eq!(
                to_uniform(&tab, Some(r)).unwrap_err().kind,
                LogErrorKind::InvalidRate
            );
        }
        assert_eq!(
            to_uniform(&tab, Some(1e-308)).unwrap_err().message,
            "the resampling rate must be between 0.01 and 1000 Hz (got 1e-308)"
        );
        let long = table(vec![0.0, 1e9], &[("u", &|v| v)]);
        let e = to_uniform(&long, Some(1000.0)).unwrap_err();
        assert_eq!(e.kind, LogErrorKind::TooLarge);
        let one = table(vec![0.0], &[("u", &|v| v)]);
        assert_eq!(
            to_uniform(&one, None).unwrap_err().kind,
            LogErrorKind::TooFewRows
        );
        let back = table(vec![0.0, 0.2, 0.1], &[("u", &|v| v)]);
        let e = to_uniform(&back, None).unwrap_err();
        assert_eq!(
            (e.kind, e.column.as_deref()),
            (LogErrorKind::NonMonotonicTime, Some("t"))
        );
        let same = table(vec![0.0, 0.1, 0.1], &[]);
        assert_eq!(
            to_uniform(&same, None).unwrap_err().kind,
            LogErrorKind::DuplicateTime
        );
        let mut short = tab.clone();
        short.data[0].pop();
        let e = to_uniform(&short, None).unwrap_err();
        assert_eq!(
            (e.kind, e.column.as_deref()),
            (LogErrorKind::RaggedRow, Some("u"))
        );
        let mut nan = tab.clone();
        nan.data[0][1] = f64::NAN;
        assert_eq!(
            to_uniform(&nan, None).unwrap_err().kind,
            LogErrorKind::NonFinite
        );
        // A time stamp off by a year: refused, not allocated.
        let jump = table(vec![0.0, 0.1, 0.2, 3.2e7], &[("u", &|v| v)]);
        assert_eq!(
            to_uniform(&jump, None).unwrap_err().kind,
            LogErrorKind::TooLarge
        );
    }

    #[test]
    fn zero_order_hold_keeps_the_last_sample() {
        let t = [0.0, 1.0, 2.5];
        let x = [10.0, 20.0, 30.0];
        let at = [-1.0, 0.0, 0.99, 1.0, 2.0, 2.5, 9.0, 0.5];
        assert_eq!(
            zoh(&t, &x, &at),
            [10.0, 10.0, 10.0, 20.0, 20.0, 30.0, 30.0, 10.0]
        );
        assert!(zoh(&[], &[], &[1.0])[0].is_nan());
    }
}
