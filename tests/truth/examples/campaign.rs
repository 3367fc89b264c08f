//! Flies a seeded campaign and writes its CSVs and truth.json:
//!
//!   cargo run --release -p seatrial-truth --example campaign -- <seed> <out_dir> [surveyor]
//!
//! The vessel is `Vessel::draw(seed)`, or `Vessel::surveyor_like()` with a
//! third argument `surveyor`; the campaign is `CampaignSpec::default()`.

use std::path::PathBuf;
use std::time::Instant;

use seatrial_truth::{CampaignSpec, Vessel, fly_campaign};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (Some(seed), Some(dir)) = (args.first(), args.get(1)) else {
        eprintln!("usage: campaign <seed> <out_dir> [surveyor]");
        std::process::exit(2);
    };
    let Ok(seed) = seed.parse::<u64>() else {
        eprintln!("seed must be an unsigned integer, got {seed:?}");
        std::process::exit(2);
    };
    let vessel = if args.get(2).map(String::as_str) == Some("surveyor") {
        Vessel::surveyor_like()
    } else {
        Vessel::draw(seed)
    };
    let start = Instant::now();
    let campaign = fly_campaign(&vessel, &CampaignSpec::default(), seed);
    let flown = start.elapsed();
    let dir = PathBuf::from(dir);
    if let Err(e) = campaign.write_dir(&dir) {
        eprintln!("cannot write {}: {e}", dir.display());
        std::process::exit(1);
    }
    let worst = campaign
        .runs
        .iter()
        .map(|r| r.meta.saturated_fraction)
        .fold(0.0f64, f64::max);
    println!(
        "{}: m = {:.1} kg, {} runs flown in {:.2} s, clock offset {:.3} s, worst saturation {:.2} %, written to {}",
        vessel.name,
        vessel.mass,
        campaign.runs.len(),
        flown.as_secs_f64(),
        campaign.clock_offset_s,
        100.0 * worst,
        dir.display()
    );
}
