//! The campaign generator: structure, logger, clocks, determinism, speed.

use std::path::PathBuf;
use std::time::Instant;

use seatrial_truth::campaign::{CONTROL_COLUMNS, NAV_COLUMNS, SINGLE_COLUMNS};
use seatrial_truth::{Campaign, CampaignSpec, Dof, Role, SignalKind, Vessel, fly_campaign};

fn campaign(seed: u64) -> Campaign {
    fly_campaign(&Vessel::draw(seed), &CampaignSpec::default(), seed)
}

fn temp_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("seatrial-truth-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

#[test]
fn campaign_has_the_planned_runs() {
    let c = campaign(21);
    let spec = &c.spec;
    assert_eq!(c.runs.len(), spec.grid_speeds.len() * 7 + 1);
    for (gi, &u0) in spec.grid_speeds.iter().enumerate() {
        let statics = c.runs_at(u0, Role::Static);
        assert_eq!(statics.len(), 1);
        let s = statics[0];
        assert!((60.0..=90.0).contains(&s.meta.duration_s));
        assert!(s.meta.excited.is_empty());
        // the surge loop holds u₀ (mean of the true u within 2 %)
        let mean_u = s.truth.nu.column(0).mean();
        assert!(
            (mean_u - u0).abs() < 0.02 * u0,
            "static at {u0}: mean u {mean_u}"
        );
        let dynamic = c.runs_at(u0, Role::Dynamic);
        assert_eq!(dynamic.len(), 6);
        for (r, dof) in dynamic.iter().zip(Dof::ALL) {
            assert_eq!(r.meta.excited, vec![dof]);
            assert!((120.0..=240.0).contains(&r.meta.duration_s));
            let expect = if (gi + dof.index()) % 2 == 0 {
                SignalKind::Square
            } else {
                SignalKind::Prbs
            };
            assert_eq!(r.meta.signal, expect);
            // the excited DOF moves more than in the static run
            let k = dof.index();
            let std = |m: &nalgebra::DMatrix<f64>| m.column(k).variance().sqrt();
            let moved = if k == 3 || k == 4 {
                std(&r.truth.eta) > 5.0 * std(&s.truth.eta)
            } else {
                std(&r.truth.nu) > 5.0 * std(&s.truth.nu)
            };
            assert!(moved, "{}: the excited DOF hardly moves", r.meta.name);
        }
    }
    let val = c.validation_runs();
    assert_eq!(val.len(), 1);
    let v = val[0];
    assert!(v.meta.duration_s >= 600.0 && v.meta.grid_speed.is_none());
    assert_eq!(v.meta.signal, SignalKind::Mixed);
    let mut speeds = v.meta.speeds.clone();
    speeds.sort_by(f64::total_cmp);
    assert_eq!(speeds, vec![0.3, 0.75, 1.25, 1.75, 2.25]);
    for r in &c.runs {
        assert!(
            r.meta.saturated_fraction < 0.02,
            "{} saturates {:.1} % of the time",
            r.meta.name,
            100.0 * r.meta.saturated_fraction
        );
    }
}

#[test]
fn logged_tau_is_every_second_20hz_command() {
    let c = campaign(22);
    for r in &c.runs {
        let cmd = &r.truth.tau_cmd_20hz;
        assert_eq!(cmd.nrows(), 2 * r.log.t.len());
        let mut odd_differs = 0;
        for k in 0..r.log.t.len() {
            assert_eq!(r.log.tau.row(k), cmd.row(2 * k), "{} row {k}", r.meta.name);
            assert_eq!(r.log.t[k], r.truth.t_20hz[2 * k]);
            assert!((r.truth.t_20hz[2 * k + 1] - r.log.t[k] - 0.05).abs() < 1e-9);
            odd_differs += usize::from(cmd.row(2 * k + 1) != cmd.row(2 * k));
        }
        // the unlogged odd commands are real, different commands
        assert!(odd_differs > 9 * r.log.t.len() / 10, "{}", r.meta.name);
        // 10 Hz stamps
        for w in r.log.t.windows(2) {
            assert!((w[1] - w[0] - 0.1).abs() < 1e-9);
        }
    }
}

#[test]
fn measured_log_carries_the_specified_noise() {
    let c = campaign(23);
    let r = &c.runs[3];
    let n = r.log.t.len() as f64;
    for j in 0..6 {
        let d = r.log.nu.column(j) - r.truth.nu.column(j);
        let rms = (d.norm_squared() / n).sqrt();
        let sigma = c.spec.noise.nu_std(j);
        assert!(
            (rms - sigma).abs() < 0.15 * sigma,
            "ν_{j}: rms {rms} vs σ {sigma}"
        );
    }
}

/// Linear interpolation of (ts, ys) at t; None outside.
fn interp(ts: &[f64], ys: &[f64], t: f64) -> Option<f64> {
    let i = ts.partition_point(|&x| x <= t);
    if i == 0 || i >= ts.len() {
        return None;
    }
    let a = (t - ts[i - 1]) / (ts[i] - ts[i - 1]);
    Some(ys[i - 1] + a * (ys[i] - ys[i - 1]))
}

fn depth_mismatch(c: &Campaign, run: usize, offset: f64) -> f64 {
    let r = &c.runs[run];
    let nav_t: Vec<f64> = r.nav.t.iter().map(|t| t + offset).collect();
    let nav_z: Vec<f64> = r.nav.eta.column(2).iter().copied().collect();
    let (mut s, mut n) = (0.0, 0);
    for k in 0..r.log.t.len() {
        if let Some(z) = interp(&nav_t, &nav_z, r.log.t[k]) {
            s += (z - r.log.eta[(k, 2)]).powi(2);
            n += 1;
        }
    }
    assert!(
        n > r.log.t.len() / 2,
        "the logs must overlap at offset {offset}"
    );
    (s / n as f64).sqrt()
}

#[test]
fn two_file_offset_is_the_one_recorded() {
    let c = campaign(24);
    let (lo, hi) = c.spec.clock_offset_range_s;
    assert!((lo..hi).contains(&c.clock_offset_s));
    let sigma = (c.spec.noise.depth.powi(2) + c.spec.nav_noise.depth.powi(2)).sqrt();
    let heave = c
        .runs
        .iter()
        .position(|r| r.meta.excited == vec![Dof::Heave])
        .expect("a heave run");
    for (i, r) in c.runs.iter().enumerate() {
        assert_eq!(r.meta.clock_offset_s, c.clock_offset_s);
        for w in r.nav.t.windows(2) {
            assert!((w[1] - w[0] - 1.0 / c.spec.nav_rate_hz).abs() < 1e-9);
        }
        // at the recorded offset the shared depth agrees to the noise
        let at = depth_mismatch(&c, i, c.clock_offset_s);
        assert!(
            at < 1.5 * sigma,
            "{}: depth mismatch {at} vs σ {sigma}",
            r.meta.name
        );
    }
    // on a heave run a wrong offset shows
    let at = depth_mismatch(&c, heave, c.clock_offset_s);
    for (wrong, factor) in [(-2.0, 4.0), (-0.3, 1.5), (0.3, 1.5), (2.0, 4.0)] {
        let off = depth_mismatch(&c, heave, c.clock_offset_s + wrong);
        assert!(off > factor * at, "offset error {wrong} s: {off} vs {at}");
    }
}

#[test]
fn csv_files_follow_the_log_contract() {
    let c = campaign(25);
    let dir = temp_dir("contract");
    c.write_dir(&dir).unwrap();
    for r in &c.runs {
        let name = &r.meta.name;
        for (file, cols, rows) in [
            (
                format!("{name}.csv"),
                SINGLE_COLUMNS.to_vec(),
                r.log.t.len(),
            ),
            (
                format!("{name}_control.csv"),
                CONTROL_COLUMNS.to_vec(),
                r.log.t.len(),
            ),
            (
                format!("{name}_nav.csv"),
                NAV_COLUMNS.to_vec(),
                r.nav.t.len(),
            ),
        ] {
            let text = std::fs::read_to_string(dir.join(&file)).unwrap();
            let mut lines = text.lines();
            assert_eq!(lines.next().unwrap(), cols.join(","), "{file}");
            let body: Vec<&str> = lines.collect();
            assert_eq!(body.len(), rows, "{file}");
            for l in &body {
                let cells: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
                assert_eq!(cells.len(), cols.len());
                assert!(cells.iter().all(|x| x.is_finite()));
            }
        }
        let first: Vec<f64> = std::fs::read_to_string(dir.join(format!("{name}.csv")))
            .unwrap()
            .lines()
            .nth(1)
            .unwrap()
            .split(',')
            .map(|x| x.parse().unwrap())
            .collect();
        assert!((first[0] - r.log.t[0]).abs() < 1e-3);
        assert!((first[1] - r.log.tau[(0, 0)]).abs() < 1e-4);
        assert!((first[18] - r.log.eta[(0, 5)]).abs() < 1e-6);
        assert!(first[18].abs() <= std::f64::consts::PI, "ψ is wrapped");
    }
    let json = std::fs::read_to_string(dir.join("truth.json")).unwrap();
    assert!(json.contains("\"clock_offset_convention\": \"nav t + clock_offset_s = control t\""));
    assert!(json.contains(&format!("\"clock_offset_s\": {}", c.clock_offset_s)));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn seeded_campaign_is_byte_identical_on_repeat() {
    let (a, b) = (temp_dir("rep-a"), temp_dir("rep-b"));
    campaign(26).write_dir(&a).unwrap();
    campaign(26).write_dir(&b).unwrap();
    let mut names: Vec<_> = std::fs::read_dir(&a)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    names.sort();
    assert_eq!(names.len(), 29 * 3 + 1);
    for n in &names {
        let (x, y) = (
            std::fs::read(a.join(n)).unwrap(),
            std::fs::read(b.join(n)).unwrap(),
        );
        assert!(x == y, "{n:?} differs between two flights of seed 26");
    }
    let other = campaign(27);
    assert_ne!(
        std::fs::read_to_string(a.join("truth.json")).unwrap(),
        other.truth_json()
    );
    std::fs::remove_dir_all(&a).unwrap();
    std::fs::remove_dir_all(&b).unwrap();
}

#[test]
fn five_campaigns_fly_in_seconds() {
    let start = Instant::now();
    let rows: usize = (30..35)
        .map(|s| {
            campaign(s)
                .runs
                .iter()
                .map(|r| r.log.t.len())
                .sum::<usize>()
        })
        .sum();
    println!(
        "5 campaigns ({rows} log rows, {:.0} s of flight) in {:.2} s",
        rows as f64 / 10.0,
        start.elapsed().as_secs_f64()
    );
}

#[test]
fn surveyor_like_vessel_flies_the_default_campaign() {
    let v = Vessel::surveyor_like();
    let c = fly_campaign(&v, &CampaignSpec::default(), 1);
    for r in &c.runs {
        assert!(r.meta.saturated_fraction < 0.02, "{}", r.meta.name);
        assert!(r.truth.nu.iter().all(|x| x.is_finite()));
    }
}
