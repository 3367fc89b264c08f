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

/// Discovery on the λ model `base` of `runs`, printed as a table row.
fn examine(
    report: SurfaceReport,
    base: Identified,
    profile: &VesselProfile,
    runs: &[RunInput],
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
        &DiscoverCampaignSettings::default(),
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
            ned_current: false,
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
                out.push(examine(report, base, &profile, &runs));
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
                let (report, base) =
                    otter_case(label, &vessel, effects, seed, &[0.3, 0.55, 0.8], &settings);
                let trial = UsvTrial {
                    effects,
                    ..UsvTrial::default()
                };
                let profile = otter_profile(&vessel);
                let runs = inputs(&profile, &fly_usv_campaign(&vessel, &trial, seed));
                out.push(examine(report, base, &profile, &runs));
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
            ned_current: false,
            ..LambdaCampaignSettings::default()
        };
        SEEDS
            .iter()
            .map(|&seed| {
                let vessel = usv::otter().draw(seed);
                let effects = Effects::all(Current::random_constant(seed + 100, 0.05, 0.3));
                let grid = otter_grid(&vessel, &effects);
                let (report, base) = otter_case(
                    "Otter all, current concealed",
                    &vessel,
                    effects,
                    seed,
                    &grid,
                    &settings,
                );
                let trial = UsvTrial {
                    effects,
                    ..UsvTrial::default()
                };
                let profile = otter_profile(&vessel);
                let runs = inputs(&profile, &fly_usv_campaign(&vessel, &trial, seed));
                examine(report, base, &profile, &runs)
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

/// A current the baseline does not carry is found once for the campaign:
/// the first-named effect is a force fixed in NED pointing the current's
/// way (within 10°), pooled over the grid speeds; named as the current,
/// its speed is within 20 % and the way to a model that has it throughout
/// is named (the identification's own current, which places runs by their
/// speed through the water); named as a pull fixed in NED, the text names
/// the current as its look-alike. Every grid point of a stored model holds
/// the one value, and the refitted models are stored where the held-out
/// runs are better with them. (Named as a pull on 3 of 4 seeds: the Otter's
/// sway damping is cross-flow drag, not linear, so at one speed the
/// current's force is as near a constant NED force as a linear-damping
/// current; telling them apart across speeds is not built yet.)
#[test]
fn a_concealed_current_is_found_once_for_the_campaign() {
    use seatrial_core::discrepancy::Effect;
    let mut stored = 0;
    for c in otter_concealed_current() {
        let seed = c.report.seed;
        let first = c
            .found
            .report
            .effects
            .first()
            .unwrap_or_else(|| panic!("seed {seed}: nothing named"));
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
        if first.effect == Effect::Current {
            let err = (n.hypot(e) - speed) / speed;
            assert!(err.abs() <= 0.2, "seed {seed}: speed off by {err}");
        }
        // The re-identification the current calls for (with the runs it
        // moves when the current was named; as the pull's look-alike else).
        assert!(
            c.found
                .report
                .summary
                .iter()
                .any(|l| l.contains("identified without a current")
                    || l.contains("a current looks the same at one forward speed")),
            "seed {seed}: {:?}",
            c.found.report.summary
        );
        if let Some(aug) = c
            .found
            .augmented
            .as_ref()
            .filter(|_| first.campaign_estimate.is_some())
        {
            stored += 1;
            let lpv = aug.document.lpv.as_ref().expect("LPV");
            // Every grid point examined (one without held-out runs keeps
            // the baseline's sub-model).
            let examined: Vec<f64> = c
                .found
                .report
                .points
                .iter()
                .map(|p| p.grid_speed_mps)
                .collect();
            for p in lpv
                .points
                .iter()
                .filter(|p| examined.contains(&p.speed_mps))
            {
                let held = p
                    .augmentation
                    .as_ref()
                    .and_then(|a| a.terms.iter().find(|t| t.effect == first.effect))
                    .map(|t| &t.coefficients);
                assert_eq!(
                    held,
                    Some(&vec![n, e]),
                    "seed {seed} at {} m/s",
                    p.speed_mps
                );
            }
        }
    }
    assert!(stored >= 2, "{stored} of {} stored", SEEDS.len());
}
