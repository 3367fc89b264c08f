//! Missing-physics discovery on horizontal (3-DOF) surface-vessel models,
//! graded on the independent surface-vessel truth (`seatrial_truth::usv`:
//! Fossen's manoeuvring model with relative velocity to a current, C_A
//! with its Munk moment, quadratic surge and cross-flow drag), the supply
//! vessel drawn ±20 % per seed, DP manoeuvres logged at 1 Hz without z, φ,
//! θ. The λ identification finds the current itself; discovery continues
//! from its model with the current carried as a term. The Otter USV at
//! speed, whose λ baseline is poor, shows discovery storing nothing it
//! cannot justify.
//!
//! `cargo test --release -p seatrial-core --test surface_discovery -- --nocapture`
//! prints the table.

mod support;

use seatrial_core::estimation::NoProgress;
use seatrial_core::identification::discover_campaign::{
    CampaignDiscovery, DiscoverCampaignSettings, discover_campaign,
};
use seatrial_core::identification::{Identified, LambdaCampaignSettings, RunInput};
use seatrial_core::planning::VesselProfile;
use seatrial_core::planning::dof::Dof;
use seatrial_truth::usv::{self, Current, Effects, SupplyTrial, UsvTrial, fly_usv_campaign};
use support::surface::{
    SurfaceReport, inputs, otter_case, otter_grid, otter_profile, supply_case, supply_profile,
};

const SEEDS: [u64; 4] = [1, 2, 3, 4];

struct Case {
    report: SurfaceReport,
    base: Identified,
    found: CampaignDiscovery,
    profile: VesselProfile,
    runs: Vec<RunInput>,
}

fn cases(seed: u64) -> Vec<(&'static str, Effects)> {
    let current = Current::random_constant(seed + 100, 0.05, 0.5);
    vec![
        ("clean", Effects::CLEAN),
        (
            "quadratic surge",
            Effects {
                quadratic_surge: true,
                ..Effects::CLEAN
            },
        ),
        (
            "cross-flow",
            Effects {
                cross_flow: true,
                ..Effects::CLEAN
            },
        ),
        (
            "Munk",
            Effects {
                munk: true,
                ..Effects::CLEAN
            },
        ),
        (
            "current",
            Effects {
                current,
                ..Effects::CLEAN
            },
        ),
    ]
}

/// The Otter's campaign under `effects`, its turns flown at one
/// amplitude (the identification proof flies two). With two, seed 1's
/// concealed current is named at 0.30 m/s but taken for a pull fixed in
/// NED at 0.55 m/s, and no campaign estimate is pooled: the look-alikes
/// are not yet told apart there.
fn otter_trial(effects: Effects) -> UsvTrial {
    UsvTrial {
        effects,
        yaw_second_half: 1.0,
        ..UsvTrial::default()
    }
}

/// Discovery on the λ model `base` of `runs`, printed as a table row.
/// Discovery as the service runs it: with the model's own identification
/// settings (`identified_with`).
fn examine(
    report: SurfaceReport,
    base: Identified,
    profile: &VesselProfile,
    runs: &[RunInput],
    identified_with: &LambdaCampaignSettings,
) -> Case {
    let forces: Vec<String> = Dof::HORIZONTAL
        .iter()
        .map(|d| d.force_column().to_string())
        .collect();
    let found = discover_campaign(
        &base.document,
        profile,
        &forces,
        runs,
        &base.estimation_run_ids,
        &base.validation_run_ids,
        &DiscoverCampaignSettings {
            identification: Some(identified_with.clone()),
            ..DiscoverCampaignSettings::default()
        },
        &mut NoProgress,
    )
    .expect("discovery runs on the 3-DOF model");
    let named: Vec<String> = found
        .report
        .effects
        .iter()
        .map(|e| format!("{} (kept {:?})", e.label, e.kept))
        .collect();
    println!(
        "{}\n    discovery: {}; stored: {}",
        report.line(),
        if named.is_empty() {
            "nothing named".to_string()
        } else {
            named.join(", ")
        },
        found.augmented.is_some()
    );
    Case {
        report,
        base,
        found,
        profile: profile.clone(),
        runs: runs.to_vec(),
    }
}

