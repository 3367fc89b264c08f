//! The physical 3-DOF model of a surface vessel (λ-filter: one sub-model at
//! 0 m/s for a DP vessel, an LPV model on forward speed for the Otter USV
//! at speed) graded on the independent surface-vessel truth
//! (`seatrial_truth::usv`: Fossen's manoeuvring model with relative
//! velocity, C_A with its Munk moment, quadratic surge and strip-theory
//! cross-flow drag), the supply vessel drawn ±20 % per seed, flown with τ
//! logged at 1 Hz and its DGNSS/gyro noise, held-out validation run; the
//! Otter drawn likewise, flown at three propeller levels with yaw PRBS and
//! τ logged at 10 Hz (τ_Y = 0: sway moves only through yaw), its grid the
//! steady speeds of those levels as its crew would state them.
//!
//! `cargo test --release -p seatrial-core --test surface_vessels -- --nocapture`
//! prints the table.

mod support;

use seatrial_core::identification::LambdaCampaignSettings;
use seatrial_truth::usv::{self, Current, Effects, UsvTrial};
use support::surface::{SurfaceReport, otter_case, otter_grid, supply_case};

const SEEDS: [u64; 5] = [1, 2, 3, 4, 5];

/// The concealed physics of each case, with the seed's constant current
/// (0.05–0.5 m/s, any direction).
fn cases(seed: u64) -> Vec<(&'static str, Effects)> {
    let current = Current::random_constant(seed + 100, 0.05, 0.5);
    vec![
        ("clean", Effects::CLEAN),
        (
            "current + Munk",
            Effects {
                current,
                munk: true,
                ..Effects::CLEAN
            },
        ),
        ("all but current", Effects::all(Current::None)),
        ("all", Effects::all(current)),
    ]
}

fn reports() -> &'static [SurfaceReport] {
    static REPORTS: std::sync::OnceLock<Vec<SurfaceReport>> = std::sync::OnceLock::new();
    REPORTS.get_or_init(|| {
        let settings = LambdaCampaignSettings::default();
        let mut out = Vec::new();
        for seed in SEEDS {
            let vessel = usv::supply().draw(seed);
            for (label, effects) in cases(seed) {
                let (r, _) = supply_case(label, &vessel, effects, seed, &settings);
                println!("{}", r.line());
                out.push(r);
            }
        }
        out
    })
}

/// Free runs over the whole held-out run (600 s) within 0.05 of the true
/// model's fit in surge, sway and yaw, with the current, the Munk moment,
/// quadratic surge and cross-flow drag concealed.
#[test]
fn free_runs_come_within_five_hundredths_of_the_true_model() {
    for r in reports() {
        for (c, model, truth) in &r.free_run {
            let (m, t) = (model.expect("a free run"), truth.expect("a truth fit"));
            assert!(
                t - m <= 0.05,
                "{} seed {}: {c} free run {m:.3} against the true model's {t:.3}\n{}",
                r.label,
                r.seed,
                r.notes.join("\n")
            );
        }
    }
}

/// A current is named once for the campaign with its speed within 20 % and
/// its direction within 10°; none where none was flown.
#[test]
fn the_current_is_found_where_it_flows_and_nowhere_else() {
    for r in reports() {
        match (r.current_true, &r.current_est) {
            (Some((speed, dir)), Some(est)) => {
                let err = r.current_error().expect("both");
                assert!(
                    err.abs() <= 0.2,
                    "{} seed {}: {:.3} m/s against {speed:.3}",
                    r.label,
                    r.seed,
                    est.speed_mps
                );
                let d = (est.direction_deg - dir.to_degrees()).rem_euclid(360.0);
                let d = d.min(360.0 - d);
                assert!(
                    d <= 10.0,
                    "{} seed {}: direction off by {d:.1}°",
                    r.label,
                    r.seed
                );
                assert!(est.speed_std_mps > 0.0 && est.speed_std_mps < 0.5 * speed);
            }
            (None, None) => {}
            (t, e) => panic!(
                "{} seed {}: current {t:?}, estimated {e:?}",
                r.label, r.seed
            ),
        }
    }
}

