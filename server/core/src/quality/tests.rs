//! Tests of the quality report against known truth: deterministic seeded
//! signals whose spectra, coherence, frequency response, rank, excitation
//! and plan lag are known in closed form.

#![allow(clippy::single_range_in_vec_init)] // vectors of blocks

use std::f64::consts::PI;

use super::*;
use crate::planning::Dof;
use crate::spectra::{Complex, WelchConfig, coherence, csd, multi_welch, tfestimate_h1, welch};
use crate::timeseries::UniformRecord;

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

// ---------------------------------------------------------------------------
// Spectra against the spectra module and against theory
// ---------------------------------------------------------------------------

/// The report's spectra are the spectra module's on the same data:
/// PSDs as `welch`, |CSD| as `csd`, coherence as `coherence`, H1 as
/// `tfestimate_h1`, for every input × output pair. Long enough that the
/// Welch estimate is split in two parts, added in the pairs' own pass.
#[test]
fn report_spectra_equal_the_spectra_functions() {
    let mut rng = Rng::new(1);
    let n = 40_000;
    let x1 = rng.white(n, 3.0);
    let x2 = rng.binary(n, 4, 1.0);
    let y1 = add_noise(&first_order(&x1, 0.8, 0.5), &mut rng, 0.3);
    let y2: Vec<f64> = first_order(&x2, 0.5, -2.0)
        .iter()
        .zip(&x1)
        .map(|(a, b)| a + 0.1 * b + 7.0)
        .collect();
    let cols = vec![
        ("x1", x1.clone()),
        ("x2", x2.clone()),
        ("y1", y1.clone()),
        ("y2", y2.clone()),
    ];
    let rec = record(4.0, cols);
    let mut spec = QualitySpec::new(names(&["x1", "x2"]), names(&["y1", "y2"]));
    spec.nperseg = Some(256);
    let r = quality_report(&rec, &spec).unwrap();
    let cfg = WelchConfig::hann(4.0, 256);
    assert_eq!(r.welch.nperseg, 256);
    assert_eq!(r.welch.noverlap, 128);
    assert_eq!(r.welch.n_segments, cfg.n_segments(n));
    assert_eq!(r.freqs_hz, cfg.frequencies());
    for (q, x) in r.inputs.iter().zip([&x1, &x2]) {
        assert_close(&q.psd, &welch(x, &cfg).unwrap().values, 1e-12, "input psd");
    }
    for (q, y) in r.outputs.iter().zip([&y1, &y2]) {
        assert_close(&q.psd, &welch(y, &cfg).unwrap().values, 1e-12, "output psd");
    }
    assert_eq!(r.pairs.len(), 4);
    let ins = [&x1, &x2];
    let outs = [&y1, &y2];
    for (p, pair) in r.pairs.iter().enumerate() {
        let (x, y) = (ins[p / 2], outs[p % 2]);
        assert_eq!(pair.input, ["x1", "x2"][p / 2]);
        assert_eq!(pair.output, ["y1", "y2"][p % 2]);
        let c: Vec<f64> = csd(x, y, &cfg)
            .unwrap()
            .values
            .iter()
            .map(|v| v.norm())
            .collect();
        assert_close(&pair.csd_magnitude, &c, 1e-12, "|csd|");
        let coh = coherence(x, y, &cfg).unwrap().values;
        assert_close(&pair.coherence, &coh, 1e-12, "coherence");
        let h = tfestimate_h1(x, y, &cfg).unwrap();
        assert_close(&pair.h1_magnitude, &h.magnitude(), 1e-12, "|H1|");
        assert_close(&pair.h1_magnitude_db, &h.magnitude_db(), 1e-12, "dB");
        assert_close(
            &pair.h1_phase_unwrapped_rad,
            &h.phase_unwrapped(),
            1e-12,
            "phase",
        );
    }
}

