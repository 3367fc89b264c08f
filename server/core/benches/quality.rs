//! Quality-report speed (the acceptance figures against scipy, see
//! `benches/compare_scipy.sh`).
//!
//! Cases, all at 10 Hz with 6 inputs and 6 outputs (12 channels, all 36
//! input→output pairs):
//! - `report_1h`: the whole [`quality_report`] of a 1-hour log (36,000
//!   samples) with the report's default `nperseg` (`default_nperseg` of the
//!   longest valid block: 4096 here);
//! - `report_10h`: the whole report of a 10-hour campaign (360,000 samples),
//!   `nperseg = 4096`;
//! - `multi_welch_1h` / `multi_welch_10h`: the spectral part alone (12 PSDs
//!   and 36 CSDs);
//! - `fft_only_1h` / `fft_only_10h`: a bare loop of the same number of
//!   4096-point real FFTs (12 per segment) of one cached segment, the floor
//!   for the spectra;
//! - `fft_segments_1h` / `fft_segments_10h`: the same FFTs of the log's own
//!   segments, each windowed straight from the record (the floor with the
//!   data read from memory, as any Welch estimate must);
//! - `fft_pairs_only_*`: half as many complex FFTs of 4096 points (two real
//!   channels packed in one), for reference: ~10 % below `fft_only`.
//!
//! The report runs as in the service: its halves on rayon's pool, memory
//! from mimalloc.
//!
//! `cargo bench -p seatrial-core --bench quality`.

use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use realfft::RealFftPlanner;
use seatrial_core::planning::Dof;
use seatrial_core::quality::{DofChannels, QualitySpec, quality_report};
use seatrial_core::spectra::{WelchConfig, multi_welch};
use seatrial_core::timeseries::UniformRecord;

/// The service's allocator (`server/src/main.rs`): measured as it runs.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

const FS: f64 = 10.0;
const NPERSEG: usize = 4096;

/// SplitMix64 with Box–Muller normals (deterministic, dependency-free).
struct Rng(u64);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        let out = seatrial_core::rng::mix(self.0);
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        out
    }

    fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 1.0) / (1u64 << 53) as f64
    }

    fn normal(&mut self) -> f64 {
        (-2.0 * self.uniform().ln()).sqrt() * (2.0 * std::f64::consts::PI * self.uniform()).cos()
    }
}

/// A 6-DOF trial log: inputs `tau_*` are random binary signals held for
/// 5–10 samples (PRBS-like), outputs `u v w p q r` first-order lags of their
/// own input plus 10 % coupling from the next one and measurement noise.
fn trial_log(n: usize) -> UniformRecord {
    let mut rng = Rng(2024);
    let inputs: Vec<Vec<f64>> = (0..6)
        .map(|d| {
            let hold = 5 + d;
            let mut level = 0.0;
            (0..n)
                .map(|k| {
                    if k % hold == 0 {
                        level = if rng.uniform() < 0.5 { -1.0 } else { 1.0 } * 1000.0;
                    }
                    level
                })
                .collect()
        })
        .collect();
    let outputs: Vec<Vec<f64>> = (0..6)
        .map(|d| {
            let a = 0.95 - 0.02 * d as f64;
            let mut s = 0.0;
            (0..n)
                .map(|k| {
                    s = a * s + 1e-4 * (inputs[d][k] + 0.1 * inputs[(d + 1) % 6][k]);
                    s + 0.01 * rng.normal()
                })
                .collect()
        })
        .collect();
    let names: Vec<String> = Dof::ALL
        .iter()
        .map(|d| d.force_column().to_owned())
        .chain(Dof::ALL.iter().map(|d| d.velocity_symbol().to_owned()))
        .collect();
    UniformRecord {
        sample_rate_hz: FS,
        t0: 0.0,
        names,
        data: inputs.into_iter().chain(outputs).collect(),
        valid: std::iter::once(0..n).collect(),
    }
}

