//! Plausibility warnings on a parsed log: units that look wrong and channels
//! that carry no information. Warnings never reject a log; the supervisor
//! decides. The rules:
//!
//! - **time in milliseconds**: the median interval of `t` (the sample
//!   interval) exceeds [`MS_MEDIAN_DT_S`] (5 s; loggers of ROVs and DP ships
//!   sample at 1 Hz or faster). The span of `t` is not a rule: a valid log
//!   in seconds may last more than a day, and an epoch clock is large in
//!   any unit. A millisecond clock at 200 Hz or faster (a step of 5 "s" or
//!   less) passes unnoticed;
//! - **roll in degrees**: max |`phi`| > π (+0.001 for rounding);
//! - **pitch in degrees**: max |`theta`| > π/2 (+0.001): Euler pitch lies in
//!   [−π/2, π/2];
//! - **heading in degrees**: max |`psi`| > 2π + 0.1, or the range
//!   (max − min) of `psi` exceeds 2π + 0.1. A heading in radians that is *unwrapped* over more than a
//!   full turn also trips this rule; the message says so;
//! - **rates in deg/s**: max |`p`|, |`q`| or |`r`| > 2π rad/s (a full turn
//!   per second);
//! - **constant column**: every value of a column other than `t` is the same
//!   (no excitation, or a dead sensor).
//!
//! Small angles logged in degrees (e.g. a roll of ±3°) pass these rules
//! unnoticed: ranges cannot tell them from radians.
//!
//! Every rule but the heading's and the constant column's is a doubt about
//! units ([`LogWarning::units`]): the run's verdicts wait for the fix. A
//! heading beyond a full turn may be an unwrapped heading in radians.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use serde::Serialize;

use crate::timeseries::LogTable;

/// Median time step (s) above which `t` is suspected to be in milliseconds.
pub const MS_MEDIAN_DT_S: f64 = 5.0;
/// Slack on the roll/pitch bounds for values rounded at ±π or ±π/2.
const ANGLE_SLACK: f64 = 1e-3;
/// Slack on the heading bounds (unwrapping overshoot).
const HEADING_SLACK: f64 = 0.1;

/// A doubt about a log that does not stop its use.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct LogWarning {
    /// The column concerned, if one is.
    pub column: Option<String>,
    /// What looks wrong and what to do, for people.
    pub message: String,
    /// The doubt is about units (time in milliseconds, angles in degrees,
    /// rates in deg/s): the log's numbers cannot be judged until it is fixed.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub units: bool,
}

impl LogWarning {
    /// A warning about one column.
    pub fn column(column: impl Into<String>, message: impl Into<String>) -> Self {
        LogWarning {
            column: Some(column.into()),
            message: message.into(),
            units: false,
        }
    }

    /// A doubt about the units of one column.
    pub fn units(column: impl Into<String>, message: impl Into<String>) -> Self {
        LogWarning {
            units: true,
            ..LogWarning::column(column, message)
        }
    }
}

/// All plausibility warnings of a table, `t` first, then columns in file
/// order. See the module documentation for the rules.
pub fn plausibility_warnings(table: &LogTable) -> Vec<LogWarning> {
    let mut out = Vec::new();
    if let Some(w) = time_warning(&table.t) {
        out.push(w);
    }
    for (name, x) in table.names.iter().zip(&table.data) {
        let Some((min, max)) = min_max(x) else {
            continue;
        };
        let amax = min.abs().max(max.abs());
        let degrees = |limit: f64| {
            (amax > limit).then(|| {
                LogWarning::units(
                    name.as_str(),
                    format!(
                        "{name} looks like degrees (max |{name}| = {}); the contract is radians: \
                         convert before identification",
                        short(amax)
                    ),
                )
            })
        };
        let doubt = match name.as_str() {
            "phi" => degrees(PI + ANGLE_SLACK),
            "theta" => degrees(FRAC_PI_2 + ANGLE_SLACK),
            // Beyond a full turn may also be radians unwrapped over several
            // turns: a doubt to read, not a reason to hold the verdicts.
            "psi" if amax > TAU + HEADING_SLACK || max - min > TAU + HEADING_SLACK => {
                Some(LogWarning::column(
                    name.as_str(),
                    format!(
                        "psi looks like degrees (max {}, range {}); the contract is radians: declare \
                 heading_unit deg (vessel profile or upload meta) or convert (if it is a \
                 heading in radians unwrapped over more than a full turn, ignore this)",
                        short(max),
                        short(max - min)
                    ),
                ))
            }
            "p" | "q" | "r" if amax > TAU => Some(LogWarning::units(
                name.as_str(),
                format!(
                    "{name} looks like deg/s (max |{name}| = {}, more than a full turn per \
                     second); the contract is rad/s: convert before identification",
                    short(amax)
                ),
            )),
            _ => None,
        };
        out.extend(doubt);
        if min == max {
            out.push(LogWarning::column(
                name.as_str(),
                format!(
                    "{name} is constant ({}) over the whole log: no excitation, or a dead sensor",
                    short(min)
                ),
            ));
        }
    }
    out
}

/// The milliseconds warning on `t`, from its sample interval.
fn time_warning(t: &[f64]) -> Option<LogWarning> {
    let dt = crate::timeseries::median_dt(t)?;
    if dt > MS_MEDIAN_DT_S {
        Some(LogWarning::units(
            "t",
            format!(
                "t looks like milliseconds (median step {}: a logger samples at 1 Hz or faster); \
                 the contract is seconds: divide by 1000 if so",
                short(dt)
            ),
        ))
    } else {
        None
    }
}

/// Smallest and largest value; `None` when empty.
fn min_max(x: &[f64]) -> Option<(f64, f64)> {
    let first = *x.first()?;
    Some(
        x.iter()
            .fold((first, first), |(lo, hi), &v| (lo.min(v), hi.max(v))),
    )
}