/// y = b/(1 − a z⁻¹) x + n with white x and n: coherence follows
/// |H|²σx² / (|H|²σx² + σn²) and H1 follows H, within the estimator's
/// statistical spread (Bendat & Piersol: σ(γ²) ≈ √2 γ(1 − γ²)/√K,
/// σ(|H1|)/|H| ≈ √((1 − γ²)/(2Kγ²))), 5 σ plus 0.01 for bias.
#[test]
fn first_order_system_matches_theory() {
    let (a, b, sx, sn, fs) = (0.8, 0.5, 1.0, 0.7, 2.0);
    let mut rng = Rng::new(1234);
    let n = 1 << 17;
    let x = rng.white(n, sx);
    let y = add_noise(&first_order(&x, a, b), &mut rng, sn);
    let rec = record(fs, vec![("x", x), ("y", y)]);
    let mut spec = QualitySpec::new(names(&["x"]), names(&["y"]));
    spec.nperseg = Some(512);
    let r = quality_report(&rec, &spec).unwrap();
    let k = r.welch.n_segments as f64;
    let pair = &r.pairs[0];
    // Bins 0 and 1 are skipped: the per-segment mean removal biases them.
    for i in 2..r.freqs_hz.len() {
        let w = 2.0 * PI * r.freqs_hz[i] / fs;
        let h = Complex::new(b, 0.0) / (Complex::new(1.0, 0.0) - a * Complex::from_polar(1.0, -w));
        let h2 = h.norm_sqr();
        let g2 = h2 * sx * sx / (h2 * sx * sx + sn * sn);
        let tol = 5.0 * 2f64.sqrt() * g2.sqrt() * (1.0 - g2) / k.sqrt() + 0.01;
        let c = pair.coherence[i];
        assert!((c - g2).abs() < tol, "f {}: γ² {c} vs {g2}", r.freqs_hz[i]);
        let rel = 5.0 * ((1.0 - g2) / (2.0 * k * g2)).sqrt() + 0.01;
        let mag = pair.h1_magnitude[i];
        assert!(
            (mag / h.norm() - 1.0).abs() < rel,
            "f {}: |H1| {mag} vs {}",
            r.freqs_hz[i],
            h.norm()
        );
        let dphase = pair.h1_phase_unwrapped_rad[i] - h.arg();
        let wrapped = (dphase + PI).rem_euclid(2.0 * PI) - PI;
        assert!(
            wrapped.abs() < rel,
            "f {}: phase off by {dphase}",
            r.freqs_hz[i]
        );
        assert!((pair.h1_magnitude_db[i] - 20.0 * mag.log10()).abs() < 1e-12);
    }
}

/// Gaps: samples outside the valid blocks (NaN here) are never read, and
/// the spectra average the segments of every block.
#[test]
fn spectra_use_valid_blocks_only() {
    let mut rec = sway_log(5000, 1e-4, 3);
    for c in &mut rec.data {
        c[2000..2300].iter_mut().for_each(|v| *v = f64::NAN);
    }
    rec.valid = vec![0..2000, 2300..5000];
    let mut spec = sway_spec();
    spec.nperseg = Some(512);
    let r = quality_report(&rec, &spec).unwrap();
    let cfg = WelchConfig::hann(10.0, 512);
    let ms = multi_welch(&[&rec.data[0], &rec.data[1]], &rec.valid, &[(0, 1)], &cfg).unwrap();
    assert_eq!(
        r.welch.n_segments,
        cfg.n_segments(2000) + cfg.n_segments(2700)
    );
    assert_close(&r.inputs[0].psd, &ms.auto[0], 1e-12, "psd");
    assert_close(&r.pairs[0].coherence, &ms.coherence(0), 1e-12, "coherence");
    assert_eq!(r.n_valid_samples, 4700);
    assert!((r.valid_duration_s - 470.0).abs() < 1e-9);
    assert!(r.inputs[0].mean.is_finite() && r.outputs[0].rms.is_finite());
}

// ---------------------------------------------------------------------------
// Verdicts
// ---------------------------------------------------------------------------

