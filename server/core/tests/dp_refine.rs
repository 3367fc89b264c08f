//! Prediction-error refinement after the staged parallel EKF, graded on the
//! independent DP ship of `seatrial-truth` (Fossen's supply vessel,
//! position-only at 1 Hz, C(ν)ν, bias random walk, thruster model).

mod support;

use seatrial_core::identification::EkfCampaignSettings;
use seatrial_core::planning::examples::supply_vessel;
use seatrial_truth::dp_ship::DpTrial;
use support::dp_truth::{identify, runs, truth};

fn env_usize(name: &str, default: usize) -> usize {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

#[test]
#[ignore]
fn explore() {
    let trial = DpTrial {
        samples: env_usize("SAMPLES", 600),
        repetitions: env_usize("REPS", 2),
        ..DpTrial::default()
    };
    let seeds = env_usize("SEEDS", 3) as u64;
    let profile = supply_vessel();
    let truth = truth();
    for seed in 1..=seeds {
        let t0 = std::time::Instant::now();
        let r = runs(&profile, &trial, seed);
        let t1 = t0.elapsed();
        let doc = identify(&profile, &r, &EkfCampaignSettings::default());
        let d = doc.dp_ship.unwrap();
        eprintln!("seed {seed}: fly+parse {:.1?}, identify {:.1?}", t1, t0.elapsed() - t1);
        for p in 0..9 {
            eprintln!(
                "  θ″{} err {:+6.2} %  std {:5.2} %  z {:+5.2}",
                p + 1,
                100.0 * (d.theta[p] / truth[p] - 1.0),
                100.0 * d.theta_std[p] / truth[p].abs(),
                (d.theta[p] - truth[p]) / d.theta_std[p]
            );
        }
        for n in doc.notes.iter().skip(3).chain(&doc.structure_findings) {
            eprintln!("  {n}");
        }
    }
}

#[test]
#[ignore]
fn zsweep() {
    let trial = DpTrial {
        samples: env_usize("SAMPLES", 600),
        repetitions: env_usize("REPS", 2),
        ..DpTrial::default()
    };
    let seeds = env_usize("SEEDS", 40) as u64;
    let refine = env_usize("REFINE", 1) == 1;
    let profile = supply_vessel();
    let truth = truth();
    let mut z = vec![Vec::new(); 9];
    let mut e = vec![Vec::new(); 9];
    let mut s = vec![Vec::new(); 9];
    for seed in 1..=seeds {
        let r = runs(&profile, &trial, seed);
        let settings = EkfCampaignSettings {
            refine,
            ..Default::default()
        };
        let doc = identify(&profile, &r, &settings);
        let d = doc.dp_ship.unwrap();
        for p in 0..9 {
            z[p].push((d.theta[p] - truth[p]) / d.theta_std[p]);
            e[p].push(100.0 * (d.theta[p] / truth[p] - 1.0));
            s[p].push(100.0 * d.theta_std[p] / truth[p].abs());
        }
        if doc.structure_findings.iter().any(|f| f.contains("kept")) {
            eprintln!("seed {seed}: {:?}", doc.structure_findings);
        }
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let mut within = 0;
    for p in 0..9 {
        let rms = (z[p].iter().map(|x| x * x).sum::<f64>() / z[p].len() as f64).sqrt();
        let maxe = e[p].iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        within += z[p].iter().filter(|x| x.abs() <= 3.0).count();
        eprintln!(
            "θ″{}: mean err {:+6.2} %, max |err| {:5.2} %, mean std {:5.2} %, mean z {:+5.2}, rms z {:4.2}, max |z| {:4.2}",
            p + 1,
            mean(&e[p]),
            maxe,
            mean(&s[p]),
            mean(&z[p]),
            rms,
            z[p].iter().fold(0.0_f64, |m, x| m.max(x.abs()))
        );
    }
    eprintln!("|z| ≤ 3: {within} of {}", 9 * seeds);
}
