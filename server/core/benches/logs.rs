//! Log parsing speed: a ~100 MB in-memory CSV of the supply vessel
//! (820 000 rows × 13 columns: t, thr_1..thr_6, u, v, r, x, y, psi), parsed
//! and checked by `parse_log`, then resampled by `to_uniform`.
//! `cargo bench -p seatrial-core --bench logs`.

use std::fmt::Write;
use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use seatrial_core::logs::{LogRole, ParseOptions, parse_log, to_uniform};
use seatrial_core::planning::examples::supply_vessel;

const ROWS: usize = 820_000;

/// A 10 Hz DP log with values of realistic length (≈ 122 bytes a row).
fn csv() -> String {
    let mut s = String::with_capacity(ROWS * 128);
    s.push_str("t,thr_1,thr_2,thr_3,thr_4,thr_5,thr_6,u,v,r,x,y,psi\n");
    for k in 0..ROWS {
        let t = k as f64 * 0.1;
        let _ = write!(s, "{t:.1}");
        for i in 0..6 {
            let _ = write!(s, ",{:.6}", (0.01 * t + i as f64).sin() * 0.9);
        }
        let _ = writeln!(
            s,
            ",{:.6},{:.6},{:.7},{:.4},{:.4},{:.6}",
            1.5 + 0.5 * (0.003 * t).sin(),
            0.2 * (0.004 * t).cos(),
            0.01 * (0.02 * t).sin(),
            1500.0 * (1e-4 * t).sin(),
            -800.0 * (1e-4 * t).cos(),
            (0.001 * t).sin() * 3.0,
        );
    }
    s
}

fn bench(c: &mut Criterion) {
    let data = csv();
    let opts = ParseOptions::for_vessel(&supply_vessel(), LogRole::Single, None);
    let mut g = c.benchmark_group("logs");
    g.sample_size(10)
        .measurement_time(Duration::from_secs(10))
        .throughput(Throughput::Bytes(data.len() as u64));
    g.bench_function(
        format!("parse_log {} MB, {ROWS} rows x 13", data.len() / 1_000_000),
        |b| b.iter(|| parse_log(black_box(data.as_bytes()), &opts).unwrap()),
    );
    let parsed = parse_log(data.as_bytes(), &opts).unwrap();
    g.bench_function(format!("to_uniform {ROWS} rows x 12"), |b| {
        b.iter(|| to_uniform(black_box(&parsed.table), None).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
