//! Divergence: a prediction that leaves every plausible range is a finding
//! ("diverged at t = 123.4 s in pitch"), never a number like −7e35.
//!
//! **Rule.** A prediction ŷ of a measured channel y is plausible while
//! |ŷ − ȳ| ≤ [`PLAUSIBLE_RANGES`] · (max y − min y), ȳ the measured mean, and
//! finite. Why 100 ranges: a model that merely drifts or misses a gain (fit
//! down to a few hundred percent below zero) stays far inside, since the
//! vessel never went further than one range from its mean in the record;
//! a simulation that grows like e^{λt} passes the band ln(100)/λ ≈ 4.6/λ
//! after it outgrows the measurement, so the reported time is where the
//! growth took over, and everything kept stays within 100 ranges — plots
//! and statistics keep meaningful magnitudes. A constant channel keeps a
//! scale: 10⁻⁹ of its magnitude, at least 10⁻¹².
//!
//! From the first implausible sample on, the prediction is cut (NaN, `null`
//! in JSON): its fit is `None` and the [`Divergence`] says when, in which
//! channel and how long after the prediction was started from the measured
//! state.

use serde::Serialize;

use crate::numbers::seconds;
use crate::planning::dof::Dof;

/// Half-width of the plausible band in measured ranges.
pub const PLAUSIBLE_RANGES: f64 = 100.0;

/// Smallest half-range a constant channel is given (its own units).
const MIN_SCALE: f64 = 1e-12;

/// The values a prediction of one measured channel may take.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlausibleBand {
    /// Lower end.
    pub lower: f64,
    /// Upper end.
    pub upper: f64,
}

impl PlausibleBand {
    /// ȳ ± [`PLAUSIBLE_RANGES`] · (max y − min y) over the finite samples of
    /// `measured`.
    pub fn of(measured: &[f64]) -> Self {
        let finite = || measured.iter().copied().filter(|v| v.is_finite());
        let n = finite().count().max(1) as f64;
        let mean = finite().sum::<f64>() / n;
        let lo = finite().fold(f64::INFINITY, f64::min);
        let hi = finite().fold(f64::NEG_INFINITY, f64::max);
        let range = if hi >= lo { hi - lo } else { 0.0 };
        let scale = range.max(1e-9 * mean.abs()).max(MIN_SCALE);
        PlausibleBand {
            lower: mean - PLAUSIBLE_RANGES * scale,
            upper: mean + PLAUSIBLE_RANGES * scale,
        }
    }

    /// `v` is finite and inside the band.
    pub fn contains(&self, v: f64) -> bool {
        v >= self.lower && v <= self.upper
    }
}

/// Why a prediction was taken as diverged.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum DivergenceReason {
    /// The prediction overflowed or became NaN.
    NonFinite,
    /// It left the plausible band (see `plausible`).
    OutOfRange,
}

/// Where a prediction of one channel left the plausible range.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct Divergence {
    /// Time of the first implausible sample from the record start (s).
    pub t_s: f64,
    /// Time since that prediction was started from the measured state (s):
    /// t for the free run, the time into its window for a restarted free
    /// run, k·h for a k-step prediction.
    pub after_s: f64,
    /// The output channel (ν symbol, or x, y, psi).
    pub output: String,
    /// Its DOF, when the output is a body velocity.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dof: Option<Dof>,
    /// Non-finite, or out of the plausible band.
    pub reason: DivergenceReason,
    /// The plausible band [lower, upper]: the measured mean ± 100 measured
    /// ranges (output units).
    pub plausible: [f64; 2],
    /// The finding in words.
    pub text: String,
}

/// Words for an output channel, `pitch (q)`, `x (north)`, and its unit.
pub(crate) fn channel_words(output: &str) -> (String, &'static str) {
    if let Some(d) = Dof::ALL.into_iter().find(|d| d.velocity_symbol() == output) {
        return (format!("{} ({output})", d.name()), d.velocity_unit());
    }
    match output {
        "x" => ("x (north)".into(), "m"),
        "y" => ("y (east)".into(), "m"),
        "psi" => ("heading ψ".into(), "rad"),
        other => (other.to_owned(), ""),
    }
}