/// A PRBS-like force through a first-order lag, measured with little
/// noise: Good, and the reason says so with its numbers.
#[test]
fn well_excited_first_order_dof_is_good() {
    let rec = sway_log(36_000, 1e-4, 7);
    let r = quality_report(&rec, &sway_spec()).unwrap();
    let d = &r.dofs[0];
    assert_eq!(d.verdict, Verdict::Good, "{}", d.reason);
    assert!(
        d.reason.starts_with("sway: good — coherence ≥ 0.8 over "),
        "{}",
        d.reason
    );
    assert!(d.reason.contains("PE order ≥ 24"), "{}", d.reason);
    assert_eq!(d.evidence.pe_order, PE_CAP);
    assert!(d.evidence.median_coherence.unwrap() > 0.9);
    assert!(!d.evidence.nyquist_warning);
    // With so little noise a first-order DOF makes v(t-1), v(t-2) and
    // tau_Y(t-1) nearly dependent (na = 2 is one more than it needs): a
    // direction on the output lags, not held against the log.
    assert!(!d.evidence.input_deficient);
    assert!(
        r.regressor
            .deficient_directions
            .iter()
            .all(|dd| dd.input_share < MIN_INPUT_SHARE)
    );
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
    // Default nperseg: the rule of `default_quality_nperseg`.
    assert_eq!(r.welch.nperseg, default_quality_nperseg(36_000));
    assert_eq!(r.welch.nperseg, 4096);
}

/// A force that never moved: Insufficient, and the reason names the DOF,
/// the input, the evidence and the action.
#[test]
fn constant_input_is_insufficient_and_named() {
    let mut rng = Rng::new(9);
    let n = 6000;
    let x = vec![5000.0; n];
    let y = rng.white(n, 0.01);
    let rec = record(10.0, vec![("tau_Y", x), ("v", y)]);
    // Two lags, so each dead channel removes one direction per lag.
    let mut spec = sway_spec();
    spec.regressor_lags = 2;
    let r = quality_report(&rec, &spec).unwrap();
    let d = &r.dofs[0];
    assert_eq!(d.verdict, Verdict::Insufficient);
    assert!(
        d.reason
            .starts_with("sway: the input tau_Y barely moved (PE order 0, mean 5000, RMS 0)"),
        "{}",
        d.reason
    );
    assert!(
        d.reason.contains("holds no dynamic information"),
        "{}",
        d.reason
    );
    // No plan: nothing to repeat, and not exciting a DOF is no failure of the run.
    assert!(
        d.reason.contains("fly a run that excites it") && !d.reason.contains("planned schedule"),
        "{}",
        d.reason
    );
    assert!(r.inputs[0].pe_order < MIN_PE_ORDER);
    assert_eq!(r.inputs[0].rms, 0.0);
    assert_eq!(r.inputs[0].mean, 5000.0);
    // Its regressor columns are dead: two directions of the full model.
    assert_eq!(r.regressor.identifiable, 2);
    assert!(
        r.regressor
            .deficient_directions
            .iter()
            .all(|d| d.columns.iter().all(|c| c.column.starts_with("tau_Y(t-"))),
        "{:?}",
        r.regressor.deficient_directions
    );
}

/// The same DOF drowned in output noise: coherence decides, not Good.
#[test]
fn heavy_output_noise_is_insufficient_by_coherence() {
    let rec = sway_log(36_000, 0.05, 11);
    let r = quality_report(&rec, &sway_spec()).unwrap();
    let d = &r.dofs[0];
    assert_eq!(d.verdict, Verdict::Insufficient, "{}", d.reason);
    assert!(d.evidence.median_coherence.unwrap() < MIN_MEDIAN_COHERENCE);
    assert!(
        d.reason.starts_with("sway: median coherence "),
        "{}",
        d.reason
    );
    assert!(d.reason.contains("from tau_Y to v"), "{}", d.reason);
    assert!(
        d.reason
            .contains("fly it again with twice the amplitude or a slower PRBS clock"),
        "{}",
        d.reason
    );
}

/// Moderate noise on a strongly low-passed output: coherence ≥ 0.5 over
/// most of the input's band but ≥ 0.8 only at low frequency — Weak, and
/// the reason says where coherence falls short.
#[test]
fn coherence_good_over_part_of_the_band_is_weak() {
    let mut rng = Rng::new(21);
    let n = 36_000;
    let x = rng.binary(n, 2, 1.0);
    // |H| falls 26 dB over the input's band (0–4 Hz).
    let y = add_noise(&first_order(&x, 0.95, 0.05), &mut rng, 0.04);
    let rec = record(10.0, vec![("tau_Y", x), ("v", y)]);
    let r = quality_report(&rec, &sway_spec()).unwrap();
    let d = &r.dofs[0];
    let frac = d.evidence.coherent_fraction.unwrap();
    assert!(frac < MIN_COHERENT_FRACTION, "{frac}");
    assert!(
        d.evidence.median_coherence.unwrap() >= MIN_MEDIAN_COHERENCE,
        "{}",
        d.reason
    );
    assert_eq!(d.verdict, Verdict::Weak, "{}", d.reason);
    assert!(
        d.reason.starts_with("sway: coherence ≥ 0.8 over only "),
        "{}",
        d.reason
    );
    assert!(
        d.reason.contains("(coherence below 0.8 above "),
        "{}",
        d.reason
    );
    assert!(!d.evidence.nyquist_warning);
}

