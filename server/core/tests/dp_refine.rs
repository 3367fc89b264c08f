//! Prediction-error refinement after the staged parallel EKF, graded on the
//! independent DP ship of `seatrial-truth` (Fossen's supply vessel,
//! position-only at 1 Hz, C(ν)ν, bias random walk, thruster model; M″ and
//! T″ from the profile, θ″ unknown).
//!
//! `cargo test --release -p seatrial-core --test dp_refine -- --nocapture`
//! prints the θ″ errors and z-scores per seed.

mod support;

use seatrial_core::identification::outcome::Identified;
use seatrial_core::identification::{EkfCampaignSettings, ModelDocument};
use seatrial_core::planning::examples::supply_vessel;
use seatrial_truth::dp_ship::DpTrial;
use support::dp_truth::{identify, identify_validated, runs, truth};

/// A campaign that carries the precision: 4 runs per manoeuvre of 3 h
/// (10 800 samples at 1 Hz) and a 3 h validation run. The sway–yaw
/// coupling θ″3 (A″_h23) is the least determined θ″: about 4 % std on the
/// paper's 2 × 600 s, 0.5 % here.
fn precision_trial() -> DpTrial {
    DpTrial {
        samples: 10_800,
        repetitions: 4,
        ..DpTrial::default()
    }
}

/// θ″ and std of one seed's identification.
struct Graded {
    seed: u64,
    theta: [f64; 9],
    std: [f64; 9],
    doc: ModelDocument,
}

impl Graded {
    fn err(&self, p: usize) -> f64 {
        self.theta[p] / truth()[p] - 1.0
    }
    fn z(&self, p: usize) -> f64 {
        (self.theta[p] - truth()[p]) / self.std[p]
    }
    fn rel_std(&self, p: usize) -> f64 {
        self.std[p] / truth()[p].abs()
    }
}

fn grade(trial: &DpTrial, seeds: &[u64], settings: &EkfCampaignSettings) -> Vec<Graded> {
    let profile = supply_vessel();
    seeds
        .iter()
        .map(|&seed| {
            let doc = identify(&profile, &runs(&profile, trial, seed), settings);
            let d = doc.dp_ship.as_ref().unwrap();
            Graded {
                seed,
                theta: d.theta.as_slice().try_into().unwrap(),
                std: d.theta_std.as_slice().try_into().unwrap(),
                doc,
            }
        })
        .collect()
}

fn print_table(title: &str, graded: &[Graded]) {
    eprintln!("{title}");
    eprintln!("seed  θ″: err % (z) … ; largest std %");
    for g in graded {
        let cells: Vec<String> = (0..9)
            .map(|p| format!("{:+.2} ({:+.1})", 100.0 * g.err(p), g.z(p)))
            .collect();
        let worst = (0..9).map(|p| g.rel_std(p)).fold(0.0, f64::max);
        eprintln!(
            "{:>4}  {}  ; {:.2}",
            g.seed,
            cells.join("  "),
            100.0 * worst
        );
    }
}

/// Fraction of (parameter, seed) cases with |z| ≤ 3, and the per-parameter
/// mean z over the seeds.
fn calibration(graded: &[Graded]) -> (f64, [f64; 9]) {
    let n = graded.len() as f64;
    let within = graded
        .iter()
        .flat_map(|g| (0..9).map(move |p| g.z(p).abs() <= 3.0))
        .filter(|&ok| ok)
        .count() as f64;
    let mean = std::array::from_fn(|p| graded.iter().map(|g| g.z(p)).sum::<f64>() / n);
    (within / (9.0 * n), mean)
}