/// One channel of a record as the plausibility check sees it.
pub(crate) struct Channel<'a> {
    /// Output name.
    pub output: &'a str,
    /// Measured samples.
    pub y: &'a [f64],
    /// Sample time (s).
    pub h: f64,
    /// Its plausible band.
    pub band: PlausibleBand,
}

impl Channel<'_> {
    /// First row of `rows` where `yhat` is implausible.
    pub fn first_outside(&self, yhat: &[f64], rows: std::ops::Range<usize>) -> Option<usize> {
        rows.into_iter().find(|&t| !self.band.contains(yhat[t]))
    }

    /// The divergence of `what` (`free-run simulation`, …), whose value at
    /// row `t` is `yhat`; `started` is the row the prediction was started
    /// from the measured state (`None`: the record start, a whole free run).
    pub fn divergence(
        &self,
        what: &str,
        yhat: f64,
        t: usize,
        started: Option<usize>,
    ) -> Divergence {
        let (words, _) = channel_words(self.output);
        let reason = if yhat.is_finite() {
            DivergenceReason::OutOfRange
        } else {
            DivergenceReason::NonFinite
        };
        let t_s = t as f64 * self.h;
        let after_s = (t - started.unwrap_or(0)) as f64 * self.h;
        let how = match reason {
            DivergenceReason::NonFinite => " (overflowed)",
            DivergenceReason::OutOfRange => "",
        };
        let since = match started {
            None => String::new(),
            Some(_) => format!(
                ", {} after its start from the measured state",
                seconds(after_s)
            ),
        };
        Divergence {
            t_s,
            after_s,
            output: self.output.to_owned(),
            dof: Dof::ALL
                .into_iter()
                .find(|d| d.velocity_symbol() == self.output),
            reason,
            plausible: [self.band.lower, self.band.upper],
            text: format!(
                "{what} diverged{how} at t = {} in {words}{since}",
                seconds(t_s)
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn band_is_a_hundred_ranges_around_the_mean() {
        let b = PlausibleBand::of(&[0.0, 1.0, 2.0, f64::NAN]);
        assert_eq!((b.lower, b.upper), (1.0 - 200.0, 1.0 + 200.0));
        assert!(b.contains(201.0) && !b.contains(201.1) && !b.contains(f64::NAN));
        assert!(!b.contains(f64::INFINITY));
        // A constant channel keeps a tiny scale rather than a zero-width band.
        let c = PlausibleBand::of(&[2.0, 2.0]);
        assert!(c.contains(2.0) && !c.contains(2.001));
    }

    #[test]
    fn the_finding_names_time_channel_and_restart() {
        let y = [0.0, 0.1];
        let ch = Channel {
            output: "q",
            y: &y,
            h: 0.1,
            band: PlausibleBand::of(&y),
        };
        let d = ch.divergence("free-run simulation", 1e30, 1234, None);
        assert_eq!(d.dof, Some(Dof::Pitch));
        assert_eq!(d.reason, DivergenceReason::OutOfRange);
        assert!((d.t_s - 123.4).abs() < 1e-9 && d.t_s == d.after_s);
        assert_eq!(
            d.text,
            "free-run simulation diverged at t = 123.4 s in pitch (q)"
        );
        assert_eq!(d.plausible, [0.05 - 10.0, 0.05 + 10.0]);
        let r = ch.divergence("restarted free run", f64::NAN, 432, Some(400));
        assert_eq!(r.reason, DivergenceReason::NonFinite);
        assert_eq!(
            r.text,
            "restarted free run diverged (overflowed) at t = 43.2 s in pitch (q), 3.2 s after its start from the measured state"
        );
        assert_eq!(channel_words("psi"), ("heading ψ".to_owned(), "rad"));
    }
}
