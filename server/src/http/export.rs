//! Exports for the pilots: schedule CSV and the printable run sheet.

use std::fmt::Write;

use seatrial_core::planning::Schedule;
use seatrial_core::planning::waveform::Waveform;

use crate::storage::campaigns::Campaign;
use crate::storage::plans::StoredPlan;
use crate::storage::vessels::Vessel;

/// Sample times k/fs, rounded to the microsecond so the CSV reads cleanly.
pub fn times(n: usize, fs: f64) -> Vec<f64> {
    (0..n)
        .map(|k| (k as f64 / fs * 1e6).round() / 1e6)
        .collect()
}

/// CSV: header `t,<columns>`, one row per sample; values in shortest
/// round-trip form, so parsing returns the stored numbers exactly.
pub fn schedule_csv(s: &Schedule) -> String {
    let n = s.len();
    let mut out = String::with_capacity(n * (s.columns.len() + 1) * 12);
    out.push('t');
    for c in &s.columns {
        out.push(',');
        out.push_str(c);
    }
    out.push('\n');
    for (k, t) in times(n, s.sample_rate_hz).into_iter().enumerate() {
        let _ = write!(out, "{t}");
        for col in &s.values {
            let _ = write!(out, ",{}", col[k]);
        }
        out.push('\n');
    }
    out
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

fn hms(s: f64) -> String {
    let s = s.round() as u64;
    format!("{}:{:02}:{:02}", s / 3600, (s / 60) % 60, s % 60)
}

/// Short description of a waveform for the sheet.
pub fn describe(w: &Waveform) -> String {
    match w {
        Waveform::Constant => "hold".into(),
        Waveform::Step { sign } => format!("step {}", if *sign > 0.0 { "+" } else { "−" }),
        Waveform::Prbs {
            order,
            clock_period_s,
            ..
        } => format!("PRBS n={order}, Tc={clock_period_s:.2} s"),
        Waveform::Square { period_s } => format!("square, P={period_s:.1} s"),
        Waveform::Multisine {
            f_lo_hz, f_hi_hz, ..
        } => format!("multisine {f_lo_hz:.3}–{f_hi_hz:.3} Hz"),
        Waveform::RandomBinary { clock_period_s, .. } => {
            format!("random binary, Tc={clock_period_s:.2} s")
        }
        Waveform::ConstantThenRandom {
            segment_s,
            clock_period_s,
            ..
        } => format!("hold/random per {segment_s:.0} s, Tc={clock_period_s:.2} s"),
        Waveform::Staircase { levels, segment_s } => {
            format!(
                "staircase of {} speeds, {segment_s:.0} s each",
                levels.len()
            )
        }
    }
}

/// Printable HTML run sheet of a plan.
pub fn run_sheet(vessel: &Vessel, campaign: &Campaign, plan: &StoredPlan) -> String {
    run_sheet_titled(vessel, campaign, plan, "Run sheet")
}

/// [`run_sheet`] under another title (e.g. the next dive's selection).
pub fn run_sheet_titled(
    vessel: &Vessel,
    campaign: &Campaign,
    plan: &StoredPlan,
    title: &str,
) -> String {
    let t = &plan.totals;
    let mut h = String::new();
    let _ = write!(
        h,
        r#"<!doctype html><html lang="en"><head><meta charset="utf-8"><title>{title} – {name}</title>
<style>
body {{ font: 11pt system-ui, sans-serif; margin: 1.5cm; }}
table {{ border-collapse: collapse; width: 100%; }}
th, td {{ border: 1px solid #888; padding: 3px 5px; vertical-align: top; font-size: 9.5pt; }}
th {{ background: #eee; }} tr {{ page-break-inside: avoid; }}
.warn {{ color: #a40; }} .box {{ width: 1.2em; height: 1.2em; border: 1px solid #000; display: inline-block; }}
@media print {{ body {{ margin: 0.8cm; }} }}
</style></head><body>
<h1>{title}: {name}</h1>
<p><b>Vessel:</b> {vessel} · <b>Plan version</b> {ver} ({created}) · <b>Grid:</b> {grid} {unit} · <b>Seed:</b> {seed}</p>
<p><b>{n}</b> experiments · run time {run} · set-up {setup} · <b>total trial time {total}</b></p>
<table><thead><tr><th>#</th><th>Code</th><th>Speed</th><th>Instruction</th><th>References</th><th>Duration</th><th>PE / band</th><th>Flown</th><th>Log file / notes</th></tr></thead><tbody>
"#,
        name = esc(&campaign.spec.name),
        title = esc(title),
        vessel = esc(&vessel.profile.name),
        ver = plan.version,
        created = esc(&plan.created_at),
        grid = campaign
            .spec
            .grid
            .speeds
            .iter()
            .map(|s| s.to_string())
            .collect::<Vec<_>>()
            .join(", "),
        unit = match campaign.spec.grid.unit {
            seatrial_core::planning::SpeedUnit::Knots => "kn",
            seatrial_core::planning::SpeedUnit::MetersPerSecond => "m/s",
        },
        seed = campaign.spec.seed,
        n = t.experiments,
        run = hms(t.run_time_s),
        setup = hms(t.setup_time_s),
        total = hms(t.total_time_s),
    );
    for se in &plan.experiments {
        let e = &se.experiment;
        let refs: Vec<String> = e
            .channels
            .iter()
            .filter(|c| c.excited)
            .map(|c| {
                format!(
                    "<b>{}</b>: {} ±{:.3} {} about {:.3}",
                    esc(&c.column),
                    esc(&describe(&c.waveform)),
                    c.amplitude,
                    esc(&c.unit),
                    c.offset
                )
            })
            .collect();
        let pe: Vec<String> = e
            .channels
            .iter()
            .filter_map(|c| c.analysis.as_ref().map(|a| (c, a)))
            .map(|(c, a)| {
                let band = a
                    .band_hz
                    .map_or("—".to_string(), |[lo, hi]| format!("{lo:.3}–{hi:.3} Hz"));
                let ge = if a.pe_order >= a.pe_cap { "≥" } else { "" };
                format!(
                    "{}: PE {ge}{} (needs {}), {band}",
                    esc(&c.column),
                    a.pe_order,
                    a.pe_required
                )
            })
            .collect();
        let speed = e.grid_speed_mps.map_or("grid".to_string(), |u| {
            format!("{:.2} kn<br>{u:.3} m/s", u / seatrial_core::planning::KNOT)
        });
        let warnings: String = e
            .warnings
            .iter()
            .map(|w| format!("<div class=warn>⚠ {}</div>", esc(w)))
            .collect();
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td>{}</td><td>{speed}</td><td>{}{warnings}</td><td>{}</td><td>{}</td><td>{}</td><td><span class=box></span></td><td></td></tr>",
            e.seq,
            esc(&e.code),
            esc(&e.instruction),
            refs.join("<br>"),
            hms(e.duration_s),
            pe.join("<br>"),
        );
    }
    h.push_str("</tbody></table>\n<p>Rules: square waves hold each level 5·T (period 10·T); PRBS clock T_c = T lengthened so a slew takes at most half a chip; PRBS runs last whole periods of the m-sequence; usable band = PSD within 10 dB of its peak; PE order as the logger sees the reference.</p>\n</body></html>\n");
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_round_trips_exactly() {
        let s = Schedule {
            sample_rate_hz: 20.0,
            columns: vec!["u_ref".into(), "v_ref".into()],
            values: vec![vec![0.1 + 0.2, 1.0 / 3.0, -2.5], vec![0.0, 1e-300, 7.0]],
        };
        let csv = schedule_csv(&s);
        let mut lines = csv.lines();
        assert_eq!(lines.next(), Some("t,u_ref,v_ref"));
        let rows: Vec<Vec<f64>> = lines
            .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
            .collect();
        assert_eq!(rows.len(), 3);
        assert_eq!(rows[2][0], 0.1);
        for (k, row) in rows.iter().enumerate() {
            assert_eq!(row[1], s.values[0][k]);
            assert_eq!(row[2], s.values[1][k]);
        }
    }
}
