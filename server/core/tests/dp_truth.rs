//! The parallel EKF on the independent DP ship of `seatrial-truth`
//! (`dp_ship`: the supply vessel of Fossen et al. 1995 in its own code),
//! logged position-only at 1 Hz (t, thr_1 … thr_6, x, y, ψ), parsed like an
//! upload. With the profile's M″ the θ″ land near the paper's; without
//! M″ the EKF starts from a least-squares fit and lands near the θ″ with the
//! prior, K″ scaled by the M″ii the fit cannot know (see
//! `identification::ekf_init`).
//!
//! `cargo test --release -p seatrial-core --test dp_truth -- --nocapture`
//! prints the per-seed table.

mod support;

use seatrial_core::identification::{EkfCampaignSettings, ModelDocument, RunInput};
use seatrial_core::planning::VesselProfile;
use seatrial_core::planning::examples::supply_vessel;
use seatrial_truth::dp_ship::{self, DpTrial};
use support::dp_truth::truth;

const SEEDS: [u64; 5] = [1, 2, 3, 11, 12];

fn identify(profile: &VesselProfile, runs: &[RunInput]) -> ModelDocument {
    support::dp_truth::identify(profile, runs, &EkfCampaignSettings::default())
}

struct Seed {
    with: [f64; 9],
    with_std: [f64; 9],
    without: [f64; 9],
    without_std: [f64; 9],
    notes: Vec<String>,
    /// Largest relative difference of A″ and of B″ (eq. 51–52) without M″
    /// from those with M″, each over the matrix's largest entry.
    ab: (f64, f64),
    findings: Vec<String>,
}

fn seeds() -> &'static [Seed] {
    static OUT: std::sync::OnceLock<Vec<Seed>> = std::sync::OnceLock::new();
    OUT.get_or_init(|| {
        let prior = supply_vessel();
        let mut bare = supply_vessel();
        bare.dp_prior.as_mut().unwrap().inertia_bis = None;
        SEEDS
            .iter()
            .map(|&s| {
                let r = support::dp_truth::runs(&prior, &DpTrial::default(), s);
                let a = identify(&prior, &r);
                let b = identify(&bare, &r);
                let arr = |v: &[f64]| -> [f64; 9] { v.try_into().unwrap() };
                let (da, db) = (a.dp_ship.unwrap(), b.dp_ship.unwrap());
                Seed {
                    with: arr(&da.theta),
                    with_std: arr(&da.theta_std),
                    without: arr(&db.theta),
                    without_std: arr(&db.theta_std),
                    notes: b.notes,
                    ab: (rel(&da.a, &db.a), rel(&da.b, &db.b)),
                    findings: b.structure_findings,
                }
            })
            .collect()
    })
}

/// max |b − a| / max |a| over the entries of two matrices.
fn rel(a: &[Vec<f64>], b: &[Vec<f64>]) -> f64 {
    let scale = a.iter().flatten().fold(0.0_f64, |m, x| m.max(x.abs()));
    a.iter()
        .flatten()
        .zip(b.iter().flatten())
        .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()))
        / scale
}

/// What the no-prior θ″ should equal: A″_h unchanged, K″ divided by the
/// truth's M″ii (M″11 for the main propellers, M″22 for the others).
fn scaled(theta: &[f64; 9]) -> [f64; 9] {
    let m = dp_ship::M;
    std::array::from_fn(|p| match p {
        5 => theta[p] / m[0][0],
        6..=8 => theta[p] / m[1][1],
        _ => theta[p],
    })
}

#[test]
fn table() {
    let truth = truth();
    for (s, r) in SEEDS.iter().zip(seeds()) {
        for n in r
            .notes
            .iter()
            .filter(|n| n.contains("least-squares") || n.contains("efine"))
            .chain(&r.findings)
        {
            eprintln!("{n}");
        }
        eprintln!(
            "seed {s}: without M″, A″ within {:.1} % and B″ within {:.1} % of those with M″ (of the largest entry)",
            100.0 * r.ab.0,
            100.0 * r.ab.1
        );
        eprintln!(
            "seed {s}:  θ″   truth    | with M″: err %  z   | without M″ (K″ per M″ii): err vs with %  z"
        );
        for p in 0..9 {
            let e_with = r.with[p] / truth[p] - 1.0;
            let expect = scaled(&r.with)[p];
            let e_without = r.without[p] / expect - 1.0;
            eprintln!(
                "  θ″{} {:>9.5} | {:>+7.2} {:>+5.1} | {:>+7.2} {:>+5.1}",
                p + 1,
                truth[p],
                100.0 * e_with,
                (r.with[p] - truth[p]) / r.with_std[p],
                100.0 * e_without,
                (r.without[p] - scaled(&truth)[p]) / r.without_std[p],
            );
        }
    }
}

/// With M″ (staged EKF and refinement): every θ″ but the weakly determined
/// coupling θ″3 (A″_h23, ~4 % std on a 2 × 600 s campaign) within 5 % of
/// the truth on every seed (measured ≤ 0.7 %; θ″3 −6.3 … +11.6 %).
#[test]
fn with_the_prior_the_truth_is_found() {
    let truth = truth();
    for (s, r) in SEEDS.iter().zip(seeds()) {
        for p in (0..9).filter(|&p| p != 2) {
            let e = r.with[p] / truth[p] - 1.0;
            assert!(e.abs() < 0.05, "seed {s} θ″{}: {:+.2} %", p + 1, 100.0 * e);
        }
    }
}

/// Without M″ (5 seeds): relative to the θ″ with M″ (K″ divided by the
/// truth's M″ii, the scale the data cannot give) surge θ″6 = K″1 within 3 %
/// (measured ≤ 1.7 %), A″_h22 (θ″2) within 10 % (≤ 5.9 %), K″5 and K″6
/// (θ″8, θ″9) within 25 % (≤ 19.6 %), A″_h11, A″_h33 and K″3 = K″4 (θ″1,
/// θ″5, θ″7) within 30 % (≤ 14.5 %, 22.7 %, 26.7 %). The couplings θ″3
/// and θ″4 follow the rough least-squares inertia shape (off by 5–300 %)
/// and are not asserted: a structure finding says so. Without M″ the θ″
/// are a rough start, not the paper's precision; the notes say how the EKF
/// was started and what is not identifiable.
#[test]
fn without_the_prior_the_theta_with_the_prior_is_found() {
    let tolerance = [0.3, 0.1, f64::NAN, f64::NAN, 0.3, 0.03, 0.3, 0.25, 0.25];
    for (s, r) in SEEDS.iter().zip(seeds()) {
        let expect = scaled(&r.with);
        for p in (0..9).filter(|p| !tolerance[*p].is_nan()) {
            let e = r.without[p] / expect[p] - 1.0;
            assert!(
                e.abs() < tolerance[p],
                "seed {s} θ″{}: {:+.2} %",
                p + 1,
                100.0 * e
            );
        }
        let notes = r.notes.join(" ");
        assert!(notes.contains("No M″ in the profile"), "{notes}");
        assert!(notes.contains("not identifiable"), "{notes}");
        assert!(
            r.findings.iter().any(|f| f.contains("θ″3 (A″_h23)")),
            "{:?}",
            r.findings
        );
    }
}