/// A record too short for two Welch segments cannot show coherence.
#[test]
fn fewer_than_two_segments_is_insufficient() {
    let rec = sway_log(80, 1e-4, 5);
    let r = quality_report(&rec, &sway_spec()).unwrap();
    assert_eq!(r.welch.n_segments, 1);
    let d = &r.dofs[0];
    assert_eq!(d.verdict, Verdict::Insufficient, "{}", d.reason);
    assert!(d.reason.contains("1 Welch segment(s)"), "{}", d.reason);
    assert!(d.reason.contains("log at least 9.6 s"), "{}", d.reason);
}

// ---------------------------------------------------------------------------
// Regressor
// ---------------------------------------------------------------------------

fn two_by_two(n: usize, seed: u64) -> (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
    let mut rng = Rng::new(seed);
    let x1 = rng.binary(n, 3, 1.0);
    let x2 = rng.white(n, 2.0);
    let y1 = add_noise(&first_order(&x1, 0.9, 0.3), &mut rng, 0.05);
    let y2 = add_noise(&first_order(&x2, 0.7, -0.4), &mut rng, 0.05);
    (x1, x2, y1, y2)
}

/// Two independent inputs and their outputs: full rank. A third input
/// that is an affine copy of the first (collinear about the mean) drops
/// the identifiable count by exactly one per lag, and the deficient
/// direction names the two columns.
#[test]
fn collinear_input_drops_identifiable_count_by_one_per_lag() {
    let (x1, x2, y1, y2) = two_by_two(20_000, 4);
    let x3: Vec<f64> = x1.iter().map(|v| 3.0 - 2.0 * v).collect();
    let all = [0..20_000];
    let r =
        regressor_analysis(&["y1", "y2", "x1", "x2"], &[&y1, &y2, &x1, &x2], 2, &all, 1).unwrap();
    assert_eq!((r.identifiable, r.n_columns), (4, 4));
    assert!(r.deficient_directions.is_empty());
    assert!((r.singular_values[0] - 1.0).abs() < 1e-15);
    assert!(r.singular_values.windows(2).all(|w| w[0] >= w[1]));

    let r = regressor_analysis(
        &["y1", "y2", "x1", "x2", "x3"],
        &[&y1, &y2, &x1, &x2, &x3],
        2,
        &all,
        1,
    )
    .unwrap();
    assert_eq!((r.identifiable, r.n_columns), (4, 5));
    assert_eq!(r.deficient_directions.len(), 1);
    let g = &r.deficient_directions[0];
    let cols: Vec<&str> = g.columns.iter().map(|c| c.column.as_str()).collect();
    assert_eq!(cols, ["x1(t-1)", "x3(t-1)"]);
    // Unit-RMS columns z1 = −z3: each lies half in the null direction.
    assert!(g.columns.iter().all(|c| (c.weight - 0.5).abs() < 1e-9));
    assert_eq!(g.dimension, 1);
    assert!(g.singular_value < 1e-6);
    assert!((g.input_share - 1.0).abs() < 1e-9);

    // With na = nb = 2 every lag of the copy is collinear: two fewer.
    let r = regressor_analysis(
        &["y1", "y2", "x1", "x2", "x3"],
        &[&y1, &y2, &x1, &x2, &x3],
        2,
        &all,
        2,
    )
    .unwrap();
    assert_eq!((r.identifiable, r.n_columns), (8, 10));
    // One group per lag, whatever rotation the eigen-solver picked within
    // the two-dimensional null space.
    let groups: Vec<Vec<&str>> = r
        .deficient_directions
        .iter()
        .map(|g| g.columns.iter().map(|c| c.column.as_str()).collect())
        .collect();
    assert_eq!(groups, [["x1(t-1)", "x3(t-1)"], ["x1(t-2)", "x3(t-2)"]]);
    assert_eq!(r.columns[0], "y1(t-1)");
    assert_eq!(r.columns[9], "x3(t-2)");
    assert_eq!(r.threshold, SINGULAR_VALUE_THRESHOLD);
}