fn spec(nperseg: Option<usize>) -> QualitySpec {
    let mut spec = QualitySpec::new(
        Dof::ALL
            .iter()
            .map(|d| d.force_column().to_owned())
            .collect(),
        Dof::ALL
            .iter()
            .map(|d| d.velocity_symbol().to_owned())
            .collect(),
    );
    spec.dofs = Dof::ALL
        .iter()
        .map(|&dof| DofChannels {
            dof,
            input: dof.force_column().to_owned(),
            output: dof.velocity_symbol().to_owned(),
        })
        .collect();
    spec.nperseg = nperseg;
    spec
}

fn io_pairs() -> Vec<(usize, usize)> {
    (0..6).flat_map(|i| (6..12).map(move |o| (i, o))).collect()
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("quality");
    g.sample_size(20)
        .warm_up_time(Duration::from_secs(2))
        .measurement_time(Duration::from_secs(8));
    for (label, n, nperseg) in [("1h", 36_000, None), ("10h", 360_000, Some(NPERSEG))] {
        let rec = trial_log(n);
        let spec = spec(nperseg);
        g.bench_function(format!("report_{label}"), |b| {
            b.iter(|| quality_report(black_box(&rec), black_box(&spec)).unwrap())
        });

        let cfg = WelchConfig::hann(FS, nperseg.unwrap_or(NPERSEG));
        let chans: Vec<&[f64]> = rec.data.iter().map(Vec::as_slice).collect();
        let pairs = io_pairs();
        g.bench_function(format!("multi_welch_{label}"), |b| {
            b.iter(|| multi_welch(black_box(&chans), &rec.valid, &pairs, &cfg).unwrap())
        });

        let n_ffts = cfg.n_segments(n) * chans.len();
        let fft = RealFftPlanner::<f64>::new().plan_fft_forward(cfg.nperseg);
        let mut input = fft.make_input_vec();
        let mut output = fft.make_output_vec();
        let mut scratch = fft.make_scratch_vec();
        let signal = &rec.data[0][..cfg.nperseg];
        g.bench_function(format!("fft_only_{label}"), |b| {
            b.iter(|| {
                for _ in 0..n_ffts {
                    input.copy_from_slice(signal);
                    fft.process_with_scratch(&mut input, &mut output, &mut scratch)
                        .unwrap();
                }
                black_box(&output);
            })
        });

        // The same FFTs of the record's own segments: each windowed straight
        // from the log (so the data are read from memory as the report
        // must), no detrend, no accumulation.
        let window = seatrial_core::spectra::Window::Hann.coefficients(cfg.nperseg);
        let step = cfg.nperseg - cfg.noverlap;
        let n_segments = cfg.n_segments(n);
        g.bench_function(format!("fft_segments_{label}"), |b| {
            b.iter(|| {
                for m in 0..n_segments {
                    for ch in &chans {
                        let seg = &ch[m * step..m * step + cfg.nperseg];
                        for ((v, x), w) in input.iter_mut().zip(seg).zip(&window) {
                            *v = x * w;
                        }
                        fft.process_with_scratch(&mut input, &mut output, &mut scratch)
                            .unwrap();
                    }
                }
                black_box(&output);
            })
        });

        let cfft = rustfft::FftPlanner::<f64>::new().plan_fft_forward(cfg.nperseg);
        let mut buf = vec![rustfft::num_complex::Complex::new(0.0, 0.0); cfg.nperseg];
        let mut cscratch = vec![buf[0]; cfft.get_inplace_scratch_len()];
        g.bench_function(format!("fft_pairs_only_{label}"), |b| {
            b.iter(|| {
                for _ in 0..n_ffts.div_ceil(2) {
                    for (z, &x) in buf.iter_mut().zip(signal) {
                        *z = rustfft::num_complex::Complex::new(x, -x);
                    }
                    cfft.process_with_scratch(&mut buf, &mut cscratch);
                }
                black_box(&buf);
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