/// A number with about four significant digits, without trailing zeros;
/// outside 10⁻⁴ … 10⁶ in scientific notation (never 309 digits).
pub(crate) fn short(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    if !(1e-4..1e6).contains(&x.abs()) {
        let e = format!("{x:.3e}");
        return match e.split_once('e') {
            Some((m, exp)) if m.contains('.') => {
                format!("{}e{exp}", m.trim_end_matches('0').trim_end_matches('.'))
            }
            _ => e,
        };
    }
    let decimals = (3 - x.abs().log10().floor() as i32).clamp(0, 6) as usize;
    let s = format!("{x:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(t: Vec<f64>, cols: &[(&str, Vec<f64>)]) -> LogTable {
        LogTable {
            t,
            names: cols.iter().map(|(n, _)| n.to_string()).collect(),
            data: cols.iter().map(|(_, x)| x.clone()).collect(),
        }
    }

    fn columns(w: &[LogWarning]) -> Vec<&str> {
        w.iter().filter_map(|w| w.column.as_deref()).collect()
    }

    #[test]
    fn heading_in_degrees_is_flagged_and_radians_are_not() {
        let t: Vec<f64> = (0..100).map(|k| k as f64 * 0.1).collect();
        let deg: Vec<f64> = (0..100).map(|k| (k as f64 * 3.7) % 360.0).collect();
        let w = plausibility_warnings(&table(t.clone(), &[("psi", deg)]));
        assert_eq!(columns(&w), ["psi"]);
        assert!(
            w[0].message
                .starts_with("psi looks like degrees (max 358.9"),
            "{}",
            w[0].message
        );

        // Radians wrapped to (−π, π] and [0, 2π): no warning.
        let wrapped: Vec<f64> = (0..100).map(|k| ((k as f64 * 0.3) % TAU) - PI).collect();
        let positive: Vec<f64> = (0..100).map(|k| (k as f64 * 0.3) % TAU).collect();
        let w = plausibility_warnings(&table(t.clone(), &[("psi", wrapped), ("x", positive)]));
        assert!(w.is_empty(), "{w:?}");

        // A small heading change logged in degrees (10° → 20°).
        let small: Vec<f64> = (0..100).map(|k| 10.0 + k as f64 * 0.1).collect();
        assert_eq!(
            columns(&plausibility_warnings(&table(t, &[("psi", small)]))),
            ["psi"]
        );
    }

    #[test]
    fn roll_pitch_and_rates_in_degrees_are_flagged() {
        let t: Vec<f64> = (0..50).map(|k| k as f64 * 0.1).collect();
        let s = |a: f64| -> Vec<f64> { (0..50).map(|k| a * (k as f64 * 0.3).sin()).collect() };
        let tab = table(
            t,
            &[
                ("phi", s(5.0)),    // 5° roll
                ("theta", s(2.0)),  // 2° pitch: > π/2
                ("p", s(0.5)),      // rad/s: fine
                ("r", s(20.0)),     // 20 deg/s
                ("q", s(3.0)),      // 3 rad/s: fine
                ("theta2", s(9.0)), // unknown column: no unit rule
            ],
        );
        let w = plausibility_warnings(&tab);
        assert_eq!(columns(&w), ["phi", "theta", "r"]);
        assert!(w[2].message.starts_with("r looks like deg/s"));
        // 3° of roll passes (documented blind spot); π exactly passes.
        let tab = table(vec![0.0, 1.0, 2.0], &[("phi", vec![0.0, PI, -PI])]);
        assert!(plausibility_warnings(&tab).is_empty());
    }

    #[test]
    fn milliseconds_and_constant_columns_are_flagged() {
        // 10 Hz logged in ms.
        let t: Vec<f64> = (0..20).map(|k| 1000.0 + k as f64 * 100.0).collect();
        let w = plausibility_warnings(&table(t, &[("u", vec![0.0; 20])]));
        assert_eq!(columns(&w), ["t", "u"]);
        assert!(
            w[0].message
                .starts_with("t looks like milliseconds (median step 100:")
        );
        assert_eq!(
            w[1].message,
            "u is constant (0) over the whole log: no excitation, or a dead sensor"
        );
        // A valid 29-hour log in seconds at 1 Hz: no milliseconds warning
        // (the span of t used to trip it).
        let t: Vec<f64> = (0..29 * 3600).map(|k| k as f64).collect();
        let u: Vec<f64> = t.iter().map(|v| v.sin()).collect();
        assert!(plausibility_warnings(&table(t, &[("u", u)])).is_empty());
        // Epoch seconds at 10 Hz: large t, small step: fine.
        let t: Vec<f64> = (0..600).map(|k| 1.7e9 + k as f64 * 0.1).collect();
        let u: Vec<f64> = t.iter().map(|v| v.sin()).collect();
        assert!(plausibility_warnings(&table(t, &[("u", u)])).is_empty());
        // 1 Hz DP log of an hour: fine.
        let t: Vec<f64> = (0..3600).map(|k| k as f64).collect();
        let u: Vec<f64> = t.iter().map(|v| v.sin()).collect();
        assert!(plausibility_warnings(&table(t, &[("u", u)])).is_empty());
    }

    #[test]
    fn short_numbers() {
        assert_eq!(short(359.6), "359.6");
        assert_eq!(short(0.1), "0.1");
        assert_eq!(short(100.0), "100");
        assert_eq!(short(-12.3456), "-12.35");
        assert_eq!(short(123_456.0), "123456");
        assert_eq!(short(1e308), "1e308");
        assert_eq!(short(-2.5e-7), "-2.5e-7");
        assert_eq!(short(1_234_567.0), "1.235e6");
    }
}