/// Sway and yaw excited by one and the same signal: the full regressor is
/// deficient and both DOFs are Weak with the collinear columns named.
#[test]
fn same_signal_on_two_dofs_makes_both_weak() {
    let mut rng = Rng::new(8);
    let n = 20_000;
    let x = rng.binary(n, 5, 1.0);
    let v = add_noise(&first_order(&x, 0.9, 0.2), &mut rng, 0.01);
    let rr = add_noise(&first_order(&x, 0.8, 0.1), &mut rng, 0.01);
    let tau_n: Vec<f64> = x.iter().map(|s| 0.5 * s).collect();
    let rec = record(
        10.0,
        vec![("tau_Y", x), ("tau_N", tau_n), ("v", v), ("r", rr)],
    );
    let spec = QualitySpec::new(names(&["tau_Y", "tau_N"]), names(&["v", "r"]))
        .with_dof(Dof::Sway, "tau_Y", "v")
        .with_dof(Dof::Yaw, "tau_N", "r");
    let mut spec = spec;
    spec.regressor_lags = 2; // one collinear direction per lag
    let rep = quality_report(&rec, &spec).unwrap();
    assert_eq!(rep.regressor.n_columns - rep.regressor.identifiable, 2);
    for d in &rep.dofs {
        assert_eq!(d.verdict, Verdict::Weak, "{}", d.reason);
        assert!(d.evidence.input_deficient);
        let pair = if d.dof == Dof::Sway {
            "tau_Y and tau_N"
        } else {
            "tau_N and tau_Y"
        };
        assert!(
            d.reason.contains(&format!("{pair} move together")),
            "{}",
            d.reason
        );
        assert!(d.reason.contains("own independent signal"), "{}", d.reason);
    }
    assert!(
        rep.warnings
            .iter()
            .any(|w| w.contains("determines 6 of its 8 parameters")),
        "{:?}",
        rep.warnings
    );
}

// ---------------------------------------------------------------------------
// Nyquist
// ---------------------------------------------------------------------------

/// A command alternating every log sample (a 20 Hz controller seen at
/// 10 Hz) warns; a slow PRBS does not.
#[test]
fn nyquist_warning_fires_for_alternating_input_only() {
    let n = 4000;
    let mut rng = Rng::new(2);
    let alt: Vec<f64> = (0..n)
        .map(|k| if k % 2 == 0 { 1.0 } else { -1.0 } + 0.3 * rng.normal())
        .collect();
    let slow = rng.binary(n, 20, 1.0);
    let v = add_noise(&first_order(&slow, 0.9, 0.1), &mut rng, 0.01);
    let rec = record(10.0, vec![("tau_K", alt), ("tau_Y", slow), ("v", v)]);
    let mut spec = QualitySpec::new(names(&["tau_K", "tau_Y"]), names(&["v"]))
        .with_dof(Dof::Sway, "tau_Y", "v")
        .with_dof(Dof::Roll, "tau_K", "v");
    let r = quality_report(&rec, &spec).unwrap();
    let k = &r.inputs[0];
    assert!(
        k.nyquist.power_fraction > 0.5,
        "{}",
        k.nyquist.power_fraction
    );
    assert_eq!(k.nyquist.band_hz, [4.0, 5.0]);
    let w = k.nyquist.warning.as_deref().unwrap();
    assert!(
        w.starts_with("tau_K has power near the 5 Hz Nyquist frequency of the log"),
        "{w}"
    );
    assert!(w.contains("e.g. a 20 Hz controller logged at 10 Hz"), "{w}");
    assert!(w.contains("inputs between samples are unknown"), "{w}");
    let y = &r.inputs[1];
    assert!(
        y.nyquist.power_fraction < 0.01,
        "{}",
        y.nyquist.power_fraction
    );
    assert!(y.nyquist.warning.is_none());
    assert!(r.warnings.iter().any(|s| s.starts_with("tau_K has power")));
    let roll = &r.dofs[1];
    assert!(roll.evidence.nyquist_warning);
    assert_ne!(roll.verdict, Verdict::Good);
    assert!(
        roll.reason
            .contains("log the inputs at the controller rate"),
        "{}",
        roll.reason
    );

    // A known controller rate is quoted.
    spec.controller_rate_hz = Some(20.0);
    let r = quality_report(&rec, &spec).unwrap();
    let w = r.inputs[0].nyquist.warning.as_deref().unwrap();
    assert!(w.contains("the controller ran at 20 Hz"), "{w}");
}