/// Quadratic surge drag at rest: a DP vessel has no drag curve over
/// speeds, so X_|u|u is estimated in the regression like the other DOFs'
/// D_q (at 0 m/s surge's remainder beyond its tangent is |u|u itself).
/// Where the truth carries it (600 s of SI1 twice per seed), the model
/// names it on at least 6 of the 10 cases (measured: 7; seed 2 gives 3000 ± 6900
/// and is left out), each within 2.5σ of the truth (measured |z| ≤ 2.0);
/// where it does not, never.
#[test]
fn quadratic_surge_drag_is_named_in_dp_where_it_acts() {
    let (mut named, mut concealed) = (0, 0);
    for r in reports() {
        let truth = -usv::supply().draw(r.seed).x_uu;
        let acts = matches!(r.label.as_str(), "all but current" | "all");
        println!(
            "{} seed {}: X_|u|u {:?} against {}",
            r.label,
            r.seed,
            r.surge_drag,
            if acts { truth } else { 0.0 }
        );
        match (acts, r.surge_drag) {
            (true, Some((d, sd))) => {
                assert!(
                    (d - truth).abs() <= 2.5 * sd,
                    "{} seed {}: X_|u|u {d:.0} ± {sd:.0} against {truth:.0} N·s²/m²",
                    r.label,
                    r.seed
                );
                named += 1;
            }
            (false, Some((d, sd))) => panic!(
                "{} seed {}: X_|u|u {d:.0} ± {sd:.0} N·s²/m² named where the truth has none",
                r.label, r.seed
            ),
            _ => {}
        }
        concealed += usize::from(acts);
    }
    assert!(named >= 6, "named on {named} of {concealed}");
}

const OTTER_SEEDS: [u64; 6] = [1, 2, 3, 4, 5, 6];

/// The Otter's cases: the clean hull, every effect but a current (Munk
/// moment, quadratic surge, cross-flow drag), every effect in the seed's
/// constant current of 0.05–0.3 m/s (up to its slowest level), and in one
/// of 0.3–0.5 m/s (up to 1.6 times its slowest level).
fn otter_cases(seed: u64) -> Vec<(&'static str, Effects)> {
    vec![
        ("Otter clean", Effects::CLEAN),
        ("Otter all but current", Effects::all(Current::None)),
        (
            "Otter all",
            Effects::all(Current::random_constant(seed + 100, 0.05, 0.3)),
        ),
        (
            "Otter strong current",
            Effects::all(Current::random_constant(seed + 100, 0.3, 0.5)),
        ),
    ]
}

fn otter_reports() -> &'static [SurfaceReport] {
    static REPORTS: std::sync::OnceLock<Vec<SurfaceReport>> = std::sync::OnceLock::new();
    REPORTS.get_or_init(|| {
        let settings = LambdaCampaignSettings::default();
        let mut out = Vec::new();
        for seed in OTTER_SEEDS {
            let vessel = usv::otter().draw(seed);
            for (label, effects) in otter_cases(seed) {
                let grid = otter_grid(&vessel, &effects);
                let trial = UsvTrial {
                    effects,
                    ..UsvTrial::default()
                };
                let (r, _) = otter_case(label, &vessel, &trial, seed, &grid, &settings);
                println!("{} gap {:.3}", r.line(), r.worst_gap().unwrap_or(f64::NAN));
                out.push(r);
            }
        }
        out
    })
}

/// The underactuated Otter at speed without a current: free runs over the
/// whole held-out run within 0.05 of the true model's in surge, sway and
/// yaw, and the model says that sway was never forced.
#[test]
fn the_otter_without_a_current_comes_within_five_hundredths() {
    for r in otter_reports().iter().filter(|r| r.current_true.is_none()) {
        let gap = r.worst_gap().expect("every channel has a free run");
        assert!(
            gap <= 0.05,
            "{} seed {}: {}\n{}",
            r.label,
            r.seed,
            r.line(),
            r.notes.join("\n")
        );
        assert!(
            r.notes
                .iter()
                .any(|n| n.starts_with("never forced in the estimation runs: sway")),
            "{} seed {}: no note on the unforced sway",
            r.label,
            r.seed
        );
    }
}

