//! Prints the missing-physics discovery proof table: every proof case
//! (`seatrial_core::discrepancy::proof::cases`) on the ROV truth, with the
//! effect named first, its DOFs, the concealed magnitude against the
//! estimate ± std, the share of the validation gap closed and the time.
//!
//! `cargo run --release -p seatrial-core --example discovery_table [seed …]`
//! (default seed 11, the one the test suite runs); `CASES=Coriolis,tether`
//! keeps the cases whose name contains one of those words. Cases beyond the proof
//! (`extra_cases`: a random-walk current) follow, reported as they come out.

use seatrial_core::discrepancy::proof::{cases, extra_cases, format_table, proof_table};

fn main() {
    let seeds: Vec<u64> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("seeds are whole numbers"))
        .collect();
    let seeds = if seeds.is_empty() { vec![11] } else { seeds };
    let wanted = std::env::var("CASES").ok();
    let keep = |name: &str| {
        wanted
            .as_deref()
            .is_none_or(|w| w.split(',').any(|x| name.contains(x.trim())))
    };
    let chosen: Vec<_> = cases().into_iter().filter(|(n, _)| keep(n)).collect();
    let extra: Vec<_> = extra_cases().into_iter().filter(|(n, _)| keep(n)).collect();
    let rows = proof_table(&chosen, &seeds);
    print!("{}", format_table(&rows));
    let failed = rows.iter().filter(|r| r.verdict.is_err()).count();
    println!("{} of {} cases pass", rows.len() - failed, rows.len());
    println!("\nBeyond the proof (reported, not required):");
    print!("{}", format_table(&proof_table(&extra, &seeds)));
}
