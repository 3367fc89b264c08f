//! Residual-test results in the words a control engineer acts on: what is
//! wrong with the model, not which statistic tripped.

use super::report::{Divergences, RestartedWindows};
use super::residuals::{CrossCorrelation, ResidualAnalysis};
use crate::numbers::{p_value, percent, quantity, seconds, sig3};

/// At most this many lag groups are spelled out in one finding.
const MAX_LAG_GROUPS: usize = 5;

/// What a channel verdict is made of.
pub(crate) struct Facts<'a> {
    /// Residual analysis of the 1-step errors (`None`: diverged).
    pub one_step: Option<&'a ResidualAnalysis>,
    /// Of the k-step errors.
    pub k_step: Option<&'a ResidualAnalysis>,
    /// The prediction horizon of `k_step`.
    pub k: usize,
    /// Input–residual cross-correlations.
    pub cross: &'a [CrossCorrelation],
    /// 1 − confidence.
    pub alpha: f64,
    /// Unit of the channel.
    pub unit: &'a str,
    /// Fit of the restarted free runs.
    pub fit_restarted: Option<f64>,
    /// Fit of the whole-record free run.
    pub fit_simulation: Option<f64>,
    /// Restart period (s).
    pub restart_s: f64,
    /// Windows of the restarted free runs.
    pub restarted: &'a RestartedWindows,
    /// Where the predictions diverged.
    pub diverged: &'a Divergences,
}

/// Findings for one output channel, most important first: divergences,
/// then the residual tests, then a free run worse than the mean.
pub(crate) fn channel_findings(f: &Facts<'_>) -> Vec<String> {
    let mut out = Vec::new();
    let d = f.diverged;
    if let Some(x) = &d.one_step {
        out.push(format!(
            "{}; the model is unusable even one sample ahead",
            x.text
        ));
    }
    if let Some(x) = &d.k_step {
        out.push(format!("{}; no {}-step fit", x.text, f.k));
    }
    if let Some(x) = &d.simulation {
        out.push(format!("{}; no free-run fit", x.text));
    }
    if let Some(x) = &d.restarted {
        let w = f.restarted;
        let rest = if w.diverged < w.windows {
            format!(
                "fit over the other {}: {}",
                w.windows - w.diverged,
                percent(f.fit_restarted)
            )
        } else {
            "no restarted fit".to_owned()
        };
        out.push(format!(
            "{} of {} free runs restarted every {} diverged, the first at t = {}, {} after its restart; {rest}",
            w.diverged,
            w.windows,
            seconds(f.restart_s),
            seconds(x.t_s),
            seconds(x.after_s),
        ));
    }
    if let Some(one_step) = f.one_step {
        residual_findings(&mut out, one_step, f);
    }
    if let Some(k_step) = f.k_step.filter(|a| !a.white) {
        let lags = &k_step.autocorrelation.lags_outside;
        out.push(format!(
            "{}-step residual correlated beyond the horizon at lags {}: slow dynamics missed",
            f.k,
            lag_groups(lags.iter().map(|&l| l as i64))
        ));
    }
    if let Some(fit) = f.fit_simulation.filter(|x| *x < 0.0) {
        out.push(format!(
            "free-run simulation does worse than the mean (fit {}): the model drifts",
            percent(Some(fit))
        ));
    }
    out
}

/// What the 1-step residual tests say.
fn residual_findings(out: &mut Vec<String>, one_step: &ResidualAnalysis, f: &Facts<'_>) {
    if one_step.white {
        out.push("residuals white".to_owned());
    } else {
        let lags = &one_step.autocorrelation.lags_outside;
        out.push(if lags.is_empty() {
            format!(
                "residual correlated (Ljung–Box {}): unmodelled dynamics",
                p_value(one_step.whiteness_p_value)
            )
        } else {
            format!(
                "residual correlated at lag{} {}: unmodelled dynamics",
                if lags.len() > 1 { "s" } else { "" },
                lag_groups(lags.iter().map(|&l| l as i64))
            )
        });
    }
    for c in f.cross {
        if c.leak {
            let place = if c.peak_lag == 0 {
                "lag 0 (the same sample): direct feedthrough or a time misalignment".to_owned()
            } else {
                format!("lag {}: missing coupling or delay", c.peak_lag)
            };
            out.push(format!(
                "input {} leaks into the residual at {place}",
                c.input
            ));
        } else if c.feedback {
            let lags = c.lags_outside.iter().copied().filter(|l| *l < 0);
            out.push(format!(
                "residual precedes input {} (lags {}): controller feedback, expected in closed loop",
                c.input,
                lag_groups(lags)
            ));
        }
    }
    if one_step.offset.significant {
        out.push(format!(
            "residual mean {} ± {} is not zero: offset (uncompensated g(η) or tether moment, current, sensor bias)",
            sig3(one_step.offset.mean),
            quantity(one_step.offset.std_error, f.unit)
        ));
    }
    let zc = &one_step.zero_crossings;
    if zc.p_value < f.alpha {
        let counts = format!(
            "{} against {} ± {} for white noise",
            zc.count,
            sig3(zc.expected),
            sig3(zc.std)
        );
        out.push(if zc.z < 0.0 {
            format!("too few zero crossings ({counts}): slow residual or offset")
        } else {
            format!(
                "too many zero crossings ({counts}): the residual alternates sign, noise fed through the predictor"
            )
        });
    }
    let nm = &one_step.normality;
    if nm.p_value < f.alpha {
        out.push(format!(
            "residuals not normal (skewness {}, excess kurtosis {}): outliers or heavy tails, the bounds are approximate",
            sig3(nm.skewness),
            sig3(nm.excess_kurtosis)
        ));
    }
}

/// Sorted lags as runs: `1–7, 12, 15–16`, cut after a few groups.
pub(crate) fn lag_groups(lags: impl IntoIterator<Item = i64>) -> String {
    let mut groups: Vec<(i64, i64)> = Vec::new();
    for l in lags {
        match groups.last_mut() {
            Some((_, hi)) if *hi + 1 == l => *hi = l,
            _ => groups.push((l, l)),
        }
    }
    let shown: Vec<String> = groups
        .iter()
        .take(MAX_LAG_GROUPS)
        .map(|&(lo, hi)| {
            let m = |l: i64| format!("{l}").replace('-', "−");
            if lo == hi {
                m(lo)
            } else if lo < 0 {
                format!("{} to {}", m(lo), m(hi))
            } else {
                format!("{lo}–{hi}")
            }
        })
        .collect();
    let more = if groups.len() > MAX_LAG_GROUPS {
        ", …"
    } else {
        ""
    };
    format!("{}{more}", shown.join(", "))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lags_are_grouped_into_runs() {
        assert_eq!(lag_groups([1, 2, 3, 4, 5, 6, 7, 12]), "1–7, 12");
        assert_eq!(lag_groups([-3, -2, 4]), "−3 to −2, 4");
        assert_eq!(lag_groups([1, 3, 5, 7, 9, 11]), "1, 3, 5, 7, 9, …");
    }
}
