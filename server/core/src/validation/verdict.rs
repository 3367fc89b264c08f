//! Residual-test results in the words a control engineer acts on: what is
//! wrong with the model, not which statistic tripped.

use super::residuals::{CrossCorrelation, ResidualAnalysis};

/// At most this many lag groups are spelled out in one finding.
const MAX_LAG_GROUPS: usize = 5;

/// The fits a channel verdict mentions.
pub(crate) struct Fits {
    pub simulation: Option<f64>,
}

/// Findings for one output channel, most important first. `alpha` is
/// 1 − confidence; `k` the prediction horizon of `k_step`.
pub(crate) fn channel_findings(
    one_step: &ResidualAnalysis,
    k_step: &ResidualAnalysis,
    k: usize,
    cross: &[CrossCorrelation],
    fits: &Fits,
    alpha: f64,
) -> Vec<String> {
    let mut out = Vec::new();
    if one_step.white {
        out.push("residuals white".to_owned());
    } else {
        let lags = &one_step.autocorrelation.lags_outside;
        out.push(if lags.is_empty() {
            format!(
                "residual correlated (Ljung–Box p = {}): unmodelled dynamics",
                num(one_step.whiteness_p_value)
            )
        } else {
            format!(
                "residual correlated at lag{} {}: unmodelled dynamics",
                if lags.len() > 1 { "s" } else { "" },
                lag_groups(lags.iter().map(|&l| l as i64))
            )
        });
    }
    for c in cross {
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
            num(one_step.offset.mean),
            num(one_step.offset.std_error)
        ));
    }
    let zc = &one_step.zero_crossings;
    if zc.p_value < alpha {
        let counts = format!(
            "{} against {} ± {} for white noise",
            zc.count,
            num(zc.expected),
            num(zc.std)
        );
        out.push(if zc.z < 0.0 {
            format!("too few zero crossings ({counts}): slow residual or offset")
        } else {
            format!(
                "too many zero crossings ({counts}): the residual alternates sign, noise fed through the predictor"
            )
        });
    }
    if !k_step.white {
        let lags = &k_step.autocorrelation.lags_outside;
        out.push(format!(
            "{k}-step residual correlated beyond the horizon at lags {}: slow dynamics missed",
            lag_groups(lags.iter().map(|&l| l as i64))
        ));
    }
    let nm = &one_step.normality;
    if nm.p_value < alpha {
        out.push(format!(
            "residuals not normal (skewness {}, excess kurtosis {}): outliers or heavy tails, the bounds are approximate",
            num(nm.skewness),
            num(nm.excess_kurtosis)
        ));
    }
    if let Some(f) = fits.simulation.filter(|f| *f < 0.0) {
        out.push(format!(
            "free-run simulation does worse than the mean (fit {}): the model drifts",
            num(f)
        ));
    }
    out
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

/// Three significant digits, as elsewhere in the reports.
fn num(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let mag = x.abs().log10().floor();
    if !(-4.0..6.0).contains(&mag) {
        return format!("{x:.2e}");
    }
    let decimals = (2.0 - mag).max(0.0) as usize;
    let s = format!("{x:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_owned()
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lags_are_grouped_into_runs() {
        assert_eq!(lag_groups([1, 2, 3, 4, 5, 6, 7, 12]), "1–7, 12");
        assert_eq!(lag_groups([-3, -2, 4]), "−3 to −2, 4");
        assert_eq!(lag_groups([1, 3, 5, 7, 9, 11]), "1, 3, 5, 7, 9, …");
        assert_eq!(num(0.012345), "0.0123");
        assert_eq!(num(1999.5), "2000");
    }
}
