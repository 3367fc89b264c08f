//! The discovery cases as a table (the example's output).

use super::{Concealed, DiscoveryCase};
use seatrial_core::numbers::sig3;

/// The table of cases: one line each, then the gap rows of channels with a
/// gap.
pub fn format_cases(cases: &[DiscoveryCase]) -> String {
    let mut s = format!(
        "{:<24} {:>4}  {:<8} {:<7} {:<60} {:>18}\n",
        "case", "seed", "score", "stored", "named (grid points)", "fly/identify/discover s"
    );
    for c in cases {
        let named: Vec<String> = c
            .named
            .iter()
            .zip(&c.advantages)
            .take(4)
            .map(|((l, n, _), a)| {
                let a: Vec<String> = a
                    .iter()
                    .map(|a| a.map_or("lost".into(), |a| format!("{a:+.2}")))
                    .collect();
                format!("{l} ({n}/{}; {})", c.grid_points, a.join(" "))
            })
            .collect();
        s += &format!(
            "{:<24} {:>4}  {:<8} {:<7} {:<60} {:>5.0}/{:>5.0}/{:>5.1}\n",
            c.concealed.name(),
            c.seed,
            c.score(),
            if c.stored { "yes" } else { "no" },
            if named.is_empty() {
                "—".to_string()
            } else {
                named.join("; ")
            },
            c.secs[0],
            c.secs[1],
            c.secs[2]
        );
        for g in &c.gaps {
            let closed = g.closed();
            if closed.iter().all(Option::is_none) && std::env::var_os("ESTIMATES").is_none() {
                continue;
            }
            let f = |v: Option<f64>| v.map_or("—".into(), |x| format!("{x:.3}"));
            let pct = |v: Option<f64>| v.map_or("—".into(), |x| format!("{:.0} %", 100.0 * x));
            s += &format!(
                "    {:<2} 1-step {} → {} (truth {}, closed {}); 10 s free run {} → {} (truth {}, closed {})\n",
                g.channel,
                f(g.base[0]),
                f(g.augmented.and_then(|a| a[0])),
                f(g.truth[0]),
                pct(closed[0]),
                f(g.base[1]),
                f(g.augmented.and_then(|a| a[1])),
                f(g.truth[1]),
                pct(closed[1]),
            );
        }
        let kept: Vec<&str> = c
            .named
            .iter()
            .zip(&c.kept)
            .filter(|(_, k)| k.0 == Some(true))
            .map(|(n, _)| n.0.as_str())
            .collect();
        if c.stored {
            s += &format!("    kept: {}\n", kept.join("; "));
        }
        if let (Some((label, _, _)), Some(est)) = (c.named.first(), c.estimates.first()) {
            s += &format!(
                "    first named, {label}: {} — truth: {}\n",
                est.join("; "),
                c.truth_size
            );
        }
        if std::env::var_os("ESTIMATES").is_some() {
            for ((label, _, _), est) in c.named.iter().zip(&c.estimates).skip(1) {
                s += &format!("    also {label}: {}\n", est.join("; "));
            }
        }
        for (((label, _, _), est), t) in c.named.iter().zip(&c.estimates).zip(&c.truth_values) {
            if let Some(t) = t {
                s += &format!(
                    "    in the truth, {label}: {} — truth {}\n",
                    est.join("; "),
                    sig3(*t)
                );
            }
        }
        if c.concealed == Concealed::Disturbance || std::env::var_os("ESTIMATES").is_some() {
            s += &format!(
                "    unexplained: {}\n",
                if c.unexplained.is_empty() {
                    "none reported".to_string()
                } else {
                    c.unexplained.join("; ")
                }
            );
        }
        if c.concealed == Concealed::DriftingCurrent {
            for d in &c.current_drift {
                s += &format!("    current drift test, {d}\n");
            }
        }
        let false_named = c.false_labels();
        if !false_named.is_empty() {
            s += &format!(
                "    named, absent from the truth: {} (kept: {})\n",
                false_named.join("; "),
                if c.false_kept().is_empty() {
                    "none".to_string()
                } else {
                    c.false_kept().join("; ")
                }
            );
        }
        if let (Some((label, _, _)), Some((Some(false), Some(why)))) =
            (c.named.first(), c.kept.first())
        {
            s += &format!("    first named, left out: {label}: {why}\n");
        }
        if !c.unconfirmed.is_empty() {
            s += &format!("    tried, not confirmed: {}\n", c.unconfirmed.join("; "));
        }
        if std::env::var_os("SUMMARY").is_some() {
            for line in &c.summary {
                s += &format!("    summary: {line}\n");
            }
        } else {
            s += &format!("    {}\n", c.verdict);
        }
    }
    s
}
