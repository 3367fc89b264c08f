//! Alignment speed: one hour of a 50 Hz navigation log against a 10 Hz
//! control log (clock offset estimate, and the full merge).
//! `cargo bench -p seatrial-core --bench alignment`.

use std::f64::consts::PI;
use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use seatrial_core::alignment::{OffsetOptions, align_logs, estimate_offset};
use seatrial_core::timeseries::LogTable;

/// SplitMix64 uniform in [0, 1).
struct Rng(u64);

impl Rng {
    fn uniform(&mut self) -> f64 {
        let z = seatrial_core::rng::mix(self.0);
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        (z >> 11) as f64 / (1u64 << 53) as f64
    }

    fn normal(&mut self) -> f64 {
        let (u1, u2) = (1.0 - self.uniform(), self.uniform());
        (-2.0 * u1.ln()).sqrt() * (2.0 * PI * u2).cos()
    }
}

/// One hour: control 10 Hz (tau_x, tau_z, z), nav 50 Hz (u, v, w, psi, z),
/// clock offset 3.37 s, ±1 % stamp jitter, 30 dB depth noise.
fn logs() -> (LogTable, LogTable) {
    let mut rng = Rng(7);
    let waves: Vec<(f64, f64, f64)> = (0..80)
        .map(|_| {
            let f = 0.002 + 0.5 * rng.uniform();
            (
                0.2 / (1.0 + (f / 0.1).powi(2)).sqrt(),
                2.0 * PI * f,
                2.0 * PI * rng.uniform(),
            )
        })
        .collect();
    let depth = |t: f64| {
        20.0 + 3.0 * (t / 600.0).sin()
            + waves
                .iter()
                .map(|(a, w, p)| a * (w * t + p).sin())
                .sum::<f64>()
    };
    let sample = |rate: f64, clock: f64, rng: &mut Rng| {
        let n = (3600.0 * rate) as usize;
        let tau: Vec<f64> = (0..n).map(|k| k as f64 / rate).collect();
        let t: Vec<f64> = tau
            .iter()
            .map(|s| s + clock + 0.01 / rate * (2.0 * rng.uniform() - 1.0))
            .collect();
        let z: Vec<f64> = tau
            .iter()
            .map(|&s| depth(s) + 0.07 * rng.normal())
            .collect();
        (tau, t, z)
    };
    let (tau_c, tc, zc) = sample(10.0, 100.0, &mut rng);
    let (tau_n, tn, zn) = sample(50.0, 100.0 - 3.37, &mut rng);
    let square = |tau: &[f64], p: f64| -> Vec<f64> {
        tau.iter()
            .map(|s| {
                if (s / p).floor() as i64 % 2 == 0 {
                    10.0
                } else {
                    -10.0
                }
            })
            .collect()
    };
    let control = LogTable {
        t: tc,
        names: vec!["tau_x".into(), "tau_z".into(), "z".into()],
        data: vec![square(&tau_c, 7.0), square(&tau_c, 11.0), zc],
    };
    let wave = |tau: &[f64], w: f64| -> Vec<f64> { tau.iter().map(|s| (w * s).sin()).collect() };
    let nav = LogTable {
        t: tn,
        names: ["u", "v", "w", "psi", "z"].map(String::from).to_vec(),
        data: vec![
            wave(&tau_n, 0.3),
            wave(&tau_n, 0.2),
            wave(&tau_n, 0.5),
            wave(&tau_n, 0.01),
            zn,
        ],
    };
    (control, nav)
}

fn bench(c: &mut Criterion) {
    let (control, nav) = logs();
    let opts = OffsetOptions::default();
    let zc = control.column("z").unwrap_or_default();
    let zn = nav.column("z").unwrap_or_default();
    let mut group = c.benchmark_group("alignment_1h_nav50_control10");
    group.sample_size(10);
    group.bench_function("estimate_offset", |b| {
        b.iter(|| estimate_offset(black_box(&control.t), zc, black_box(&nav.t), zn, &opts))
    });
    group.bench_function("align_logs", |b| {
        b.iter(|| align_logs(black_box(&control), black_box(&nav), "z", None, &opts))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