/// White noise at the log rate has 20 % of its power in the top 20 % of the
/// band: it warns too (nothing says it did not change between samples),
/// so such a DOF is at best Weak.
#[test]
fn white_input_at_the_log_rate_warns() {
    let mut rng = Rng::new(17);
    let x = rng.white(36_000, 1.0);
    let y = add_noise(&first_order(&x, 0.9, 0.1), &mut rng, 1e-3);
    let rec = record(10.0, vec![("tau_Y", x), ("v", y)]);
    let r = quality_report(&rec, &sway_spec()).unwrap();
    let f = r.inputs[0].nyquist.power_fraction;
    assert!((f - 0.2).abs() < 0.02, "{f}");
    assert_eq!(r.dofs[0].verdict, Verdict::Weak, "{}", r.dofs[0].reason);
}

// ---------------------------------------------------------------------------
// Plan adherence
// ---------------------------------------------------------------------------

/// The logged force is the schedule (planned at 20 Hz) started 57.3 s into
/// a 10 Hz log, through a slight lag and noise: the lag is found, and the
/// run is followed. Flown at half amplitude it is not, and the DOF is Weak.
#[test]
fn plan_adherence_finds_the_lag_and_flags_half_amplitude() {
    let mut rng = Rng::new(33);
    let plan_fs = 20.0;
    let plan = rng.binary(6000, 40, 1000.0); // 300 s, 2 s clock
    let plan_at = |t: f64| plan[((t * plan_fs).round() as usize).min(plan.len() - 1)];
    let n = 4000; // 400 s at 10 Hz
    let lag_s = 57.3;
    let logged = |gain: f64, rng: &mut Rng| -> Vec<f64> {
        let raw: Vec<f64> = (0..n)
            .map(|k| {
                let t = k as f64 / 10.0 - lag_s;
                if (0.0..300.0).contains(&t) {
                    gain * plan_at(t)
                } else {
                    0.0
                }
            })
            .collect();
        add_noise(&first_order(&raw, 0.3, 0.7), rng, 20.0)
    };
    for (gain, followed) in [(1.0, true), (0.5, false)] {
        let x = logged(gain, &mut rng);
        let v = add_noise(&first_order(&x, 0.95, 5e-6), &mut rng, 1e-4);
        let rec = record(10.0, vec![("tau_Y", x), ("v", v)]);
        let mut spec = sway_spec();
        spec.planned = Some(PlannedReference {
            sample_rate_hz: plan_fs,
            columns: vec![("tau_Y".into(), "sway_prbs".into(), plan.clone())],
        });
        let r = quality_report(&rec, &spec).unwrap();
        let a = &r.adherence[0];
        assert!((a.lag_s - lag_s).abs() <= 0.15, "lag {}", a.lag_s);
        assert!(a.correlation > 0.95, "r {}", a.correlation);
        assert!(
            (a.amplitude_ratio.unwrap() - gain).abs() < 0.05 * gain,
            "ratio {:?}",
            a.amplitude_ratio
        );
        assert!((a.coverage - 1.0).abs() < 1e-9, "coverage {}", a.coverage);
        assert_eq!(a.followed, followed, "{}", a.message);
        let d = &r.dofs[0];
        assert_eq!(d.evidence.plan_followed, Some(followed));
        if followed {
            assert!(a.nrmse.unwrap() < 0.3, "nrmse {:?}", a.nrmse);
            assert_eq!(d.verdict, Verdict::Good, "{}", d.reason);
        } else {
            assert!(a.message.contains("amplitude ratio 0.49"), "{}", a.message);
            assert!(a.message.contains("outside 0.7–1.3"), "{}", a.message);
            assert_eq!(d.verdict, Verdict::Weak, "{}", d.reason);
            assert!(
                d.reason.contains("did not follow the planned sway_prbs"),
                "{}",
                d.reason
            );
            assert!(r.warnings.iter().any(|w| w.contains("sway_prbs")));
        }
    }
}

