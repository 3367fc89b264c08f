//! The excitation signal of a run, from the switching intervals of its most
//! excited DOF: regular → square, whole chips → PRBS, else other.

use super::{DofActivity, blocks, mean_std, switch_times};
use crate::identification::description::RunSignal;
use crate::timeseries::UniformRecord;

/// Largest coefficient of variation of the switching intervals of a square
/// wave (its half-periods are equal).
pub const SQUARE_MAX_CV: f64 = 0.15;

/// Largest mean deviation of the switching intervals from whole chips
/// (fraction of a chip) for a PRBS.
pub const CHIP_MAX_DEVIATION: f64 = 0.15;

/// Fewest switching intervals to tell a signal.
pub const MIN_INTERVALS: usize = 4;

/// Two-level signal: ≥ 80 % of the samples within ±25 % of the half-range
/// (5th–95th percentile) from one of the two levels.
fn two_level(rec: &UniformRecord, col: &[f64]) -> Option<(f64, f64)> {
    let mut v: Vec<f64> = blocks(rec, col).flatten().copied().collect();
    if v.len() < 10 {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let q = |p: f64| v[((v.len() - 1) as f64 * p).round() as usize];
    let (lo, hi) = (q(0.05), q(0.95));
    let (mid, a) = (0.5 * (lo + hi), 0.5 * (hi - lo));
    if a <= 0.0 {
        return None;
    }
    let near = v
        .iter()
        .filter(|x| ((*x - mid).abs() - a).abs() <= 0.25 * a)
        .count();
    (near as f64 >= 0.8 * v.len() as f64).then_some((mid, a))
}

/// Signal and why, from the most excited DOF.
pub(super) fn signal(
    rec: &UniformRecord,
    inputs: &[String],
    acts: &[DofActivity],
) -> (RunSignal, String) {
    let Some((j, best)) = acts
        .iter()
        .enumerate()
        .filter(|(_, a)| a.excited)
        .max_by(|a, b| a.1.score.total_cmp(&b.1.score))
    else {
        return (
            RunSignal::Other,
            "nothing switches: no excitation signal (holds or steps)".into(),
        );
    };
    let d = best.dof;
    let (name, col, lo, hi, why_col) = match rec
        .column(&inputs[j])
        .and_then(|c| two_level(rec, c).map(|l| (c, l)))
    {
        Some((c, (mid, a))) => (
            inputs[j].as_str(),
            c,
            mid - 0.5 * a,
            mid + 0.5 * a,
            "the two-level input",
        ),
        None => {
            let c = rec.column(d.velocity_symbol()).unwrap_or_default();
            let (m, s) = mean_std(rec, c);
            (
                d.velocity_symbol(),
                c,
                m - 0.5 * s,
                m + 0.5 * s,
                "the velocity (the input is not two-level: closed-loop control)",
            )
        }
    };
    let h = 1.0 / rec.sample_rate_hz;
    let intervals: Vec<f64> = switch_times(rec, col, lo, hi)
        .iter()
        .flat_map(|s| {
            s.windows(2)
                .map(|w| (w[1] - w[0]) as f64 * h)
                .collect::<Vec<_>>()
        })
        .collect();
    let what = format!("switching of {} {name}", why_col);
    if intervals.len() < MIN_INTERVALS {
        return (
            RunSignal::Other,
            format!(
                "{what}: {} complete interval(s), too few to tell square from PRBS",
                intervals.len()
            ),
        );
    }
    let n = intervals.len() as f64;
    let mean = intervals.iter().sum::<f64>() / n;
    let cv = (intervals.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n).sqrt() / mean;
    if cv < SQUARE_MAX_CV {
        return (
            RunSignal::Square,
            format!(
                "{what}: {} half-periods of {mean:.2} s, all alike (variation {:.0} %) — a square wave",
                intervals.len(),
                100.0 * cv
            ),
        );
    }
    // Chip: the typical shortest interval, refined over whole multiples.
    let min = intervals.iter().copied().fold(f64::INFINITY, f64::min);
    let short: Vec<f64> = intervals
        .iter()
        .copied()
        .filter(|&x| x <= 1.5 * min)
        .collect();
    let mut chip = short.iter().sum::<f64>() / short.len() as f64;
    let multiples =
        |c: f64| -> Vec<f64> { intervals.iter().map(|x| (x / c).round().max(1.0)).collect() };
    let mut k = multiples(chip);
    for _ in 0..3 {
        chip = intervals.iter().sum::<f64>() / k.iter().sum::<f64>();
        k = multiples(chip);
    }
    let dev = intervals
        .iter()
        .zip(&k)
        .map(|(x, m)| (x / chip - m).abs())
        .sum::<f64>()
        / n;
    let kmax = k.iter().copied().fold(0.0, f64::max);
    if dev < CHIP_MAX_DEVIATION && kmax >= 2.0 {
        return (
            RunSignal::Prbs,
            format!(
                "{what}: {} intervals, each a whole number (1–{kmax:.0}) of {chip:.2} s chips (mean deviation {:.0} % of a chip) — a PRBS (or random binary)",
                intervals.len(),
                100.0 * dev
            ),
        );
    }
    (
        RunSignal::Other,
        format!(
            "{what}: intervals neither alike (variation {:.0} %) nor whole chips (deviation {:.0} % of {chip:.2} s)",
            100.0 * cv,
            100.0 * dev
        ),
    )
}