fn discovered() -> &'static [Case] {
    static CASES: std::sync::OnceLock<Vec<Case>> = std::sync::OnceLock::new();
    CASES.get_or_init(|| {
        let with_current = LambdaCampaignSettings::default();
        // The same current case identified with constant loads only: the
        // baseline then misses the current, and discovery must not make it
        // worse.
        let loads_only = LambdaCampaignSettings {
            ned_current: Some(false),
            ..LambdaCampaignSettings::default()
        };
        let mut out = Vec::new();
        for seed in SEEDS {
            let vessel = usv::supply().draw(seed);
            let mut all = cases(seed);
            all.push(("current, loads only", all[4].1));
            for (label, effects) in all {
                let settings = if label == "current, loads only" {
                    &loads_only
                } else {
                    &with_current
                };
                let (report, base) = supply_case(label, &vessel, effects, seed, settings);
                let trial = SupplyTrial {
                    effects,
                    ..SupplyTrial::default()
                };
                let profile = supply_profile(&vessel, &trial);
                let runs = inputs(&profile, &usv::fly_supply_campaign(&vessel, &trial, seed));
                out.push(examine(report, base, &profile, &runs, settings));
            }
        }
        out
    })
}

/// The Otter USV at 0.3, 0.55 and 0.8 m/s (τ_Y = 0, logged at 10 Hz): its
/// λ baseline is poor (underactuated sway), which is where discovery must
/// not store what it cannot justify.
fn otter_discovered() -> &'static [Case] {
    static CASES: std::sync::OnceLock<Vec<Case>> = std::sync::OnceLock::new();
    CASES.get_or_init(|| {
        let settings = LambdaCampaignSettings::default();
        let mut out = Vec::new();
        for seed in [1, 2] {
            let vessel = usv::otter().draw(seed);
            let current = Current::random_constant(seed + 100, 0.05, 0.3);
            for (label, effects) in [
                ("Otter clean", Effects::CLEAN),
                (
                    "Otter cross-flow + quadratic surge",
                    Effects {
                        cross_flow: true,
                        quadratic_surge: true,
                        ..Effects::CLEAN
                    },
                ),
                (
                    "Otter current",
                    Effects {
                        current,
                        ..Effects::CLEAN
                    },
                ),
            ] {
                let trial = otter_trial(effects);
                let (report, base) =
                    otter_case(label, &vessel, &trial, seed, &[0.3, 0.55, 0.8], &settings);
                let profile = otter_profile(&vessel);
                let runs = inputs(&profile, &fly_usv_campaign(&vessel, &trial, seed));
                out.push(examine(report, base, &profile, &runs, &settings));
            }
        }
        out
    })
}

/// The Otter with every hydrodynamic effect in a current of 0.05–0.3 m/s,
/// identified with constant loads only (`ned_current: false`) on the
/// crew's grid (the levels' steady speeds): the current is concealed from
/// the baseline, which also holds runs at the grid point of their speed
/// over ground.
fn otter_concealed_current() -> &'static [Case] {
    static CASES: std::sync::OnceLock<Vec<Case>> = std::sync::OnceLock::new();
    CASES.get_or_init(|| {
        let settings = LambdaCampaignSettings {
            ned_current: Some(false),
            ..LambdaCampaignSettings::default()
        };
        SEEDS
            .iter()
            .map(|&seed| {
                let vessel = usv::otter().draw(seed);
                let effects = Effects::all(Current::random_constant(seed + 100, 0.05, 0.3));
                let grid = otter_grid(&vessel, &effects);
                let trial = otter_trial(effects);
                let (report, base) = otter_case(
                    "Otter all, current concealed",
                    &vessel,
                    &trial,
                    seed,
                    &grid,
                    &settings,
                );
                let profile = otter_profile(&vessel);
                let runs = inputs(&profile, &fly_usv_campaign(&vessel, &trial, seed));
                examine(report, base, &profile, &runs, &settings)
            })
            .collect()
    })
}

fn all_cases() -> impl Iterator<Item = &'static Case> {
    discovered()
        .iter()
        .chain(otter_discovered())
        .chain(otter_concealed_current())
}

