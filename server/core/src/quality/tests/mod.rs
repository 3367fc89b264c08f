//! Tests of the quality report against known truth: deterministic seeded
//! signals whose spectra, coherence, frequency response, rank, excitation
//! and plan lag are known in closed form.

#![allow(clippy::single_range_in_vec_init)] // vectors of blocks

use std::f64::consts::PI;

use super::*;
use crate::planning::Dof;
use crate::spectra::{Complex, WelchConfig, coherence, csd, multi_welch, tfestimate_h1, welch};
use crate::timeseries::UniformRecord;

mod adherence;
mod errors;
mod nyquist;
mod regressor;
mod report_spectra;
mod verdicts;

/// SplitMix64 with Box–Muller normals: deterministic, dependency-free.
struct Rng {
    state: u64,
}

impl Rng {
    fn new(seed: u64) -> Self {
        Rng { state: seed }
    }

    fn next_u64(&mut self) -> u64 {
        let out = crate::rng::mix(self.state);
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        out
    }

    fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 1.0) / (1u64 << 53) as f64
    }

    fn normal(&mut self) -> f64 {
        (-2.0 * self.uniform().ln()).sqrt() * (2.0 * PI * self.uniform()).cos()
    }

    fn white(&mut self, n: usize, sigma: f64) -> Vec<f64> {
        (0..n).map(|_| sigma * self.normal()).collect()
    }

    /// Random ±`amp` levels held for `hold` samples (a PRBS-like input).
    fn binary(&mut self, n: usize, hold: usize, amp: f64) -> Vec<f64> {
        let mut level = amp;
        (0..n)
            .map(|k| {
                if k % hold == 0 {
                    level = if self.uniform() < 0.5 { -amp } else { amp };
                }
                level
            })
            .collect()
    }
}

/// `y[n] = a·y[n−1] + b·x[n]`: H(e^{jω}) = b / (1 − a e^{−jω}).
fn first_order(x: &[f64], a: f64, b: f64) -> Vec<f64> {
    let mut s = 0.0;
    x.iter()
        .map(|v| {
            s = a * s + b * v;
            s
        })
        .collect()
}

fn add_noise(y: &[f64], rng: &mut Rng, sigma: f64) -> Vec<f64> {
    y.iter().map(|v| v + sigma * rng.normal()).collect()
}

fn record(fs: f64, cols: Vec<(&str, Vec<f64>)>) -> UniformRecord {
    let n = cols[0].1.len();
    UniformRecord {
        sample_rate_hz: fs,
        t0: 0.0,
        names: cols.iter().map(|c| c.0.to_owned()).collect(),
        data: cols.into_iter().map(|c| c.1).collect(),
        valid: vec![0..n],
    }
}

fn names(v: &[&str]) -> Vec<String> {
    v.iter().map(|s| (*s).to_owned()).collect()
}

fn assert_close(a: &[f64], e: &[f64], tol: f64, what: &str) {
    assert_eq!(a.len(), e.len(), "{what}: length");
    let scale = e
        .iter()
        .filter(|v| v.is_finite())
        .fold(0.0f64, |m, v| m.max(v.abs()));
    for (k, (x, y)) in a.iter().zip(e).enumerate() {
        if x.is_infinite() || y.is_infinite() {
            assert_eq!(x, y, "{what}[{k}]");
            continue;
        }
        assert!(
            (x - y).abs() <= tol * scale,
            "{what}[{k}]: {x} vs {y} (scale {scale:e})"
        );
    }
}

/// A sway DOF: `tau_Y` (PRBS-like, held 5 samples) → `v` (first-order lag
/// with time constant ≈ 2 s at 10 Hz) plus output noise `sn`.
fn sway_log(n: usize, sn: f64, seed: u64) -> UniformRecord {
    let mut rng = Rng::new(seed);
    let x = rng.binary(n, 5, 2000.0);
    let y = add_noise(&first_order(&x, 0.95, 5e-6), &mut rng, sn);
    record(10.0, vec![("tau_Y", x), ("v", y)])
}

fn sway_spec() -> QualitySpec {
    QualitySpec::new(names(&["tau_Y"]), names(&["v"])).with_dof(Dof::Sway, "tau_Y", "v")
}
