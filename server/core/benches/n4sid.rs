//! N4SID speed and validation fit (the acceptance figures against sippy,
//! see `benches/compare_sippy.sh`).
//!
//! A 6-input, 6-output, 6th-order innovation model at h = 0.1 s (coupled
//! first-order velocity lags, time constants 1–4 s, innovation gain K),
//! driven by random binary inputs held 3–8 samples. Cases
//! `n4sid/N` for N = 4,000 / 40,000 / 360,000 samples: the whole
//! identification (unweighted N4SID, horizon i = 10, order fixed at 6,
//! D = 0 — the settings of sippy's `system_identification(y, u, 'N4SID',
//! SS_f=10, SS_fixed_order=6)`).
//!
//! With `N4SID_EXPORT_DIR` set, first writes the training runs
//! `train_<N>.csv`, a held-out run `valid.csv` (columns u0..u5, y0..y5) and
//! `rust_fits.json` (validation NRMSE of each model: free-run simulation
//! and 1-step prediction, mean over outputs).
//!
//! `cargo bench -p seatrial-core --bench n4sid`.

use std::fmt::Write as _;
use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::{DMatrix, DVector};
use seatrial_core::estimation::NoProgress;
use seatrial_core::estimation::n4sid::{N4sidSettings, Weighting, n4sid};
use seatrial_core::rng::SplitMix64;
use seatrial_core::validation::{Predictor, ValidationRecord, nrmse_fit_columns};

const H: f64 = 0.1;
const M: usize = 6;
const L: usize = 6;
const ORDER: usize = 6;
const HORIZON: usize = 10;
const SIZES: [usize; 3] = [4_000, 40_000, 360_000];
const VALID: usize = 20_000;

struct Truth {
    a: DMatrix<f64>,
    b: DMatrix<f64>,
    c: DMatrix<f64>,
    k: DMatrix<f64>,
    noise: f64,
}

fn truth() -> Truth {
    let mut rng = SplitMix64::new(66);
    let poles: Vec<f64> = [1.0, 1.5, 2.0, 2.5, 3.0, 4.0]
        .iter()
        .map(|tau: &f64| (-H / tau).exp())
        .collect();
    // Coupled: A = T diag(poles) T⁻¹ with T = I + 0.2 · random.
    let t = DMatrix::from_fn(ORDER, ORDER, |r, c| {
        f64::from(u8::from(r == c)) + 0.2 * rng.uniform_in(-1.0, 1.0)
    });
    let a =
        &t * DMatrix::from_diagonal(&DVector::from_vec(poles)) * t.clone().try_inverse().unwrap();
    let b = DMatrix::from_fn(ORDER, M, |r, c| {
        if r == c {
            H
        } else {
            0.02 * rng.uniform_in(-1.0, 1.0)
        }
    });
    let c = DMatrix::from_fn(L, ORDER, |r, c| {
        f64::from(u8::from(r == c)) + 0.1 * rng.uniform_in(-1.0, 1.0)
    });
    let k = DMatrix::from_fn(ORDER, L, |r, c| if r == c { 0.3 } else { 0.0 });
    Truth {
        a,
        b,
        c,
        k,
        noise: 0.02,
    }
}

/// A run of n samples: random binary inputs (±1 held 3–8 samples) and the
/// outputs of the innovation model (e white, std `noise`).
fn run(sys: &Truth, n: usize, seed: u64) -> (DMatrix<f64>, DMatrix<f64>) {
    let mut rng = SplitMix64::new(seed);
    let mut u = DMatrix::zeros(n, M);
    for ch in 0..M {
        let mut t = 0;
        while t < n {
            let hold = 3 + (rng.next_u64() % 6) as usize;
            let level = if rng.uniform() < 0.5 { -1.0 } else { 1.0 };
            for s in t..(t + hold).min(n) {
                u[(s, ch)] = level;
            }
            t += hold;
        }
    }
    let mut y = DMatrix::zeros(n, L);
    let mut x = DVector::zeros(ORDER);
    for t in 0..n {
        let e = DVector::from_fn(L, |_, _| sys.noise * rng.normal());
        let ut = u.row(t).transpose();
        let yt = &sys.c * &x + &e;
        y.row_mut(t).copy_from(&yt.transpose());
        x = &sys.a * &x + &sys.b * &ut + &sys.k * e;
    }
    (u, y)
}

fn settings() -> N4sidSettings {
    N4sidSettings {
        horizon: HORIZON,
        order: Some(ORDER),
        max_order: ORDER,
        weighting: Weighting::N4sid,
        estimate_d: false,
        ..N4sidSettings::new(H)
    }
}

fn write_csv(path: &std::path::Path, u: &DMatrix<f64>, y: &DMatrix<f64>) {
    let mut s = String::new();
    let names: Vec<String> = (0..M)
        .map(|k| format!("u{k}"))
        .chain((0..L).map(|k| format!("y{k}")))
        .collect();
    s.push_str(&names.join(","));
    s.push('\n');
    for t in 0..u.nrows() {
        let row: Vec<String> = u
            .row(t)
            .iter()
            .chain(y.row(t).iter())
            .map(|v| format!("{v:.17e}"))
            .collect();
        s.push_str(&row.join(","));
        s.push('\n');
    }
    std::fs::write(path, s).expect("write csv");
}

fn mean_fit(measured: &DMatrix<f64>, predicted: &DMatrix<f64>) -> f64 {
    let fits = nrmse_fit_columns(measured, predicted);
    fits.iter().map(|f| f.unwrap_or(f64::NAN)).sum::<f64>() / fits.len() as f64
}

/// Writes the data and Rust's validation fits for compare_sippy.sh.
fn export(sys: &Truth, dir: &str) {
    let dir = std::path::Path::new(dir);
    std::fs::create_dir_all(dir).expect("export dir");
    let (uv, yv) = run(sys, VALID, 999);
    write_csv(&dir.join("valid.csv"), &uv, &yv);
    let rec = ValidationRecord {
        h: H,
        u: &uv,
        y: &yv,
    };
    let mut json = String::from("{\"horizon\": 10, \"order\": 6, \"cases\": {");
    for (k, &n) in SIZES.iter().enumerate() {
        let (u, y) = run(sys, n, n as u64);
        write_csv(&dir.join(format!("train_{n}.csv")), &u, &y);
        let model = n4sid(&[(&u, &y)], &settings(), &mut NoProgress).expect("n4sid");
        let sim = mean_fit(&yv, &model.simulate(&rec));
        let one = mean_fit(&yv, &model.predict_k_step(&rec, 1));
        let sep = if k == 0 { "" } else { ", " };
        let _ = write!(
            json,
            "{sep}\"{n}\": {{\"sim_fit\": {sim:.6}, \"one_step_fit\": {one:.6}}}"
        );
    }
    json.push_str("}}\n");
    std::fs::write(dir.join("rust_fits.json"), json).expect("write json");
}

fn bench(c: &mut Criterion) {
    let sys = truth();
    if let Ok(dir) = std::env::var("N4SID_EXPORT_DIR") {
        export(&sys, &dir);
    }
    let mut group = c.benchmark_group("n4sid");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(20));
    for n in SIZES {
        let (u, y) = run(&sys, n, n as u64);
        let set = settings();
        group.bench_function(format!("{n}"), |bch| {
            bch.iter(|| n4sid(&[(black_box(&u), black_box(&y))], &set, &mut NoProgress).unwrap())
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
