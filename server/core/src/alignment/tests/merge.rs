//! [`align_logs`] against known truth.

use super::super::test_support::{Depth, LogSpec, Rng, table};
use super::super::*;
use crate::timeseries::LogTable;

/// The run's own estimate (every run here has one).
fn own(rep: &AlignmentReport) -> &OffsetEstimate {
    rep.offset.as_ref().expect("an own estimate")
}

/// True time of the input step.
const STEP_AT: f64 = 123.4;
/// Control stamps = true + 100; nav stamps = true + 100 − OFFSET.
const OFFSET: f64 = 3.37;

/// A navigation velocity as a function of true time.
fn surge(tau: f64) -> f64 {
    0.5 * (0.2 * tau).sin() + 0.1 * (0.031 * tau).cos()
}

struct Run {
    control: LogTable,
    nav: LogTable,
    /// Control stamp of the first sample at or after the step.
    step_stamp: f64,
}

/// Control at 10 Hz over true [0, 600] (tau_x steps 0 → 10 N at
/// `STEP_AT`, tau_z a ±5 N square wave, z), nav at `nav_hz` over true
/// [20, 580] with the clock offset (u = `surge`, psi, z), 30 dB SNR depth.
fn run(seed: u64, nav_hz: f64, nav_clock_drift: f64) -> Run {
    let mut rng = Rng::new(seed);
    let depth = Depth::lively(&mut rng, 600.0);
    let noise = depth.std(0.0, 600.0) * 10f64.powf(-1.5);
    let control_spec = LogSpec {
        rate_hz: 10.0,
        start: 0.0,
        end: 600.0,
        clock: 100.0,
        jitter: 0.01,
        noise,
    };
    let nav_spec = LogSpec {
        rate_hz: nav_hz,
        start: 20.0,
        end: 580.0,
        clock: 100.0 - OFFSET,
        jitter: 0.01,
        noise,
    };
    let tau_c = control_spec.true_times();
    let (tc, zc) = control_spec.sample(|t| depth.eval(t), &mut rng);
    let step_index = tau_c.iter().position(|&t| t >= STEP_AT - 1e-9).unwrap();
    let tau_x: Vec<f64> = (0..tc.len())
        .map(|k| if k >= step_index { 10.0 } else { 0.0 })
        .collect();
    let tau_z: Vec<f64> = tau_c
        .iter()
        .map(|t| {
            if (t / 7.0).floor() as i64 % 2 == 0 {
                5.0
            } else {
                -5.0
            }
        })
        .collect();
    let tau_n = nav_spec.true_times();
    let (mut tn, zn) = nav_spec.sample(|t| depth.eval(t), &mut rng);
    // A drifting nav clock: its stamps run `drift` fast.
    let t_ref = tn[0];
    tn.iter_mut()
        .for_each(|t| *t = t_ref + (*t - t_ref) * (1.0 + nav_clock_drift));
    let u: Vec<f64> = tau_n.iter().map(|&t| surge(t)).collect();
    let psi: Vec<f64> = tau_n.iter().map(|&t| 0.01 * t).collect();
    Run {
        step_stamp: tc[step_index],
        control: table(tc, vec![("tau_x", tau_x), ("tau_z", tau_z), ("z", zc)]),
        nav: table(tn, vec![("u", u), ("psi", psi), ("z", zn)]),
    }
}

fn merged_time(rec: &crate::timeseries::UniformRecord, k: usize) -> f64 {
    rec.t0 + k as f64 / rec.sample_rate_hz
}

