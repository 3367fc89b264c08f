//! Prints the discovery table on the independent truth: per seed, a drawn
//! vessel with each concealed effect alone (and the clean case), identified
//! and examined by the service's campaign discovery — what was named, at how
//! many grid points, whether the augmented model passed the held-out gate,
//! and the share of the baseline-to-truth gap it closed on the held-out run.
//!
//! `cargo run --release -p seatrial-core --example open_world_discovery [seeds…]`
//! (default seed 1); `CASES=current,tether` keeps cases whose name contains
//! one of those words; `TIER=small` runs the small tier instead (the
//! issue's sensitivity sizes: 0.04 s lag and delay, saturation at 70 %, a
//! 5–10 % dead zone, a 0.05 m/s current, quadratic yaw damping doubled),
//! `TIER=all` both.

#[path = "../tests/support/mod.rs"]
mod support;

use support::open_world_discovery::{Concealed, discover_case, format_cases};

fn main() {
    let seeds: Vec<u64> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("seeds are whole numbers"))
        .collect();
    let seeds = if seeds.is_empty() { vec![1] } else { seeds };
    let wanted = std::env::var("CASES").ok();
    let keep = |name: &str| {
        wanted
            .as_deref()
            .is_none_or(|w| w.split(',').any(|x| name.contains(x.trim())))
    };
    let tier: Vec<Concealed> = match std::env::var("TIER").as_deref() {
        Ok("small") => Concealed::SMALL.to_vec(),
        Ok("all") => [Concealed::ALL.as_slice(), Concealed::SMALL.as_slice()].concat(),
        _ => Concealed::ALL.to_vec(),
    };
    let spec = seatrial_truth::CampaignSpec::default();
    let mut cases = Vec::new();
    for &seed in &seeds {
        for c in tier.iter().copied().filter(|c| keep(c.name())) {
            let case = discover_case(seed, c, &spec);
            eprint!("{}", format_cases(std::slice::from_ref(&case)));
            cases.push(case);
        }
    }
    println!("{}", format_cases(&cases));
}
