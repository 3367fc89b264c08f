//! Planning speed: the demo campaigns end to end, and the pieces that
//! dominate them (PE order, schedule spectrum). `cargo bench -p seatrial-core`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use seatrial_core::planning::analysis::schedule_spectrum;
use seatrial_core::planning::examples::{
    supply_vessel, supply_vessel_campaign, surveyor_campaign, surveyor_rov,
};
use seatrial_core::planning::{CampaignSpec, generate_plan};
use seatrial_core::signals;

fn rov() -> CampaignSpec {
    surveyor_campaign(1)
}

fn dp() -> CampaignSpec {
    supply_vessel_campaign(1)
}

fn bench(c: &mut Criterion) {
    let (v, s) = (surveyor_rov(), rov());
    c.bench_function("plan ROV 7 grid points, 127 experiments", |b| {
        b.iter(|| generate_plan(black_box(&v), black_box(&s)).unwrap())
    });
    let (v, s) = (supply_vessel(), dp());
    c.bench_function("plan DP 3 manoeuvres x 2", |b| {
        b.iter(|| generate_plan(black_box(&v), black_box(&s)).unwrap())
    });
    let x: Vec<f64> = (0..3000)
        .map(|k| if (k / 37) % 3 == 0 { 1.0 } else { -0.5 })
        .collect();
    c.bench_function("pe_order 3000 samples, cap 24", |b| {
        b.iter(|| signals::pe_order(black_box(&x), 24, signals::DEFAULT_PE_TOL).unwrap())
    });
    let y: Vec<f64> = (0..6000).map(|k| ((k as f64) * 0.01).sin()).collect();
    c.bench_function("schedule spectrum 6000 samples", |b| {
        b.iter(|| schedule_spectrum(black_box(&y), 20.0).unwrap())
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
