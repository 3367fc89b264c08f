//! The merge's cautions in plain words: rates, the offset used and where it
//! came from, the overlap.

use super::decide::{Chosen, OffsetSource, PooledValue};
use super::offset::{Confidence, OffsetEstimate};

/// `residual_relative` above which the report warns.
const RESIDUAL_WARNING: f64 = 0.2;
/// |z| between the own estimate and the offset used beyond which they are
/// said to disagree.
const DISAGREE_Z: f64 = 4.0;

/// What the warnings are about.
pub(crate) struct Context<'a> {
    pub shared: &'a str,
    pub own: Option<&'a OffsetEstimate>,
    pub chosen: Chosen,
    pub pooled: Option<PooledValue>,
    pub fs: f64,
    pub control_rate_hz: f64,
    pub nav_rate_hz: f64,
    pub hold: bool,
    pub overlap: f64,
    pub control_span: f64,
    pub nav_span: f64,
}

/// A number without trailing zeros: 10 → "10", 12.5 → "12.5".
pub(crate) fn fmt_num(v: f64) -> String {
    let s = format!("{v:.3}");
    s.trim_end_matches('0').trim_end_matches('.').to_owned()
}

/// An offset with its standard deviation, with the digits the σ supports:
/// `7.43002 ± 0.00050 s`, `1.699 ± 272.840 s`, `7.500 s` (no σ: set by hand).
pub fn offset_words(offset_s: f64, std_s: Option<f64>) -> String {
    match std_s {
        Some(s) if s > 0.0 && s.is_finite() => {
            let d = ((-s.log10()).ceil() as i64 + 1).clamp(3, 6) as usize;
            format!("{offset_s:.d$} ± {s:.d$} s")
        }
        _ => format!("{offset_s:.3} s"),
    }
}

/// The source of an offset in words ("hand-set run", "pooled", …).
pub(crate) fn source_words(source: OffsetSource) -> &'static str {
    match source {
        OffsetSource::UserRun => "run's hand-set",
        OffsetSource::UserCampaign => "campaign's hand-set",
        OffsetSource::Own => "estimated",
        OffsetSource::Pooled => "campaign's pooled",
        OffsetSource::WeakOwn => "weakly estimated",
    }
}

pub(crate) fn rate_warnings(c: &Context) -> Vec<String> {
    let mut w = Vec::new();
    if c.control_rate_hz < c.nav_rate_hz * 0.99 {
        w.push(format!(
            "the control log ({} Hz) is slower than the navigation log ({} Hz): the inputs are known only every {} s",
            fmt_num(c.control_rate_hz),
            fmt_num(c.nav_rate_hz),
            fmt_num(1.0 / c.control_rate_hz)
        ));
    }
    if c.fs > c.control_rate_hz * 1.01 {
        w.push(format!(
            "the inputs are held (zero-order hold) from {} Hz up to {} Hz: the extra samples repeat the last command, they are not new information",
            fmt_num(c.control_rate_hz),
            fmt_num(c.fs)
        ));
    } else if !c.hold {
        w.push(format!(
            "the inputs are averaged over {} s to go from {} Hz down to {} Hz",
            fmt_num(1.0 / c.fs),
            fmt_num(c.control_rate_hz),
            fmt_num(c.fs)
        ));
    }
    if c.fs > c.nav_rate_hz * 1.01 {
        w.push(format!(
            "the navigation log ({} Hz) is interpolated linearly up to {} Hz: the samples in between are not measured",
            fmt_num(c.nav_rate_hz),
            fmt_num(c.fs)
        ));
    }
    w
}