#[test]
fn merged_record_covers_the_overlap_with_every_column() {
    let r = run(1, 25.0, 0.0);
    let (rec, rep) = align_logs(&r.control, &r.nav, "z", None, &OffsetOptions::default()).unwrap();
    assert_eq!(
        rec.names,
        ["tau_x", "tau_z", "z_control", "u", "psi", "z"].map(String::from)
    );
    assert!((own(&rep).offset_s - OFFSET).abs() < 0.01, "{rep:?}");
    assert_eq!(own(&rep).confidence, Confidence::High);
    // Default rate: the lower of the two (10 Hz control vs 25 Hz nav).
    assert!((rep.rate_hz - 10.0).abs() < 0.01);
    assert!((rep.control_rate_hz - 10.0).abs() < 0.01);
    assert!((rep.nav_rate_hz - 25.0).abs() < 0.01);
    // Overlap on the control clock: nav covers true [20, 580].
    assert!((rep.overlap_start_s - 120.0).abs() < 0.01, "{rep:?}");
    assert!((rep.overlap_end_s - 680.0).abs() < 0.01, "{rep:?}");
    assert_eq!(rec.t0, rep.overlap_start_s);
    let last = merged_time(&rec, rec.len() - 1);
    assert!(last <= rep.overlap_end_s && last > rep.overlap_end_s - 0.1);
    assert_eq!(rec.valid, vec![0..rec.len()]);
    assert!(rec.data.iter().all(|c| c.len() == rec.len()));
    assert!(
        rep.warnings.iter().any(|w| w
            == "the control log (10 Hz) is slower than the navigation log (25 Hz): the inputs are known only every 0.1 s"),
        "{:?}",
        rep.warnings
    );
    assert!(own(&rep).residual_relative < 0.1, "{:?}", rep.offset);
    // The two copies of the shared channel agree once aligned.
    let (z, zc) = (rec.column("z").unwrap(), rec.column("z_control").unwrap());
    let rms = (z.iter().zip(zc).map(|(a, b)| (a - b).powi(2)).sum::<f64>() / z.len() as f64).sqrt();
    assert!(rms < 0.15, "{rms}");
}

#[test]
fn navigation_channels_land_on_the_control_clock() {
    let r = run(2, 20.0, 0.0);
    let (rec, _) = align_logs(
        &r.control,
        &r.nav,
        "z",
        Some(10.0),
        &OffsetOptions::default(),
    )
    .unwrap();
    let u = rec.column("u").unwrap();
    let mut worst: f64 = 0.0;
    for (k, v) in u.iter().enumerate() {
        let tau = merged_time(&rec, k) - 100.0;
        worst = worst.max((v - surge(tau)).abs());
    }
    // Linear interpolation of a 0.2 rad/s wave at 20 Hz, jitter and the
    // offset error: far below the 0.1 m/s that one 0.1 s slip would cause.
    assert!(worst < 2e-3, "{worst}");
}

#[test]
fn an_input_step_lands_at_its_time() {
    let r = run(3, 25.0, 0.0);
    let o = OffsetOptions::default();
    // At the control rate and above: zero-order hold, only 0 and 10, the
    // step at the first merged sample at or after its stamp.
    for rate in [10.0, 50.0] {
        let (rec, rep) = align_logs(&r.control, &r.nav, "z", Some(rate), &o).unwrap();
        let tau_x = rec.column("tau_x").unwrap();
        for (k, v) in tau_x.iter().enumerate() {
            let want = if merged_time(&rec, k) >= r.step_stamp {
                10.0
            } else {
                0.0
            };
            assert_eq!(
                *v,
                want,
                "rate {rate}, sample {k} at {}",
                merged_time(&rec, k)
            );
        }
        if rate > 10.0 {
            assert!(rep.warnings.iter().any(|w| w.contains("zero-order hold")));
        }
    }
    // Below it: cell averages; the cell straddling the step holds the
    // fraction of the cell after it, the others 0 or 10.
    let (rec, rep) = align_logs(&r.control, &r.nav, "z", Some(2.0), &o).unwrap();
    let tau_x = rec.column("tau_x").unwrap();
    for (k, v) in tau_x.iter().enumerate() {
        let (a, b) = (merged_time(&rec, k) - 0.25, merged_time(&rec, k) + 0.25);
        let want = 10.0 * ((b - r.step_stamp) / 0.5).clamp(0.0, 1.0);
        assert!(
            (v - want).abs() < 1e-9,
            "sample {k} [{a}, {b}]: {v} vs {want}"
        );
    }
    assert!(
        rep.warnings
            .iter()
            .any(|w| w.contains("averaged over 0.5 s"))
    );
    // The ±5 N square wave averages to its duty cycle, never beyond ±5.
    assert!(
        rec.column("tau_z")
            .unwrap()
            .iter()
            .all(|v| v.abs() <= 5.0 + 1e-12)
    );
}