/// Where no hydrodynamic effect is concealed, discovery names nothing: the
/// supply vessel in DP and the Otter at speed.
#[test]
fn nothing_is_named_on_the_clean_vessel() {
    for c in all_cases().filter(|c| c.report.label.ends_with("clean")) {
        assert!(
            c.found.report.effects.is_empty() && c.found.augmented.is_none(),
            "{} seed {}: {:?}",
            c.report.label,
            c.report.seed,
            c.found.report.summary
        );
    }
}

/// No stored augmented model is worse than the model it examined on any
/// held-out channel, and every stored one is simulable (finite fits). The
/// baselines that miss the current give discovery terms to try (a bias
/// moment in yaw for the current's moment): one that lifts the 1-step,
/// k-step and 10 s fits but loses sway over the whole 600 s free run is
/// not stored, and the verdict says so.
#[test]
fn no_stored_model_is_worse_than_its_baseline() {
    assert!(
        discovered().iter().any(|c| c
            .found
            .report
            .summary
            .iter()
            .any(|l| l.contains("was not stored") && l.contains("whole-run free-run"))),
        "no verdict weighed the whole held-out run"
    );
    for c in all_cases() {
        let Some(aug) = &c.found.augmented else {
            continue;
        };
        for (b, a) in c.base.validation.iter().zip(&aug.validation) {
            for (cb, ca) in b.report.channels.iter().zip(&a.report.channels) {
                let (fb, fa) = (cb.fit_simulation, ca.fit_simulation);
                let fa = fa.expect("the augmented model simulates");
                assert!(
                    fa >= fb.unwrap_or(f64::NEG_INFINITY) - 0.005,
                    "{} seed {}: free run {fb:?} → {fa}",
                    c.report.label,
                    c.report.seed
                );
            }
        }
    }
}

/// The current the identification found is carried into discovery (its
/// library then works in the velocity through the water), not named again.
#[test]
fn the_identified_current_is_carried_not_named_again() {
    for c in discovered().iter().filter(|c| c.report.label == "current") {
        assert!(c.report.current_est.is_some(), "seed {}", c.report.seed);
        let first = &c.found.report.summary[0];
        assert!(
            first.contains("the terms the model carries (ocean current"),
            "seed {}: {first}",
            c.report.seed
        );
        assert!(
            c.found
                .report
                .effects
                .iter()
                .all(|e| e.effect != seatrial_core::discrepancy::Effect::Current),
            "seed {}: {:?}",
            c.report.seed,
            c.found.report.summary
        );
    }
}

/// The case's seed and the effect its discovery named first.
fn first_named(
    c: &Case,
) -> (
    u64,
    &seatrial_core::identification::discover_campaign::EffectAcrossGrid,
) {
    let seed = c.report.seed;
    let first = c
        .found
        .report
        .effects
        .first()
        .unwrap_or_else(|| panic!("seed {seed}: nothing named"));
    (seed, first)
}