/// A log that ends half-way through the schedule: coverage says so.
#[test]
fn plan_coverage_counts_the_logged_part() {
    let mut rng = Rng::new(44);
    let plan = rng.binary(3000, 20, 1.0); // 300 s at 10 Hz
    let n = 1500;
    let x: Vec<f64> = (0..n)
        .map(|k| if k >= 300 { plan[k - 300] } else { 0.0 })
        .collect();
    let v = add_noise(&first_order(&x, 0.9, 0.1), &mut rng, 1e-3);
    let rec = record(10.0, vec![("tau_Y", x), ("v", v)]);
    let mut spec = sway_spec();
    spec.planned = Some(PlannedReference {
        sample_rate_hz: 10.0,
        columns: vec![("tau_Y".into(), "p".into(), plan)],
    });
    let r = quality_report(&rec, &spec).unwrap();
    let a = &r.adherence[0];
    assert!((a.lag_s - 30.0).abs() < 1e-9, "{}", a.lag_s);
    assert!(
        (a.coverage - 1200.0 / 3000.0).abs() < 1e-9,
        "{}",
        a.coverage
    );
    assert!(a.correlation > 0.999);
    assert!(!a.followed);
    assert!(a.message.contains("coverage 40 % < 90 %"), "{}", a.message);
}

// ---------------------------------------------------------------------------
// Errors and serialization
// ---------------------------------------------------------------------------

#[test]
fn invalid_requests_are_errors_naming_the_field() {
    let rec = sway_log(2000, 1e-3, 1);
    let field = |rec: &UniformRecord, spec: &QualitySpec| {
        quality_report(rec, spec).unwrap_err().field().to_owned()
    };
    let mut s = sway_spec();
    s.inputs.push("tau_X".into());
    let e = quality_report(&rec, &s).unwrap_err();
    assert_eq!(e.field(), "inputs[1]");
    assert_eq!(e.message(), "column `tau_X` is not in the log");
    let s = QualitySpec::new(vec![], names(&["v"]));
    assert_eq!(field(&rec, &s), "inputs");
    let s = QualitySpec::new(names(&["tau_Y", "tau_Y"]), names(&["v"]));
    assert_eq!(field(&rec, &s), "inputs[1]");
    let s = sway_spec().with_dof(Dof::Yaw, "tau_N", "v");
    assert_eq!(field(&rec, &s), "dofs[1].input");
    let s = sway_spec().with_dof(Dof::Yaw, "tau_Y", "r");
    assert_eq!(field(&rec, &s), "dofs[1].output");
    let mut s = sway_spec();
    s.nperseg = Some(2001);
    assert_eq!(field(&rec, &s), "nperseg");
    s.nperseg = Some(0);
    assert_eq!(field(&rec, &s), "nperseg");
    let mut big = rec.clone();
    big.data[0] = vec![0.0; 2000];
    let mut s = QualitySpec::new(names(&["tau_Y"]), names(&["v"]));
    s.nperseg = Some(2000);
    assert!(quality_report(&big, &s).is_ok());
    s.planned = Some(PlannedReference {
        sample_rate_hz: 1e-3,
        columns: vec![("v".into(), "slow".into(), vec![1.0; 100])],
    });
    assert_eq!(field(&big, &s), "planned.columns[0]");
    let mut s = sway_spec();
    s.regressor_lags = 0;
    assert_eq!(field(&rec, &s), "regressor_lags");
    s.regressor_lags = 200;
    assert_eq!(field(&rec, &s), "regressor_lags");
    let mut s = sway_spec();
    s.controller_rate_hz = Some(-1.0);
    assert_eq!(field(&rec, &s), "controller_rate_hz");
    let mut s = sway_spec();
    s.planned = Some(PlannedReference {
        sample_rate_hz: 0.0,
        columns: vec![],
    });
    assert_eq!(field(&rec, &s), "planned.sample_rate_hz");
    s.planned = Some(PlannedReference {
        sample_rate_hz: 1.0,
        columns: vec![("w".into(), "p".into(), vec![1.0, 2.0])],
    });
    assert_eq!(field(&rec, &s), "planned.columns[0]");
    s.planned = Some(PlannedReference {
        sample_rate_hz: 1.0,
        columns: vec![("v".into(), "p".into(), vec![1.0])],
    });
    assert_eq!(field(&rec, &s), "planned.columns[0]");

    let mut bad = rec.clone();
    bad.data[1][1234] = f64::NAN;
    match quality_report(&bad, &sway_spec()).unwrap_err() {
        QualityError::NonFinite { field, index, .. } => {
            assert_eq!((field.as_str(), index), ("v", 1234))
        }
        e => panic!("{e:?}"),
    }
    // Outside the valid blocks a NaN is fine.
    bad.valid = vec![0..1234, 1235..2000];
    assert!(quality_report(&bad, &sway_spec()).is_ok());

    let mut r2 = rec.clone();
    r2.sample_rate_hz = f64::NAN;
    assert_eq!(field(&r2, &sway_spec()), "sample_rate_hz");
    let mut r2 = rec.clone();
    r2.valid = vec![];
    assert_eq!(field(&r2, &sway_spec()), "valid");
    r2.valid = vec![0..10, 5..20];
    assert_eq!(field(&r2, &sway_spec()), "valid[1]");
    r2.valid = vec![0..2001];
    assert_eq!(field(&r2, &sway_spec()), "valid[0]");
    let mut r2 = rec.clone();
    r2.data[1].pop();
    assert_eq!(field(&r2, &sway_spec()), "data[1]");
    let e = quality_report(&r2, &sway_spec()).unwrap_err();
    assert!(e.to_string().starts_with("data[1]: "), "{e}");
}