#[test]
fn a_drifting_clock_is_reported() {
    // 300 ppm: 0.17 s over the 560 s overlap, 1.7 samples at 10 Hz.
    let r = run(4, 25.0, 300e-6);
    let (_, rep) = align_logs(&r.control, &r.nav, "z", None, &OffsetOptions::default()).unwrap();
    let w = rep
        .warnings
        .iter()
        .find(|w| w.contains("drift"))
        .expect("drift warning");
    assert!(w.contains("ppm"), "{w}");
    let r = run(4, 25.0, 0.0);
    let (_, rep) = align_logs(&r.control, &r.nav, "z", None, &OffsetOptions::default()).unwrap();
    assert!(
        !rep.warnings.iter().any(|w| w.contains("drift")),
        "{:?}",
        rep.warnings
    );
}

#[test]
fn gaps_are_left_out_of_the_valid_blocks() {
    let mut r = run(5, 25.0, 0.0);
    // Drop 5 s of navigation data around true time 300 s.
    let keep: Vec<bool> = r
        .nav
        .t
        .iter()
        .map(|t| !(t - (100.0 - OFFSET) > 300.0 && t - (100.0 - OFFSET) < 305.0))
        .collect();
    fn kept(v: &[f64], keep: &[bool]) -> Vec<f64> {
        v.iter()
            .zip(keep)
            .filter(|(_, k)| **k)
            .map(|(x, _)| *x)
            .collect()
    }
    r.nav.t = kept(&r.nav.t, &keep);
    r.nav.data = r.nav.data.iter().map(|c| kept(c, &keep)).collect();
    let (rec, rep) = align_logs(&r.control, &r.nav, "z", None, &OffsetOptions::default()).unwrap();
    assert_eq!(rec.valid.len(), 2, "{:?}", rec.valid);
    let (first, second) = (&rec.valid[0], &rec.valid[1]);
    assert_eq!(first.start, 0);
    assert_eq!(second.end, rec.len());
    let gap_start = merged_time(&rec, first.end) - 100.0;
    let gap_end = merged_time(&rec, second.start) - 100.0;
    assert!(
        (gap_start - 300.0).abs() < 0.15 && (gap_end - 305.0).abs() < 0.15,
        "{gap_start} {gap_end}"
    );
    assert!(
        rep.warnings
            .iter()
            .any(|w| w.contains("navigation log has 1 gap")),
        "{:?}",
        rep.warnings
    );
}

#[test]
fn shared_names_and_missing_columns() {
    let r = run(6, 10.0, 0.0);
    let mut nav = r.nav.clone();
    nav.names[0] = "tau_x".into();
    let (rec, rep) = align_logs(&r.control, &nav, "z", None, &OffsetOptions::default()).unwrap();
    assert_eq!(rec.names[0], "tau_x_control");
    assert_eq!(rec.names[3], "tau_x");
    assert!(rep.warnings.iter().any(|w| w.contains("'tau_x_control'")));

    let e = align_logs(&r.control, &r.nav, "depth", None, &OffsetOptions::default()).unwrap_err();
    assert_eq!(e.field(), "shared");
    assert_eq!(e.message(), "the control log has no column 'depth'");
    let mut nav = r.nav.clone();
    nav.names[2] = "depth".into();
    let e = align_logs(&r.control, &nav, "z", None, &OffsetOptions::default()).unwrap_err();
    assert_eq!(e.message(), "the navigation log has no column 'z'");

    let mut nav = r.nav.clone();
    nav.data[0].pop();
    let e = align_logs(&r.control, &nav, "z", None, &OffsetOptions::default()).unwrap_err();
    assert_eq!(e.field(), "nav.u");
    let mut control = r.control.clone();
    control.data[0][5] = f64::NAN;
    let e = align_logs(&control, &r.nav, "z", None, &OffsetOptions::default()).unwrap_err();
    assert!(matches!(e, AlignError::NonFinite { index: 5, .. }), "{e:?}");
    assert_eq!(e.field(), "control.tau_x");
    let e = align_logs(
        &r.control,
        &r.nav,
        "z",
        Some(0.0),
        &OffsetOptions::default(),
    )
    .unwrap_err();
    assert_eq!(e.field(), "rate_hz");
    let bad = OffsetOptions {
        max_offset_s: Some(f64::INFINITY),
        rate_hz: None,
    };
    let e = align_logs(&r.control, &r.nav, "z", None, &bad).unwrap_err();
    assert_eq!(e.field(), "opts.max_offset_s");
}