/// On the precision campaign (5 seeds): the predicted std of every θ″ is
/// ≤ 0.7 %, every θ″ within 2 % of the truth, |z| ≤ 3 on ≥ 95 % of the
/// (parameter, seed) cases and no parameter's mean z beyond ±2 (a bias of
/// 4.5 standard errors of the mean over 5 seeds).
#[test]
fn precision_campaign_gives_every_theta_within_two_percent_with_calibrated_std() {
    let graded = grade(
        &precision_trial(),
        &[1, 2, 3, 4, 5],
        &EkfCampaignSettings::default(),
    );
    print_table(
        "precision campaign (4 × 10 800 s per manoeuvre), refined:",
        &graded,
    );
    for g in &graded {
        assert!(
            g.doc
                .notes
                .iter()
                .any(|n| n.starts_with("Refined after the staging")),
            "seed {}: {:?}",
            g.seed,
            g.doc.structure_findings
        );
        for p in 0..9 {
            assert!(
                g.rel_std(p) <= 0.007,
                "seed {} θ″{}: std {:.2} %",
                g.seed,
                p + 1,
                100.0 * g.rel_std(p)
            );
            assert!(
                g.err(p).abs() < 0.02,
                "seed {} θ″{}: {:+.2} %",
                g.seed,
                p + 1,
                100.0 * g.err(p)
            );
        }
    }
    let (within, mean) = calibration(&graded);
    eprintln!("|z| ≤ 3 on {:.1} %; mean z {mean:+.2?}", 100.0 * within);
    assert!(within >= 0.95, "{within}");
    assert!(mean.iter().all(|m| m.abs() < 2.0), "{mean:?}");
}

/// The paper's short campaign (2 runs of 600 s per manoeuvre, 10 seeds):
/// θ″3 is known only to ~4 % here, but every θ″ lies within 3 reported std
/// of the truth on every seed, and the z over all cases scatter like a unit
/// normal (rms 0.7–1.3).
#[test]
fn short_campaign_every_theta_is_consistent_with_its_std() {
    let seeds: Vec<u64> = (1..=10).collect();
    let graded = grade(&DpTrial::default(), &seeds, &EkfCampaignSettings::default());
    print_table(
        "short campaign (2 × 600 s per manoeuvre), refined:",
        &graded,
    );
    let mut sum = 0.0;
    for g in &graded {
        for p in 0..9 {
            assert!(
                g.z(p).abs() <= 3.0,
                "seed {} θ″{}: {:+.2} % at std {:.2} %",
                g.seed,
                p + 1,
                100.0 * g.err(p),
                100.0 * g.rel_std(p)
            );
            sum += g.z(p).powi(2);
        }
    }
    let rms = (sum / (9.0 * graded.len() as f64)).sqrt();
    eprintln!("rms z {rms:.2}");
    assert!((0.7..=1.3).contains(&rms), "rms z {rms}");
}