#[test]
fn report_serializes_in_snake_case() {
    let rec = sway_log(3000, 1e-4, 2);
    let r = quality_report(&rec, &sway_spec()).unwrap();
    let v = serde_json::to_value(&r).unwrap();
    for key in [
        "sample_rate_hz",
        "freqs_hz",
        "inputs",
        "outputs",
        "pairs",
        "regressor",
        "adherence",
        "dofs",
        "warnings",
        "welch",
    ] {
        assert!(v.get(key).is_some(), "{key}");
    }
    assert_eq!(v["dofs"][0]["dof"], "sway");
    assert_eq!(v["dofs"][0]["verdict"], "good");
    assert!(v["pairs"][0]["h1_phase_unwrapped_rad"].is_array());
    assert!(v["inputs"][0]["nyquist"]["power_fraction"].is_number());
    assert!(v["regressor"]["singular_values"].is_array());
    let spec: QualitySpec = serde_json::from_str(
        r#"{"inputs":["tau_Y"],"outputs":["v"],"dofs":[{"dof":"sway","input":"tau_Y","output":"v"}]}"#,
    )
    .unwrap();
    assert_eq!(spec, sway_spec());
}

/// Unit doubts replace every verdict by `check_units` naming them, keep the
/// evidence; no doubts leave the verdicts as computed.
#[test]
fn unit_doubts_replace_every_verdict_and_none_leave_them() {
    let report = quality_report(&sway_log(6000, 0.01, 3), &sway_spec()).unwrap();
    let mut v = report.dofs.clone();
    units_first(&mut v, &[]);
    assert_eq!(v, report.dofs);
    assert_eq!(v[0].verdict, Verdict::Good, "{}", v[0].reason);
    units_first(
        &mut v,
        &["t looks like milliseconds", "phi looks like degrees"],
    );
    for (after, before) in v.iter().zip(&report.dofs) {
        assert_eq!(after.verdict, Verdict::CheckUnits);
        assert!(
            after
                .reason
                .starts_with("sway: check the log's units first"),
            "{}",
            after.reason
        );
        assert!(
            after
                .reason
                .contains("milliseconds; phi looks like degrees")
        );
        assert_eq!(after.evidence, before.evidence);
    }
}
