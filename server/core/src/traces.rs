//! A logged record prepared for a time plot of every channel: the window
//! [from, to] at full resolution when it is short, else each bucket of
//! samples as its minimum and its maximum (the envelope survives, spikes
//! included), and the statistics of the window from every sample. Samples
//! outside the record's valid blocks are gaps (null), not numbers.

use serde::Serialize;

use crate::identification::export_state_space::{input_unit, output_unit};
use crate::timeseries::UniformRecord;

/// SI unit of a log column (the log contract): N, N·m, m/s, rad/s, m, rad,
/// `-` for normalized thruster commands and unknown columns.
pub fn column_unit(name: &str) -> String {
    let u = input_unit(name);
    if u != "-" {
        return u;
    }
    output_unit(name)
}

/// Statistics of one channel over the window's valid samples.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct WindowStats {
    /// Valid samples in the window.
    pub n: usize,
    /// Mean (absent without valid samples).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mean: Option<f64>,
    /// Standard deviation (population, 1/N).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub std: Option<f64>,
    /// Root mean square.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rms: Option<f64>,
    /// Smallest value.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub min: Option<f64>,
    /// Largest value.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max: Option<f64>,
}

/// One channel of the plot.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct Trace {
    /// Log column.
    pub name: String,
    /// SI unit.
    pub unit: String,
    /// Value per entry of `time_s` (null in a gap).
    pub values: Vec<Option<f64>>,
    /// Statistics of the window from every sample.
    pub stats: WindowStats,
}

/// The plot of a window of a record.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct TracePlot {
    /// Sample rate of the record (Hz).
    pub sample_rate_hz: f64,
    /// Whole record: first and last sample time (s).
    pub record_s: [f64; 2],
    /// The window shown (s), within the record.
    pub window_s: [f64; 2],
    /// Samples in the window.
    pub n_samples: usize,
    /// Samples per bucket (1: every sample is shown; else each bucket
    /// gives two points, its minimum then its maximum).
    pub stride: usize,
    /// Time of each point (s).
    pub time_s: Vec<f64>,
    /// Every channel in the record's column order.
    pub channels: Vec<Trace>,
}

fn stats(values: &[f64], valid: &[bool]) -> WindowStats {
    let xs: Vec<f64> = values
        .iter()
        .zip(valid)
        .filter(|(v, ok)| **ok && v.is_finite())
        .map(|(v, _)| *v)
        .collect();
    let n = xs.len();
    if n == 0 {
        return WindowStats {
            n,
            mean: None,
            std: None,
            rms: None,
            min: None,
            max: None,
        };
    }
    let mean = xs.iter().sum::<f64>() / n as f64;
    let var = xs.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / n as f64;
    let ms = xs.iter().map(|x| x * x).sum::<f64>() / n as f64;
    WindowStats {
        n,
        mean: Some(mean),
        std: Some(var.sqrt()),
        rms: Some(ms.sqrt()),
        min: xs.iter().copied().reduce(f64::min),
        max: xs.iter().copied().reduce(f64::max),
    }
}

/// The samples `i0..=i1` of the window [`from_s`, `to_s`] (default: the
/// whole record), clipped to the record. `Err` names the bad field.
pub fn window_indices(
    rec: &UniformRecord,
    from_s: Option<f64>,
    to_s: Option<f64>,
) -> Result<(usize, usize), (&'static str, String)> {
    let n = rec.len();
    if n == 0 {
        return Err(("run_id", "the record has no samples".into()));
    }
    let dt = 1.0 / rec.sample_rate_hz;
    let t_of = |k: usize| rec.t0 + k as f64 * dt;
    let (t_first, t_last) = (t_of(0), t_of(n - 1));
    for (field, v) in [("from_s", from_s), ("to_s", to_s)] {
        if v.is_some_and(|v| !v.is_finite()) {
            return Err((field, "must be a finite number of seconds".into()));
        }
    }
    let from = from_s.unwrap_or(t_first).max(t_first);
    let to = to_s.unwrap_or(t_last).min(t_last);
    if to <= from || to.is_nan() || from.is_nan() {
        return Err((
            "to_s",
            format!(
                "the window must end after it starts and overlap the record ({t_first:.3}–{t_last:.3} s); got {from:.3}–{to:.3} s"
            ),
        ));
    }
    let i0 = (((from - rec.t0) / dt).ceil().max(0.0) as usize).min(n - 1);
    let i1 = (((to - rec.t0) / dt).floor().max(0.0) as usize).min(n - 1);
    Ok((i0, i1))
}

/// The record cut to the window [`from_s`, `to_s`] (see
/// [`window_indices`]): its samples, valid blocks and start time, as if the
/// log held only those rows.
pub fn cut(
    rec: &UniformRecord,
    from_s: Option<f64>,
    to_s: Option<f64>,
) -> Result<UniformRecord, (&'static str, String)> {
    let (i0, i1) = window_indices(rec, from_s, to_s)?;
    Ok(UniformRecord {
        sample_rate_hz: rec.sample_rate_hz,
        t0: rec.t0 + i0 as f64 / rec.sample_rate_hz,
        names: rec.names.clone(),
        data: rec.data.iter().map(|c| c[i0..=i1].to_vec()).collect(),
        valid: rec
            .valid
            .iter()
            .map(|r| r.start.max(i0)..r.end.min(i1 + 1))
            .filter(|r| r.start < r.end)
            .map(|r| r.start - i0..r.end - i0)
            .collect(),
    })
}