/// Mean k-step and restarted free-run fits over the held-out runs'
/// channels (the whole-run free run has no bias estimate and drifts).
fn held_out_fits(id: &Identified) -> (f64, f64) {
    let mut k = Vec::new();
    let mut sim = Vec::new();
    for v in &id.validation {
        for c in &v.report.channels {
            k.push(c.fit_k_step.unwrap_or(f64::NEG_INFINITY));
            sim.push(c.fit_restarted.unwrap_or(f64::NEG_INFINITY));
        }
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    (mean(&k), mean(&sim))
}

/// The refinement never makes a result non-finite or worse on the held-out
/// run: on short campaigns with the noise stated right, too small (0.3 m
/// for 1 m) and too large (3 m), every θ″ and std stays finite and the
/// held-out k-step and restarted free-run fits stay within 0.0005 of the
/// staged EKF's (or better), and every θ″ stays within 3 reported std of
/// the truth (the std's inflation by the innovations covers a noise stated
/// too small); where the refinement is not taken, a finding says why.
#[test]
fn refinement_never_makes_the_held_out_fit_worse_or_non_finite() {
    let profile = supply_vessel();
    for noise in [1.0, 0.3, 3.0] {
        for seed in [1, 2, 3] {
            let r = runs(&profile, &DpTrial::default(), seed);
            let settings = |refine| EkfCampaignSettings {
                refine,
                position_noise_std_m: noise,
                ..Default::default()
            };
            let staged = identify_validated(&profile, &r, &settings(false));
            let refined = identify_validated(&profile, &r, &settings(true));
            let d = refined.document.dp_ship.as_ref().unwrap();
            assert!(d.theta.iter().chain(&d.theta_std).all(|v| v.is_finite()));
            let (k0, s0) = held_out_fits(&staged);
            let (k1, s1) = held_out_fits(&refined);
            let taken = refined
                .document
                .notes
                .iter()
                .any(|n| n.starts_with("Refined after the staging"));
            let t = truth();
            let zmax = (0..9)
                .map(|p| ((d.theta[p] - t[p]) / d.theta_std[p]).abs())
                .fold(0.0, f64::max);
            eprintln!(
                "noise {noise} m, seed {seed}: max |z| {zmax:.2}; refined {taken}; k-step fit {k0:.5} → {k1:.5}, restarted {s0:.5} → {s1:.5}"
            );
            assert!(k1.is_finite() && s1.is_finite());
            assert!(zmax <= 3.0, "max |z| {zmax}");
            assert!(k1 >= k0 - 5e-4, "k-step {k0} → {k1}");
            assert!(s1 >= s0 - 5e-4, "restarted {s0} → {s1}");
            if !taken {
                assert!(
                    refined
                        .document
                        .structure_findings
                        .iter()
                        .any(|f| f.contains("EKF's θ″ and std are kept")),
                    "{:?}",
                    refined.document.structure_findings
                );
            }
        }
    }
}

fn env_or(name: &str, default: usize) -> usize {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// The longer seed sweep of the precision campaign, with the per-parameter
/// error and z statistics (`SEEDS` seeds, default 20; `REPS`, `SAMPLES`
/// change the campaign, `REFINE=0` shows the staged EKF alone):
///
/// `SEEDS=20 cargo test --release -p seatrial-core --test dp_refine -- --ignored --nocapture`
#[test]
#[ignore]
fn seed_sweep() {
    let trial = DpTrial {
        samples: env_or("SAMPLES", precision_trial().samples),
        repetitions: env_or("REPS", precision_trial().repetitions),
        ..DpTrial::default()
    };
    let seeds: Vec<u64> = (1..=env_or("SEEDS", 20) as u64).collect();
    let settings = EkfCampaignSettings {
        refine: env_or("REFINE", 1) == 1,
        ..Default::default()
    };
    let graded = grade(&trial, &seeds, &settings);
    print_table(
        &format!(
            "{} × {} s per manoeuvre, refine {}:",
            trial.repetitions, trial.samples, settings.refine
        ),
        &graded,
    );
    for g in graded
        .iter()
        .filter(|g| !g.doc.structure_findings.is_empty())
    {
        eprintln!("seed {}: {:?}", g.seed, g.doc.structure_findings);
    }
    let n = graded.len() as f64;
    for p in 0..9 {
        let z: Vec<f64> = graded.iter().map(|g| g.z(p)).collect();
        let rms = (z.iter().map(|x| x * x).sum::<f64>() / n).sqrt();
        let worst = graded.iter().map(|g| g.err(p).abs()).fold(0.0, f64::max);
        let std = graded.iter().map(|g| g.rel_std(p)).sum::<f64>() / n;
        eprintln!(
            "θ″{}: max |err| {:.2} %, mean std {:.2} %, mean z {:+.2} (± {:.2}), rms z {:.2}, max |z| {:.2}",
            p + 1,
            100.0 * worst,
            100.0 * std,
            z.iter().sum::<f64>() / n,
            1.0 / n.sqrt(),
            rms,
            z.iter().fold(0.0_f64, |m, x| m.max(x.abs()))
        );
    }
    let (within, _) = calibration(&graded);
    eprintln!(
        "|z| ≤ 3 on {:.1} % of {} cases",
        100.0 * within,
        9 * graded.len()
    );
}