/// The offset used, where it came from, and how it compares with the own
/// estimate.
pub(crate) fn offset_warnings(c: &Context) -> Vec<String> {
    let mut w = Vec::new();
    let plot = format!("check it by plotting {0} and {0}_control", c.shared);
    let ch = c.chosen;
    let own_words = |o: &OffsetEstimate| {
        format!(
            "its own estimate is {} ({})",
            offset_words(o.offset_s, Some(o.std_error_s)),
            o.reason
        )
    };
    match ch.source {
        OffsetSource::Own => {
            if let Some(o) = c.own
                && o.confidence == Confidence::Medium
            {
                w.push(format!(
                    "the clock offset {} is only moderately certain (correlation {:.2}, peak ratio {:.2}); {plot}",
                    offset_words(o.offset_s, Some(o.std_error_s)),
                    o.correlation,
                    o.peak_ratio
                ));
            }
        }
        OffsetSource::WeakOwn => {
            if let Some(o) = c.own {
                w.push(format!(
                    "THE CLOCK OFFSET IS NOT RELIABLE: {} is this run's own estimate, which is not informative — {}. No campaign offset was available to replace it: set the run's or the campaign's offset by hand, or upload a run of this campaign whose {} changes clearly; {plot}",
                    offset_words(o.offset_s, Some(o.std_error_s)),
                    o.reason,
                    c.shared
                ));
            }
        }
        OffsetSource::Pooled => {
            let p = c.pooled.map_or(String::new(), |p| {
                format!(
                    " ({:.3} ± {:.3} s from {} run(s))",
                    p.offset_s, p.std_s, p.runs
                )
            });
            let own = match (c.own, c.pooled) {
                (Some(o), Some(q)) if q.includes_own => format!(
                    "it combines this run's own informative estimate {} with the consistent runs' of the campaign",
                    offset_words(o.offset_s, Some(o.std_error_s))
                ),
                (Some(o), _) => own_words(o),
                (None, _) => "it has no own estimate".to_owned(),
            };
            w.push(format!(
                "the campaign's pooled clock offset is used{p}: {own}"
            ));
        }
        OffsetSource::UserRun | OffsetSource::UserCampaign => {
            let own = c
                .own
                .map_or_else(String::new, |o| format!("; {}", own_words(o)));
            w.push(format!(
                "the clock offset {} is the {} one{own}",
                offset_words(ch.offset_s, None),
                source_words(ch.source)
            ));
        }
    }
    // An informative own estimate that disagrees with what was used.
    if let Some(o) = c.own
        && o.informative
        && ch.source != OffsetSource::Own
    {
        let z = (o.offset_s - ch.offset_s) / o.std_error_s.hypot(ch.std_s.unwrap_or(0.0));
        if z.abs() > DISAGREE_Z {
            w.push(format!(
                "the run's own informative estimate {} disagrees with the {} offset {} used (z = {z:.1})",
                offset_words(o.offset_s, Some(o.std_error_s)),
                source_words(ch.source),
                offset_words(ch.offset_s, ch.std_s)
            ));
        }
    }
    if let (OffsetSource::Own, Some(o), Some(p)) = (ch.source, c.own, c.pooled) {
        let z = (o.offset_s - p.offset_s) / o.std_error_s.hypot(p.std_s);
        if z.abs() > DISAGREE_Z {
            w.push(format!(
                "this run's offset {} disagrees with the campaign's pooled {} (z = {z:.1}): were its computers' clocks reset?",
                offset_words(o.offset_s, Some(o.std_error_s)),
                offset_words(p.offset_s, Some(p.std_s))
            ));
        }
    }
    if let Some(o) = c.own
        && matches!(ch.source, OffsetSource::Own | OffsetSource::WeakOwn)
        && o.residual_relative > RESIDUAL_WARNING
    {
        w.push(format!(
            "after alignment {} still differs between the logs by {:.0} % of its variation: the logs may not record the same quantity (sensor, units, sign), or a clock drifts",
            c.shared,
            100.0 * o.residual_relative
        ));
    }
    w
}

pub(crate) fn overlap_warnings(c: &Context) -> Vec<String> {
    let mut w = Vec::new();
    for (log, span) in [
        ("control log", c.control_span),
        ("navigation log", c.nav_span),
    ] {
        if span > 0.0 && c.overlap < 0.8 * span {
            w.push(format!(
                "only {:.0} % of the {log} ({:.1} s of {:.1} s) overlaps the other log; the rest is dropped",
                100.0 * c.overlap / span,
                c.overlap,
                span
            ));
        }
    }
    w
}