/// A current the baseline does not carry is found once for the campaign.
/// Discovery's per-speed hypotheses name a pull fixed in NED (at one speed
/// a current's force turns with the heading as a pull does, and the
/// baseline's damping absorbed part of it); the campaign is then identified
/// again with the NED current estimated, and the held-out runs decide. The
/// first-named effect is the current on every seed, within 10 % of the
/// true speed and 10° of its direction (measured: within 1 % and 2°; seed
/// 4's 0.29 m/s current, near the slowest level, lost to the pull until
/// the identification refitted its sub-models without the C(δ)δ it had
/// left out). The current model is stored on every seed and carries the
/// named value.
#[test]
fn a_concealed_current_is_found_once_for_the_campaign() {
    use seatrial_core::discrepancy::Effect;
    let (mut stored, mut as_current) = (0, 0);
    for c in otter_concealed_current() {
        let (seed, first) = first_named(c);
        assert!(
            matches!(first.effect, Effect::Current | Effect::TetherPull),
            "seed {seed}: {:?}",
            c.found.report.summary
        );
        // Pooled where two or more speeds named it; else the one speed's.
        let values: Vec<f64> = match &first.campaign_estimate {
            Some(once) => once.coefficients.iter().map(|c| c.value).collect(),
            None => {
                assert_eq!(first.grid_speeds_mps.len(), 1, "seed {seed}: not pooled");
                c.found
                    .report
                    .points
                    .iter()
                    .flat_map(|p| &p.report.findings)
                    .find(|f| f.effect == first.effect)
                    .map(|f| f.coefficients.iter().map(|c| c.value).collect())
                    .expect("the finding")
            }
        };
        let (n, e) = (values[0], values[1]);
        let (speed, dir) = c.report.current_true.expect("flown in a current");
        let ddir = (e.atan2(n) - dir + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
            - std::f64::consts::PI;
        println!(
            "seed {seed}: current {:.3} m/s → {:.0}°; named first: {}, for the campaign {:.3} → {:.0}° ({:+.1}°); stored {}",
            speed,
            dir.to_degrees().rem_euclid(360.0),
            first.label,
            n.hypot(e),
            e.atan2(n).to_degrees().rem_euclid(360.0),
            ddir.to_degrees(),
            c.found.augmented.is_some()
        );
        assert!(
            ddir.abs() <= 10f64.to_radians(),
            "seed {seed}: direction off by {ddir} rad"
        );
        // The re-identification with the current was run, and the summary
        // says what it showed.
        assert!(
            c.found
                .report
                .summary
                .iter()
                .any(|l| l.contains("Identified again with the NED current estimated")),
            "seed {seed}: {:?}",
            c.found.report.summary
        );
        if first.effect == Effect::Current {
            as_current += 1;
            let err = (n.hypot(e) - speed) / speed;
            assert!(err.abs() <= 0.1, "seed {seed}: speed off by {err}");
            // The pull it was mistaken for is left out as its look-alike.
            for other in c.found.report.effects.iter().skip(1) {
                if other.effect.fixed_in_ned() {
                    assert_eq!(other.kept, Some(false), "seed {seed}: {}", other.label);
                }
            }
        }
        let Some(aug) = c.found.augmented.as_ref() else {
            continue;
        };
        stored += 1;
        let lpv = aug.document.lpv.as_ref().expect("LPV");
        if first.effect == Effect::Current {
            // The model identified again (or discovery's model on it): its
            // current is the one named.
            assert_eq!(first.kept, Some(true));
            match lpv.current.as_ref() {
                Some(cur) => assert_eq!(cur.ned_mps, [n, e], "seed {seed}"),
                None => {
                    for p in &lpv.points {
                        let held = p
                            .augmentation
                            .as_ref()
                            .and_then(|a| a.terms.iter().find(|t| t.effect == Effect::Current))
                            .map(|t| t.coefficients.clone());
                        assert_eq!(held, Some(vec![n, e]), "seed {seed} at {}", p.speed_mps);
                    }
                }
            }
            continue;
        }
        // Every grid point holds the pooled pull.
        if first.campaign_estimate.is_some() {
            assert_holds_everywhere(aug, first.effect, [n, e], seed);
        }
    }
    assert_eq!(
        as_current,
        SEEDS.len(),
        "the current named first on {as_current} of {}",
        SEEDS.len()
    );
    assert_eq!(stored, SEEDS.len(), "{stored} of {} stored", SEEDS.len());
}

/// Every grid point of the stored LPV model holds `effect` at `value`.
fn assert_holds_everywhere(
    aug: &Identified,
    effect: seatrial_core::discrepancy::Effect,
    value: [f64; 2],
    seed: u64,
) {
    for p in &aug.document.lpv.as_ref().expect("LPV").points {
        let held = p
            .augmentation
            .as_ref()
            .and_then(|a| a.terms.iter().find(|t| t.effect == effect))
            .map(|t| t.coefficients.clone());
        assert_eq!(
            held,
            Some(value.to_vec()),
            "seed {seed} at {} m/s",
            p.speed_mps
        );
    }
}

/// A force fixed in NED acts at every forward speed. Where discovery does
/// not examine a grid speed (here: not asked for; elsewhere: no held-out
/// run there), the stored model holds the campaign's one estimate there
/// too, that speed's M and D̄ refitted on its estimation runs with it; the
/// report says which speeds were not examined and that the force is held
/// at them. The Otter with its current concealed, discovery without the
/// re-identification: the pull fixed in NED stands for the campaign.
#[test]
fn a_shared_force_is_held_at_the_grid_speeds_not_examined() {
    let c = &otter_concealed_current()[0];
    let lpv = c.base.document.lpv.as_ref().expect("LPV");
    let grid: Vec<f64> = lpv.points.iter().map(|p| p.speed_mps).collect();
    let asked = grid[..grid.len() - 1].to_vec();
    let forces: Vec<String> = Dof::HORIZONTAL
        .iter()
        .map(|d| d.force_column().to_string())
        .collect();
    let found = discover_campaign(
        &c.base.document,
        &c.profile,
        &forces,
        &c.runs,
        &c.base.estimation_run_ids,
        &c.base.validation_run_ids,
        &DiscoverCampaignSettings {
            grid_speeds_mps: Some(asked.clone()),
            reidentify_current: false,
            ..DiscoverCampaignSettings::default()
        },
        &mut NoProgress,
    )
    .expect("discovery runs");
    let rep = &found.report;
    println!("{:#?}", rep.summary);
    assert_eq!(rep.points.len(), asked.len(), "{:?}", rep.skipped);
    assert_eq!(rep.skipped.len(), 1, "{:?}", rep.skipped);
    assert!(rep.skipped[0].contains("not among settings.grid_speeds_mps"));
    let first = rep.effects.first().expect("a force named");
    assert!(first.effect.fixed_in_ned(), "{:?}", rep.summary);
    let once = first.campaign_estimate.as_ref().expect("pooled");
    let value = [once.coefficients[0].value, once.coefficients[1].value];
    assert!(
        rep.summary
            .iter()
            .any(|l| l.contains("is also held at the grid speeds not examined")),
        "{:?}",
        rep.summary
    );
    let aug = found.augmented.as_ref().expect("stored");
    assert_holds_everywhere(aug, first.effect, value, c.report.seed);
    // The speed not examined is refitted, not the baseline's sub-model.
    let last = |doc: &seatrial_core::identification::ModelDocument| {
        doc.lpv
            .as_ref()
            .expect("LPV")
            .points
            .last()
            .expect("a point")
            .d_bar
            .clone()
    };
    assert_ne!(last(&aug.document), last(&c.base.document));
}

/// The supply vessel in DP, its current (0.05–0.5 m/s) concealed from the
/// baseline (identified with constant loads only, one grid point at
/// 0 m/s): discovery's per-speed terms stand in for the current (a pull
/// fixed in NED, or Coriolis and cross-flow terms), and identifying the
/// campaign again with the NED current estimated explains the held-out
/// runs better. The current is named first on every seed, its speed within
/// 10 % and its direction within 5° (measured: −4 … +1 %, ≤ 2°), the
/// stored model carries it, and every other finding is left out.
#[test]
fn a_concealed_current_on_a_dp_vessel_is_named_by_identifying_again() {
    use seatrial_core::discrepancy::Effect;
    for c in discovered()
        .iter()
        .filter(|c| c.report.label == "current, loads only")
    {
        let (seed, first) = first_named(c);
        assert_eq!(
            first.effect,
            Effect::Current,
            "seed {seed}: {:?}",
            c.found.report.summary
        );
        let once = first.campaign_estimate.as_ref().expect("one estimate");
        let (n, e) = (once.coefficients[0].value, once.coefficients[1].value);
        let (speed, dir) = c.report.current_true.expect("flown in a current");
        let err = (n.hypot(e) - speed) / speed;
        let ddir = (e.atan2(n) - dir + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
            - std::f64::consts::PI;
        println!(
            "DP seed {seed}: current {speed:.3} m/s, named {:.3} m/s ({:+.1} %, {:+.1}°)",
            n.hypot(e),
            100.0 * err,
            ddir.to_degrees()
        );
        assert!(err.abs() <= 0.1, "seed {seed}: speed off by {err}");
        assert!(ddir.abs() <= 5f64.to_radians(), "seed {seed}: {ddir} rad");
        assert_eq!(first.kept, Some(true));
        for other in c.found.report.effects.iter().skip(1) {
            assert_eq!(other.kept, Some(false), "seed {seed}: {}", other.label);
        }
        let aug = c.found.augmented.as_ref().expect("stored");
        let cur = aug.document.lpv.as_ref().and_then(|l| l.current.as_ref());
        assert_eq!(cur.map(|c| c.ned_mps), Some([n, e]));
    }
}
