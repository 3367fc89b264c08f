//! Test-only helpers: scipy fixtures, a deterministic Gaussian generator and
//! relative comparisons.

use std::collections::HashMap;

use serde::Deserialize;

use super::{Detrend, WelchConfig, Window};

/// scipy.signal.welch reference cases (see `gen_spectra.py`).
pub(crate) const WELCH_JSON: &str =
    include_str!("../../../../tests/fixtures/spectra/welch_cases.json");
/// scipy.signal.csd / welch / coherence reference cases.
pub(crate) const CROSS_JSON: &str =
    include_str!("../../../../tests/fixtures/spectra/cross_cases.json");

#[derive(Debug, Deserialize)]
pub(crate) struct Fixture<C> {
    pub signals: HashMap<String, Vec<f64>>,
    pub cases: Vec<C>,
}

#[derive(Debug, Deserialize)]
pub(crate) struct CaseParams {
    pub name: String,
    pub fs: f64,
    pub nperseg: usize,
    pub noverlap: usize,
    pub detrend: String,
}

impl CaseParams {
    pub fn config(&self) -> WelchConfig {
        WelchConfig {
            fs: self.fs,
            nperseg: self.nperseg,
            noverlap: self.noverlap,
            window: Window::Hann,
            detrend: match self.detrend.as_str() {
                "none" => Detrend::None,
                "constant" => Detrend::Constant,
                "linear" => Detrend::Linear,
                other => panic!("unknown detrend {other} in fixture {}", self.name),
            },
        }
    }
}

#[derive(Debug, Deserialize)]
pub(crate) struct WelchCase {
    #[serde(flatten)]
    pub params: CaseParams,
    pub x: String,
    pub freqs: Vec<f64>,
    pub pxx: Vec<f64>,
}

#[derive(Debug, Deserialize)]
pub(crate) struct CrossCase {
    #[serde(flatten)]
    pub params: CaseParams,
    pub x: String,
    pub y: String,
    pub freqs: Vec<f64>,
    pub pxy_re: Vec<f64>,
    pub pxy_im: Vec<f64>,
    pub pxx: Vec<f64>,
    pub pyy: Vec<f64>,
    pub coherence: Vec<f64>,
    pub h1_re: Vec<f64>,
    pub h1_im: Vec<f64>,
    pub h1_mag_db: Vec<f64>,
    pub h1_phase_unwrapped: Vec<f64>,
}

pub(crate) fn welch_fixture() -> Fixture<WelchCase> {
    serde_json::from_str(WELCH_JSON).expect("welch_cases.json parses")
}

pub(crate) fn cross_fixture() -> Fixture<CrossCase> {
    serde_json::from_str(CROSS_JSON).expect("cross_cases.json parses")
}

/// Asserts `|a − e| <= tol · max |e|` element-wise (relative to the largest
/// expected magnitude, so near-zero bins do not dominate); NaN fails.
pub(crate) fn assert_rel_close(actual: &[f64], expected: &[f64], tol: f64, what: &str) {
    assert_eq!(actual.len(), expected.len(), "{what}: length");
    let scale = expected.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for (k, (a, e)) in actual.iter().zip(expected).enumerate() {
        let err = (a - e).abs();
        assert!(
            err <= tol * scale,
            "{what}[{k}]: {a} vs {e}, error {err:e} > {tol:e} x scale {scale:e}"
        );
    }
}

/// SplitMix64 pseudo-random generator with Box–Muller standard normals;
/// deterministic and dependency-free.
pub(crate) struct Gaussian {
    state: u64,
    spare: Option<f64>,
}

impl Gaussian {
    pub fn new(seed: u64) -> Self {
        Gaussian {
            state: seed,
            spare: None,
        }
    }

    fn next_u64(&mut self) -> u64 {
        let out = crate::rng::mix(self.state);
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        out
    }

    /// Uniform on (0, 1].
    fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 1.0) / (1u64 << 53) as f64
    }

    /// One standard normal sample.
    pub fn sample(&mut self) -> f64 {
        if let Some(s) = self.spare.take() {
            return s;
        }
        let r = (-2.0 * self.uniform().ln()).sqrt();
        let theta = 2.0 * std::f64::consts::PI * self.uniform();
        self.spare = Some(r * theta.sin());
        r * theta.cos()
    }

    /// `n` samples of N(0, sigma²).
    pub fn vec(&mut self, n: usize, sigma: f64) -> Vec<f64> {
        (0..n).map(|_| sigma * self.sample()).collect()
    }
}

pub(crate) fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

pub(crate) fn variance(v: &[f64]) -> f64 {
    let m = mean(v);
    v.iter().map(|s| (s - m) * (s - m)).sum::<f64>() / v.len() as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gaussian_generator_has_unit_moments() {
        let mut g = Gaussian::new(1);
        let v = g.vec(200_000, 1.0);
        assert!(mean(&v).abs() < 0.01);
        assert!((variance(&v) - 1.0).abs() < 0.01);
        let kurt = v.iter().map(|s| s.powi(4)).sum::<f64>() / v.len() as f64;
        assert!((kurt - 3.0).abs() < 0.05, "kurtosis {kurt}");
        // deterministic
        assert_eq!(Gaussian::new(7).vec(5, 1.0), Gaussian::new(7).vec(5, 1.0));
    }

    #[test]
    fn fixtures_parse_and_reference_known_signals() {
        let w = welch_fixture();
        assert!(!w.cases.is_empty());
        for c in &w.cases {
            assert!(w.signals.contains_key(&c.x), "{}", c.params.name);
        }
        let c = cross_fixture();
        assert!(!c.cases.is_empty());
        for case in &c.cases {
            assert!(c.signals.contains_key(&case.x) && c.signals.contains_key(&case.y));
        }
    }
}