#[test]
fn a_flat_shared_channel_is_named() {
    let r = run(7, 10.0, 0.0);
    let mut control = r.control.clone();
    control.data[2].iter_mut().for_each(|v| *v = 12.0);
    let e = align_logs(&control, &r.nav, "z", None, &OffsetOptions::default()).unwrap_err();
    assert!(matches!(e, AlignError::FlatSignal { .. }));
    assert_eq!(e.field(), "shared");
    assert_eq!(
        e.message(),
        "the shared channel z does not change in the control log; alignment needs a signal both computers saw vary, e.g. a depth change"
    );
}

#[test]
fn a_periodic_shared_channel_warns() {
    let mut rng = Rng::new(9);
    let depth = Depth::sinusoid(15.0);
    let spec = |rate_hz, clock| LogSpec {
        rate_hz,
        start: 0.0,
        end: 300.0,
        clock,
        jitter: 0.01,
        noise: 0.01,
    };
    let (tc, zc) = spec(10.0, 0.0).sample(|t| depth.eval(t), &mut rng);
    let (tn, zn) = spec(10.0, -2.0).sample(|t| depth.eval(t), &mut rng);
    let control = table(tc, vec![("z", zc)]);
    let nav = table(tn, vec![("z", zn)]);
    let (_, rep) = align_logs(&control, &nav, "z", None, &OffsetOptions::default()).unwrap();
    assert_eq!(own(&rep).confidence, Confidence::Low);
    assert!(
        rep.warnings
            .iter()
            .any(|w| w.starts_with("THE CLOCK OFFSET IS NOT RELIABLE") && w.contains("ambiguous")),
        "{:?}",
        rep.warnings
    );
}

#[test]
fn a_mismatched_channel_warns() {
    // The nav "z" is in feet: the shapes align, the values do not.
    let r = run(8, 25.0, 0.0);
    let mut nav = r.nav.clone();
    nav.data[2].iter_mut().for_each(|v| *v *= 3.28);
    let (_, rep) = align_logs(&r.control, &nav, "z", None, &OffsetOptions::default()).unwrap();
    assert!((own(&rep).offset_s - OFFSET).abs() < 0.01);
    assert!(own(&rep).residual_relative > 0.2);
    assert!(
        rep.warnings
            .iter()
            .any(|w| w.contains("still differs between the logs")),
        "{:?}",
        rep.warnings
    );
}

#[test]
fn report_serializes_in_snake_case() {
    let r = run(10, 25.0, 0.0);
    let (_, rep) = align_logs(&r.control, &r.nav, "z", None, &OffsetOptions::default()).unwrap();
    let json = serde_json::to_value(&rep).unwrap();
    for key in [
        "offset",
        "shared_channel",
        "rate_hz",
        "control_rate_hz",
        "nav_rate_hz",
        "overlap_start_s",
        "overlap_end_s",
        "warnings",
    ] {
        assert!(json.get(key).is_some(), "{key} missing in {json}");
    }
    assert_eq!(json["offset"]["confidence"], "high");
    assert_eq!(json["shared_channel"], "z");
}
