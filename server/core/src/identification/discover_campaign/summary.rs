//! The effects across the grid (each named effect with the speeds that
//! chose it), and the campaign's story in sentences: what was named at
//! which grid speeds and how large, what the held-out gate decided, and the
//! structure no candidate explains (per DOF across the grid).

use std::collections::BTreeMap;

use super::{EffectAcrossGrid, PointDiscovery, speeds_text};
use crate::discrepancy::lines::SpectralLine;
use crate::discrepancy::locate::capital;
use crate::discrepancy::{Effect, Verdict};
use crate::numbers::sig3;
use crate::planning::dof::Dof;

/// Each effect the grid speeds' findings name, with the speeds that chose
/// it, its magnitude and held-out gain at each.
pub(super) fn effects_across(points: &[PointDiscovery]) -> Vec<EffectAcrossGrid> {
    let mut by: BTreeMap<Effect, EffectAcrossGrid> = BTreeMap::new();
    for p in points {
        for f in &p.report.findings {
            let e = by
                .entry(f.effect)
                .or_insert_with(|| EffectAcrossGrid::unnamed(f.effect, f.label.clone()));
            e.grid_speeds_mps.push(p.grid_speed_mps);
            let gain = p
                .report
                .hypotheses
                .iter()
                .find(|h| h.effect == f.effect && h.verdict == Verdict::Chosen)
                .and_then(|h| h.cv_gain)
                .filter(|g| g.is_finite())
                .unwrap_or(0.0);
            e.held_out_gains.push(gain);
            let m = f
                .coefficients
                .first()
                .map(|c| [Some(c.value), c.std])
                .or(f.shape.as_ref().map(|s| [Some(s.value), s.std]))
                .unwrap_or([None, None]);
            e.magnitudes.push(m);
        }
    }
    // By how many speeds chose it (a property of the vehicle shows at
    // every speed), then by the held-out evidence. (By evidence alone, a
    // term one speed chose late could outrank one every speed chose: each
    // gain is conditional on the terms chosen before it there.)
    let mut v: Vec<_> = by.into_values().collect();
    v.sort_by(|a, b| {
        b.grid_speeds_mps
            .len()
            .cmp(&a.grid_speeds_mps.len())
            .then(b.evidence().total_cmp(&a.evidence()))
    });
    v
}

