//! Prints the discovery table on the independent truth: per seed, a drawn
//! vessel with each concealed effect alone (and the clean case), identified
//! and examined by the service's campaign discovery — what was named, at how
//! many grid points, whether the augmented model passed the held-out gate,
//! and the share of the baseline-to-truth gap it closed on the held-out run.
//!
//! `cargo run --release -p seatrial-core --example open_world_discovery [seeds…]`
//! (default seed 1); `CASES=current,tether` keeps cases whose name contains
//! one of those words.

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
    let spec = seatrial_truth::CampaignSpec::default();
    let mut cases = Vec::new();
    for &seed in &seeds {
        for c in Concealed::ALL.into_iter().filter(|c| keep(c.name())) {
            let case = discover_case(seed, c, &spec);
            eprint!("{}", format_cases(std::slice::from_ref(&case)));
            cases.push(case);
        }
    }
    println!("{}", format_cases(&cases));
}
