//! Prints, per seeded vessel of the independent truth (`seatrial-truth`),
//! the λ-filter identification's parameter errors in σ and its validation
//! fits against the true model and an affine least-squares baseline.
//!
//! `cargo run --release -p seatrial-core --example open_world_table [seeds…] [--structure diagonal|coupled|auto] [--in-grid] [--validation-speeds 0.3,0.75] [--noise-free] [--zero-noise vl,va,rp,pos] [--controller-hz 20] [--projected-m] [--linear-damping] [--held-above]`
//!
//! `--in-grid` flies the validation staircase at speeds inside the grid
//! (0.5, 0.75, 1.25, 1.75, 2.0 m/s) instead of below, between and beyond it,
//! `--validation-speeds` at the listed ones (m/s);
//! `--noise-free` flies without measurement noise, `--zero-noise` without
//! the listed part of it (linear velocities, angular rates, roll and pitch,
//! positions with depth and heading); `--controller-hz` tells the identification the controller's rate (the
//! truth's loop runs at 20 Hz, logged at 10 Hz); `--projected-m` fits M's
//! rows freely and stores the nearest symmetric M (`symmetric_inertia:
//! false`); `--linear-damping` fits linear damping only
//! (`quadratic_damping: false`); `--held-above` holds the top sub-model
//! above the grid (`extend_above_grid: false`).

#[path = "../tests/support/open_world.rs"]
mod open_world;

use seatrial_core::identification::lambda_campaign::StructureChoice;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut seeds = Vec::new();
    let mut structure = None;
    let mut controller_hz = None;
    let mut symmetric = true;
    let mut quadratic = true;
    let mut above = true;
    let mut spec = seatrial_truth::CampaignSpec::default();
    let mut it = args.iter();
    while let Some(a) = it.next() {
        if a == "--structure" {
            structure = it.next().map(|s| match s.as_str() {
                "diagonal" => StructureChoice::Diagonal,
                "coupled" => StructureChoice::Coupled,
                "symmetric" => StructureChoice::Symmetric,
                _ => StructureChoice::Auto,
            });
        } else if a == "--controller-hz" {
            controller_hz = it.next().and_then(|v| v.parse::<f64>().ok());
        } else if a == "--projected-m" {
            symmetric = false;
        } else if a == "--linear-damping" {
            quadratic = false;
        } else if a == "--held-above" {
            above = false;
        } else if a == "--noise-free" {
            spec.noise = seatrial_truth::NoiseSpec::none();
        } else if a == "--zero-noise" {
            for part in it.next().map(String::as_str).unwrap_or("").split(',') {
                for noise in [&mut spec.noise, &mut spec.nav_noise] {
                    zero_noise(noise, part);
                }
            }
        } else if a == "--validation-speeds" {
            spec.validation_speeds = it
                .next()
                .map(|v| v.split(',').filter_map(|x| x.parse::<f64>().ok()).collect());
        } else if a == "--in-grid" {
            spec.validation_speeds = Some(vec![0.5, 0.75, 1.25, 1.75, 2.0]);
        } else if let Ok(s) = a.parse::<u64>() {
            seeds.push(s);
        }
    }
    if seeds.is_empty() {
        seeds = vec![1, 2, 3, 4, 5];
    }
    let mut settings = open_world::settings(structure);
    settings.controller_rate_hz = controller_hz;
    settings.symmetric_inertia = symmetric;
    settings.quadratic_damping = quadratic;
    settings.extend_above_grid = above;
    for seed in seeds {
        let t = std::time::Instant::now();
        let r = open_world::evaluate_with(seed, true, &settings, &spec);
        let within = r.z.iter().filter(|z| z.z().abs() <= 3.0).count();
        println!(
            "\n## seed {seed}: {within}/{} parameters within ±3σ ({:.0} %), {:.1} s",
            r.z.len(),
            100.0 * within as f64 / r.z.len().max(1) as f64,
            t.elapsed().as_secs_f64()
        );
        let mut worst: Vec<_> = r.z.iter().collect();
        worst.sort_by(|a, b| b.z().abs().total_cmp(&a.z().abs()));
        let filter = std::env::var("SHOW").ok();
        let shown: Vec<_> = match &filter {
            Some(f) => r.z.iter().filter(|z| z.name.contains(f.as_str())).collect(),
            None => worst.iter().take(12).copied().collect(),
        };
        for z in shown {
            println!(
                "  {:<22} est {:>11.4} truth {:>11.4} σ {:>9.4} z {:>7.1}",
                z.name,
                z.estimate,
                z.truth,
                z.std,
                z.z()
            );
        }
        println!("  channel | 1-step  true   affine | free run  true   oracle");
        let f = |x: Option<f64>| x.map_or("   —  ".into(), |v| format!("{v:6.3}"));
        for c in &r.fits {
            println!(
                "  {:<7} | {} {} {} | {} {} {}",
                c.channel,
                f(c.one_step),
                f(c.one_step_true),
                f(c.one_step_affine),
                f(c.free_run),
                f(c.free_run_true),
                f(c.free_run_oracle)
            );
        }
        for s in r.findings.iter().chain(&r.notes) {
            println!("  - {s}");
        }
    }
}

/// `noise` without one part: `vl` linear velocities, `va` angular rates,
/// `rp` roll and pitch, `pos` positions, depth and heading.
fn zero_noise(noise: &mut seatrial_truth::NoiseSpec, part: &str) {
    match part {
        "vl" => noise.velocity_linear = 0.0,
        "va" => noise.velocity_angular = 0.0,
        "rp" => noise.roll_pitch = 0.0,
        "pos" => (noise.position_xy, noise.depth, noise.heading) = (0.0, 0.0, 0.0),
        other => panic!("--zero-noise: unknown part '{other}' (vl, va, rp, pos)"),
    }
}
