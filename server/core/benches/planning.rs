//! Planning speed: the demo campaigns end to end, and the pieces that
//! dominate them (PE order, schedule spectrum). `cargo bench -p seatrial-core`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use seatrial_core::planning::analysis::schedule_spectrum;
use seatrial_core::planning::campaign::{Durations, Excitation};
use seatrial_core::planning::examples::{supply_vessel, surveyor_rov};
use seatrial_core::planning::{
    CampaignSpec, ExperimentFamily, SpeedGrid, SpeedUnit, generate_plan,
};
use seatrial_core::signals;

fn rov() -> CampaignSpec {
    CampaignSpec {
        name: "bench".into(),
        grid: SpeedGrid {
            unit: SpeedUnit::Knots,
            speeds: vec![0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5],
        },
        families: vec![
            ExperimentFamily::Static,
            ExperimentFamily::Dynamic,
            ExperimentFamily::Recursive,
            ExperimentFamily::Validation,
        ],
        repetitions: None,
        excitation: Excitation::default(),
        durations: Durations::default(),
        seed: 1,
    }
}

fn dp() -> CampaignSpec {
    CampaignSpec {
        name: "bench".into(),
        grid: SpeedGrid {
            unit: SpeedUnit::MetersPerSecond,
            speeds: vec![0.0],
        },
        families: vec![
            ExperimentFamily::DpSurge,
            ExperimentFamily::DpSwayYaw,
            ExperimentFamily::DpAzimuth,
        ],
        repetitions: Some(2),
        excitation: Excitation::default(),
        durations: Durations::default(),
        seed: 1,
    }
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