pub(super) fn summarize(
    points: &[PointDiscovery],
    effects: &[EffectAcrossGrid],
    skipped: &[String],
) -> Vec<String> {
    let n = points.len();
    let mut out = Vec::new();
    let mut carried: Vec<String> = points
        .iter()
        .flat_map(|p| p.report.carried.iter().map(Effect::label))
        .collect();
    carried.sort();
    carried.dedup();
    if effects.is_empty() {
        out.push(if carried.is_empty() {
            format!(
                "No missing physics named at {n} grid speed(s): the baseline explains the recordings within the evidence."
            )
        } else {
            format!(
                "Nothing found beyond the terms the model carries ({}) at {n} grid speed(s): no new version is stored.",
                carried.join("; ")
            )
        });
    } else if !carried.is_empty() {
        out.push(format!(
            "Continued from the terms the model carries ({}): kept and refitted with the new ones.",
            carried.join("; ")
        ));
    }
    for e in effects {
        let k = e.grid_speeds_mps.len();
        let vals: Vec<f64> = e.magnitudes.iter().filter_map(|m| m[0]).collect();
        let (lo, hi) = vals
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
                (l.min(v), h.max(v))
            });
        let range = match (vals.len(), e.magnitudes.first()) {
            (0, _) => "no coefficient".to_owned(),
            (1, Some([_, Some(s)])) => format!("first coefficient {} ± {}", sig3(lo), sig3(*s)),
            (1, _) => format!("first coefficient {}", sig3(lo)),
            _ => format!("first coefficient {} … {}", sig3(lo), sig3(hi)),
        };
        let scope = if k == n && n > 1 {
            "at every grid speed examined — a property of the vehicle".to_string()
        } else if k == 1 && n > 1 {
            format!(
                "only at {:.2} m/s — check those runs before trusting it",
                e.grid_speeds_mps[0]
            )
        } else {
            format!(
                "at {k} of {n} grid speeds ({} m/s)",
                speeds_text(&e.grid_speeds_mps)
            )
        };
        let gate = match (e.kept, &e.held_out_verdict) {
            (Some(true), Some(v)) => format!(" Kept: {v}."),
            (Some(false), Some(v)) => format!(" Left out: {v}."),
            _ => String::new(),
        };
        let once = e
            .campaign_estimate
            .as_ref()
            .map(|c| format!(" {}", c.text))
            .unwrap_or_default();
        if k == 0 {
            // Estimated for the campaign, not named by a grid speed.
            out.push(format!("{}:{once}{gate}", e.label));
            continue;
        }
        let (label, named) = if e.unconfirmed {
            (format!("Tried, not confirmed: {}", e.label), "chosen")
        } else {
            (e.label.clone(), "named")
        };
        out.push(format!(
            "{label}: {named} {scope}; {range}; held-out fit gained {:.3} (summed over speeds and channels).{once}{gate}",
            e.evidence()
        ));
    }
    // Unexplained structure, per DOF across the grid (the per-speed
    // signatures are in each point's report).
    let mut left: BTreeMap<Dof, (Vec<f64>, f64, f64)> = BTreeMap::new();
    let mut periodic: BTreeMap<Dof, Vec<(f64, &SpectralLine)>> = BTreeMap::new();
    for p in points {
        for u in &p.report.unexplained {
            if let Some(l) = &u.line {
                periodic
                    .entry(u.dof)
                    .or_default()
                    .push((p.grid_speed_mps, l));
                continue;
            }
            let e = left
                .entry(u.dof)
                .or_insert((vec![], f64::INFINITY, f64::NEG_INFINITY));
            e.0.push(p.grid_speed_mps);
            e.1 = e.1.min(u.band.excess_db);
            e.2 = e.2.max(u.band.excess_db);
        }
    }
    for (dof, lines) in &periodic {
        let speeds: Vec<f64> = lines.iter().map(|(v, _)| *v).collect();
        let range = |f: &dyn Fn(&SpectralLine) -> f64| {
            let lo = lines
                .iter()
                .map(|(_, l)| f(l))
                .fold(f64::INFINITY, f64::min);
            let hi = lines
                .iter()
                .map(|(_, l)| f(l))
                .fold(f64::NEG_INFINITY, f64::max);
            if sig3(lo) == sig3(hi) {
                sig3(lo)
            } else {
                format!("{}–{}", sig3(lo), sig3(hi))
            }
        };
        let (shown, runs) = lines
            .iter()
            .fold((0, 0), |(a, b), (_, l)| (a + l.runs_with_line, b + l.runs));
        out.push(format!(
            "{}: a periodic force at {} Hz, about {} {} in amplitude, at {} m/s (in {shown} of {runs} runs): it comes from outside the model's physics (waves, vortex shedding, machinery), and nothing physical is named in {} at any speed.",
            capital(dof.name()),
            range(&|l| l.frequency_hz),
            range(&|l| l.amplitude),
            dof.force_unit(),
            speeds_text(&speeds),
            dof.name()
        ));
    }
    for (dof, (speeds, lo, hi)) in &left {
        out.push(format!(
            "{}: structure no candidate explains at {} m/s ({lo:.0}–{hi:.0} dB above the noise floor); see the per-speed signatures.",
            dof.name(),
            speeds_text(speeds)
        ));
    }
    // Look-alikes, once per pair: where, and the first deciding run proposed.
    let mut pairs: BTreeMap<(Effect, Effect), (Vec<f64>, String)> = BTreeMap::new();
    for p in points {
        for a in &p.report.ambiguities {
            let e = pairs
                .entry((a.chosen, a.alternative))
                .or_insert_with(|| (vec![], a.text.clone()));
            e.0.push(p.grid_speed_mps);
        }
    }
    for (speeds, text) in pairs.values() {
        out.push(format!(
            "At {} m/s: {text}{}",
            speeds_text(speeds),
            if speeds.len() > 1 {
                " (numbers and run from the first of these speeds; each speed's report has its own)"
            } else {
                ""
            }
        ));
    }
    if !skipped.is_empty() {
        out.push(format!("Not examined: {}.", skipped.join("; ")));
    }
    out
}
