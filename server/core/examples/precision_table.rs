//! Issue 15's proof for the ROV as a table: the predicted std of every
//! λ-filter parameter of the Surveyor plan (`design::predict_precision`,
//! the vessel as prior) against the empirical spread of the estimates over
//! noise seeds of the independent truth (`seatrial-truth`) flying the same
//! plan (one autopilot, noise varied), against the std the identification
//! reports on those runs, and (`--own`) against the noise-only spread of
//! the project's own simulator flying the plan with the prior. `--retune`
//! re-tunes the truth's autopilot per seed (nominal inertia and ĝ(η)
//! drawn anew), so the spread also holds the change of the closed loop.
//! `--no-recursive` leaves the recursive family (REC runs) out of the plan;
//! `--designed` flies the campaign as `design::design_campaign` designs it
//! within the rule-based plan's hours; `--repeat N` flies the rule-based
//! plan with every run repeated N times (the design's rule-based front).
//! The profile declares the truth's autopilot (the team's gains and ĝ
//! feed-forward), so the prediction flies the plan through it;
//! `--generic-autopilot` leaves it out (the project's loops designed from
//! the profile's limits fly the prediction), `--tune-seed N` tunes the
//! truth's autopilot from another seed, `--inferred-autopilot` predicts
//! with the autopilot inferred from a first dive's logs
//! (`identification::autopilot_fit`) instead, `--linear` identifies with linear
//! damping only (both sides).
//! `--tsv PATH` writes each parameter's predicted and empirical std with
//! the plan's ship hours, for `ship_hours.py` (the ship-hour ratio of a
//! designed campaign against the rule-based plan repeated, on the truth).
//!
//! `cargo run --release -p seatrial-core --example precision_table -- [seeds=20] [--threads 2] [--own] [--retune] [--no-recursive] [--designed] [--generic-autopilot] [--linear] [--tune-seed N] [--inferred-autopilot] [--repeat N] [--tsv PATH] [--grid-kn 0.5,2,3.5]`

#[path = "../tests/support/precision_truth.rs"]
mod precision_truth;

use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut seeds = 20usize;
    let mut threads = 2usize;
    let mut own = false;
    let mut retune = false;
    let mut variant = precision_truth::PlanVariant::default();
    let mut tsv: Option<String> = None;
    let mut inferred = false;
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--threads" => threads = it.next().and_then(|v| v.parse().ok()).expect("--threads N"),
            "--own" => own = true,
            "--retune" => retune = true,
            "--no-recursive" => variant.no_recursive = true,
            "--designed" => variant.designed = true,
            "--generic-autopilot" => variant.generic_autopilot = true,
            "--linear" => variant.linear_damping = true,
            "--inferred-autopilot" => inferred = true,
            "--tune-seed" => {
                variant.tune_seed = Some(
                    it.next()
                        .and_then(|v| v.parse().ok())
                        .expect("--tune-seed N"),
                )
            }
            "--tsv" => tsv = Some(it.next().expect("--tsv PATH").clone()),
            "--repeat" => {
                variant.repeat = it.next().and_then(|v| v.parse().ok()).expect("--repeat N")
            }
            "--grid-kn" => {
                variant.grid_kn = Some(
                    it.next()
                        .expect("--grid-kn a,b,c")
                        .split(',')
                        .map(|v| v.parse::<f64>().expect("a speed in knots"))
                        .collect(),
                )
            }
            n => seeds = n.parse().expect("the number of seeds"),
        }
    }
    let t0 = Instant::now();
    let mut setup = precision_truth::setup(&variant);
    if inferred {
        // A first dive (noise seed 1000, not among the compared seeds)
        // flown by the truth; the autopilot inferred from its logs replaces
        // the declared one.
        let fit = precision_truth::infer_truth_autopilot(&setup, 1000);
        let c = &setup.controller;
        println!("autopilot inferred from the first dive (truth in brackets):");
        for l in &fit.loops {
            let i = l.dof.index();
            println!(
                "  {:<6} kp {:.4e} [{:.4e}]  ki {:.4e} [{:.4e}]  kd {} [{:.4e}]  R² {:.4}  {} pairs",
                l.dof.name(),
                l.gains.kp,
                c.kp[i],
                l.gains.ki,
                c.ki[i],
                l.gains.kd.map_or("—".to_string(), |k| format!("{k:.4e}")),
                c.kd[i],
                l.r_squared,
                l.pairs
            );
        }
        if let Some(g) = &fit.autopilot.restoring_feed_forward {
            println!(
                "  W − B {:.4e} [{:.4e}] N, z_G W − z_B B {:.4e} [{:.4e}] N·m",
                g.w_minus_b, c.nominal_w_minus_b, g.zg_w_minus_zb_b, c.nominal_zg_w_minus_zb_b
            );
        }
        setup.profile.autopilot = Some(fit.autopilot);
    }
    let hours = setup.plan.totals.total_time_s / 3600.0;
    println!(
        "plan: {} runs, {hours:.2} ship hours (runs and set-up)",
        setup.plan.experiments.len()
    );
    let pred = precision_truth::predict(&setup);
    eprintln!(
        "predicted {} parameters from {} runs in {:.1} s",
        pred.total,
        pred.runs,
        t0.elapsed().as_secs_f64()
    );
    let t1 = Instant::now();
    let seed_list: Vec<u64> = (1..=seeds as u64).collect();
    let est = if retune {
        precision_truth::fly_seeds_with(
            &setup,
            &seed_list,
            threads,
            precision_truth::fly_and_identify_retuned,
        )
    } else {
        precision_truth::fly_seeds(&setup, &seed_list, threads)
    };
    eprintln!(
        "{seeds} truth campaigns flown and identified in {:.1} s",
        t1.elapsed().as_secs_f64()
    );
    let (mut cmp, missing) = precision_truth::compare(&pred, &est);
    if missing > 0 {
        println!("{missing} predicted parameters missing from some seed's identification");
    }
    if own {
        let t2 = Instant::now();
        let preds: Vec<_> = seed_list
            .iter()
            .map(|&k| precision_truth::predict_seed(&setup, k))
            .collect();
        precision_truth::add_self_spread(&mut cmp, &preds);
        eprintln!(
            "{seeds} own-simulator predictions in {:.1} s",
            t2.elapsed().as_secs_f64()
        );
    }
    precision_truth::print_table(&cmp, seeds);
    if let Some(path) = tsv {
        precision_truth::write_tsv(&path, &cmp, hours).expect("the TSV file");
        eprintln!("rows written to {path}");
    }
}