/// The window [`from_s`, `to_s`] (default: the whole record) with at most
/// about `points` points per channel. `Err` names the bad field.
pub fn trace_plot(
    rec: &UniformRecord,
    from_s: Option<f64>,
    to_s: Option<f64>,
    points: usize,
) -> Result<TracePlot, (&'static str, String)> {
    let (i0, i1) = window_indices(rec, from_s, to_s)?;
    let dt = 1.0 / rec.sample_rate_hz;
    let t_of = |k: usize| rec.t0 + k as f64 * dt;
    let (t_first, t_last) = (t_of(0), t_of(rec.len() - 1));
    let len = i1 + 1 - i0;
    let mut valid = vec![false; len];
    for r in &rec.valid {
        for k in r.start.max(i0)..r.end.min(i1 + 1) {
            valid[k - i0] = true;
        }
    }
    let points = points.max(2);
    let stride = if len <= points {
        1
    } else {
        len.div_ceil(points / 2)
    };
    let mut time_s = Vec::new();
    let mut buckets = Vec::new();
    let mut s = 0;
    while s < len {
        let e = (s + stride).min(len);
        buckets.push((s, e));
        time_s.push(t_of(i0 + s));
        if stride > 1 {
            time_s.push(t_of(i0 + (s + e) / 2));
        }
        s = e;
    }
    let channels = rec
        .names
        .iter()
        .zip(&rec.data)
        .map(|(name, col)| {
            let w = &col[i0..=i1];
            let ok = |k: usize| valid[k] && w[k].is_finite();
            let mut values = Vec::with_capacity(time_s.len());
            for &(s, e) in &buckets {
                if stride == 1 {
                    values.push(ok(s).then(|| w[s]));
                    continue;
                }
                let vs: Vec<f64> = (s..e).filter(|&k| ok(k)).map(|k| w[k]).collect();
                values.push(vs.iter().copied().reduce(f64::min));
                values.push(vs.iter().copied().reduce(f64::max));
            }
            Trace {
                name: name.clone(),
                unit: column_unit(name),
                values,
                stats: stats(w, &valid),
            }
        })
        .collect();
    Ok(TracePlot {
        sample_rate_hz: rec.sample_rate_hz,
        record_s: [t_first, t_last],
        window_s: [t_of(i0), t_of(i1)],
        n_samples: len,
        stride,
        time_s,
        channels,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(n: usize) -> UniformRecord {
        UniformRecord {
            sample_rate_hz: 10.0,
            t0: 0.0,
            names: vec!["tau_X".into(), "u".into()],
            data: vec![
                (0..n).map(|k| (k as f64 * 0.1).sin()).collect(),
                (0..n)
                    .map(|k| if k == 537 { 9.0 } else { k as f64 })
                    .collect(),
            ],
            valid: std::iter::once(0..n).collect(),
        }
    }

    #[test]
    fn a_cut_record_is_the_window_s_samples_with_its_valid_blocks() {
        let rec = UniformRecord {
            sample_rate_hz: 10.0,
            t0: 5.0,
            names: vec!["u".into()],
            data: vec![(0..100).map(f64::from).collect()],
            valid: vec![0..30, 40..100],
        };
        // 6.0–9.0 s: samples 10..=40, the gap 30..40 kept as a gap.
        let w = super::cut(&rec, Some(6.0), Some(9.0)).unwrap();
        assert_eq!(w.t0, 6.0);
        assert_eq!(w.data[0].first(), Some(&10.0));
        assert_eq!(w.data[0].last(), Some(&40.0));
        assert_eq!(w.valid, vec![0..20, 30..31]);
        assert_eq!(
            super::cut(&rec, Some(9.0), Some(6.0)).unwrap_err().0,
            "to_s"
        );
        assert_eq!(
            super::cut(&rec, Some(f64::NAN), None).unwrap_err().0,
            "from_s"
        );
    }

    #[test]
    fn short_windows_are_exact_and_stats_are_the_sample_ones() {
        let r = record(1000);
        let p = trace_plot(&r, Some(1.0), Some(2.0), 500).unwrap();
        assert_eq!(p.stride, 1);
        assert_eq!(p.n_samples, 11);
        assert_eq!(p.time_s[0], 1.0);
        assert_eq!(p.channels[1].unit, "m/s");
        assert_eq!(p.channels[0].unit, "N");
        // u = 10…20: mean 15, population variance 10.
        let s = &p.channels[1].stats;
        assert_eq!(s.n, 11);
        assert!((s.mean.unwrap() - 15.0).abs() < 1e-12);
        assert!((s.std.unwrap() - 10f64.sqrt()).abs() < 1e-12);
        assert_eq!((s.min, s.max), (Some(10.0), Some(20.0)));
    }

    #[test]
    fn long_windows_keep_each_buckets_extremes_and_gaps_are_null() {
        let mut r = record(10_000);
        r.valid = vec![0..5000, 6000..10_000];
        let p = trace_plot(&r, None, None, 200).unwrap();
        assert!(p.stride > 1 && p.time_s.len() <= 202);
        let u = &p.channels[1].values;
        // The dip to 9 at sample 537 survives as a bucket minimum.
        assert!(u.iter().flatten().any(|v| *v == 9.0));
        // The gap 500–600 s shows as nulls.
        let k = p.time_s.iter().position(|t| *t >= 520.0).unwrap();
        assert!(u[k].is_none() && u[k + 1].is_none());
        assert_eq!(p.channels[1].stats.n, 9000);
    }

    #[test]
    fn a_window_outside_the_record_names_the_field() {
        let r = record(100);
        let (field, msg) = trace_plot(&r, Some(50.0), Some(60.0), 100).unwrap_err();
        assert_eq!(field, "to_s");
        assert!(msg.contains("overlap"), "{msg}");
        assert_eq!(
            trace_plot(&r, Some(f64::NAN), None, 10).unwrap_err().0,
            "from_s"
        );
    }
}
