//! Spectra against the spectra module and against theory.

use super::*;

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