/// The Otter in a current: the current within 5 % and 3° on every seed,
/// and the free runs, whose heading (and with it the current's push in the
/// body frame) the model integrates over 180 s, within 0.05 of the true
/// model's on every seed (measured: 0.002–0.020; seed 4's 0.29 m/s
/// current, near its slowest level, 0.020, 0.049 before the velocities'
/// noise was discounted in the regression). Three things carry it: turns
/// flown at two amplitudes (at one, the model fitted there damped smaller
/// turns too much and its heading drifted: seeds 2 and 4 0.051 and
/// 0.072), C(δ)δ, which acts through the never-forced sway mass, kept
/// only where it earns its place on the held-out runs, and the sub-models
/// fitted and stepped on the velocity through the water, so that the
/// current's rotation ν̇_c does not act through that mass either.
#[test]
fn the_otter_in_a_current_finds_it_and_follows_the_held_out_run() {
    let current: Vec<&SurfaceReport> = otter_reports()
        .iter()
        .filter(|r| r.label == "Otter all")
        .collect();
    assert_eq!(current.len(), OTTER_SEEDS.len());
    for r in &current {
        assert_current_within_five_percent_and_three_degrees(r);
        let gap = r.worst_gap().expect("every channel has a free run");
        assert!(
            gap <= 0.05,
            "seed {}: {}\n{}",
            r.seed,
            r.line(),
            r.notes.join("\n")
        );
        below_grid_note_is_true(r);
    }
}

/// The Otter in a current of 0.3–0.5 m/s, as strong as its slowest level
/// or stronger: the current is still found within 5 % and 3° on every
/// seed (measured: within 0.6 % and 1°), and the whole-run free runs come
/// within 0.05 of the true model's on every seed (measured gaps 0.009
/// 0.004 0.008 0.028 0.016 0.047). With the current as fast as the hull, a
/// small error in the model's own heading turns a push as large as its
/// speed through the water. Two things carry it: the sub-models fitted and
/// stepped on ν_r (before, the gaps were 0.023–0.396: the current's
/// rotation M ν̇_c acted through the sway mass no run forced, which the
/// grid points then estimated at 45–105 kg), and the velocities' noise
/// discounted in the regression (before, 0.015 0.003 0.010 0.062 0.018
/// 0.044: 1 cm/s of GNSS noise on an unforced sway of a few cm/s shrank
/// N_v, the Munk moment's way into yaw, and seed 4's heading drifted 7° in
/// 160 s under a 0.495 m/s current).
#[test]
fn the_otter_in_a_strong_current_finds_it() {
    let strong: Vec<&SurfaceReport> = otter_reports()
        .iter()
        .filter(|r| r.label == "Otter strong current")
        .collect();
    assert_eq!(strong.len(), OTTER_SEEDS.len());
    for r in &strong {
        assert_current_within_five_percent_and_three_degrees(r);
        let gap = r.worst_gap().expect("every channel has a free run");
        assert!(
            gap <= 0.05,
            "seed {}: {}\n{}",
            r.seed,
            r.line(),
            r.notes.join("\n")
        );
    }
}

/// The Otter's current named once for the campaign, its speed within 5 %
/// and its direction within 3° of the truth.
fn assert_current_within_five_percent_and_three_degrees(r: &SurfaceReport) {
    let (speed, dir) = r.current_true.expect("flown");
    let est = r.current_est.as_ref().unwrap_or_else(|| {
        panic!(
            "{} seed {}: no current\n{}",
            r.label,
            r.seed,
            r.notes.join("\n")
        )
    });
    let err = r.current_error().expect("both");
    assert!(
        err.abs() <= 0.05,
        "{} seed {}: {:.3} m/s against {speed:.3}",
        r.label,
        r.seed,
        est.speed_mps
    );
    let d = (est.direction_deg - dir.to_degrees()).rem_euclid(360.0);
    assert!(
        d.min(360.0 - d) <= 3.0,
        "{} seed {}: direction off by {d:.1}°",
        r.label,
        r.seed
    );
}

/// The note on how much of the held-out run lies below the grid speaks of
/// the speed through the water, which the model is scheduled on: its share
/// within 5 points of the truth's, and no note where the truth's is under
/// 4 % (the note starts at 5 %).
fn below_grid_note_is_true(r: &SurfaceReport) {
    let said = r.notes.iter().find_map(|n| {
        let rest = n.strip_prefix("validation run VAL: ")?;
        let (pct, tail) = rest.split_once(" % of it was flown ")?;
        tail.starts_with("below").then(|| pct.parse::<f64>().ok())?
    });
    let truth = 100.0 * r.below_grid_share;
    match said {
        Some(pct) => assert!(
            (pct - truth).abs() <= 5.0,
            "seed {}: the note says {pct} % below the grid, the truth {truth:.1} %",
            r.seed
        ),
        None => assert!(
            truth < 4.0,
            "seed {}: {truth:.1} % below the grid, no note",
            r.seed
        ),
    }
}
