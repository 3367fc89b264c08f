//! The residual tests of [`super::residuals`] against their white-noise
//! laws and closed-form cases.

use super::ValidationError;
use super::correlation::autocorrelation;
use super::residuals::*;
use crate::rng::SplitMix64;

fn white(seed: u64, n: usize) -> Vec<f64> {
    let mut rng = SplitMix64::new(seed);
    (0..n).map(|_| rng.normal()).collect()
}

fn ar1(seed: u64, n: usize, phi: f64) -> Vec<f64> {
    let w = white(seed, n + 200);
    let mut x = 0.0;
    let mut out = Vec::with_capacity(n);
    for (t, v) in w.iter().enumerate() {
        x = phi * x + v;
        if t >= 200 {
            out.push(x);
        }
    }
    out
}

#[test]
fn white_noise_passes_at_the_nominal_rate() {
    let s = ResidualSettings::default();
    let (runs, n) = (300, 2000);
    let (mut lb_reject, mut zc_reject, mut jb_reject, mut offset_reject) = (0, 0, 0, 0);
    let (mut outside, mut tested) = (0usize, 0usize);
    let mut p_sum = 0.0;
    for seed in 0..runs {
        let e = white(1000 + seed, n);
        let a = analyze_residuals(&e, &s, "residual").unwrap();
        lb_reject += usize::from(!a.white);
        zc_reject += usize::from(a.zero_crossings.p_value < 0.01);
        jb_reject += usize::from(a.normality.p_value < 0.01);
        offset_reject += usize::from(a.offset.significant);
        outside += a.autocorrelation.lags_outside.len();
        tested += s.max_lag;
        p_sum += a.whiteness_p_value;
    }
    // Each test rejects a white sequence ~1 % of the time: Bin(300, 0.01)
    // has mean 3, and P(X ≥ 11) < 1e-4.
    for (name, k) in [
        ("Ljung–Box", lb_reject),
        ("zero crossings", zc_reject),
        ("Jarque–Bera", jb_reject),
        ("offset", offset_reject),
    ] {
        assert!(k <= 10, "{name} rejected white noise {k}/{runs} times");
    }
    // Lags outside ±2.576/√N: 1 % of 15 000 lags = 150 (sd ≈ 12).
    let rate = outside as f64 / tested as f64;
    assert!((0.006..0.014).contains(&rate), "rate outside bounds {rate}");
    // p-values are uniform under the null: mean ½ (sd 0.017 here).
    assert!((p_sum / runs as f64 - 0.5).abs() < 0.07);
}

#[test]
fn ar1_with_phi_0_8_fails_clearly() {
    let (n, phi) = (2000, 0.8);
    let e = ar1(5, n, phi);
    let a = analyze_residuals(&e, &ResidualSettings::default(), "residual").unwrap();
    assert!(!a.white);
    assert!(a.whiteness_p_value < 1e-100);
    // r(k) ≈ φ^k.
    for k in 1..5 {
        assert!((a.autocorrelation.values[k] - phi.powi(k as i32)).abs() < 0.06);
    }
    assert_eq!(&a.autocorrelation.lags_outside[..5], &[1, 2, 3, 4, 5]);
    // Gaussian AR(1): P(sign change) = arccos(φ)/π (orthant probability).
    let zc = &a.zero_crossings;
    let p = phi.acos() / std::f64::consts::PI;
    let want = (n - 1) as f64 * p;
    assert!(
        (zc.count as f64 - want).abs() < 5.0 * want.sqrt(),
        "{} vs {want}",
        zc.count
    );
    assert!(zc.z < -20.0 && zc.p_value < 1e-50);
}

#[test]
fn zero_crossings_of_a_known_sequence() {
    // Signs + − + (0 skipped) − + +: four changes among six signed samples.
    let zc = zero_crossings(&[1.0, -1.0, 2.0, 0.0, -3.0, 4.0, 4.0]);
    assert_eq!(zc.count, 4);
    assert_eq!(zc.expected, 2.5);
    assert!((zc.std - 5f64.sqrt() / 2.0).abs() < 1e-15);
    // An offset residual never crosses.
    let zc = zero_crossings(&vec![0.5; 100]);
    assert_eq!(zc.count, 0);
    assert!(zc.p_value < 1e-20);
}

#[test]
fn ljung_box_of_a_known_autocorrelation() {
    // r = [1, 0.2, −0.1], N = 100: Q = 100·102·(0.04/99 + 0.01/98).
    let lb = ljung_box(&[1.0, 0.2, -0.1], 100);
    let q = 100.0 * 102.0 * (0.04 / 99.0 + 0.01 / 98.0);
    assert!((lb.statistic - q).abs() < 1e-12);
    assert_eq!(lb.dof, 2);
    assert!((lb.p_value - (-q / 2.0).exp()).abs() < 1e-14);
}

#[test]
fn k_step_errors_are_judged_beyond_their_ma_order() {
    // e = MA(4) of white noise: correlated up to lag 4 by construction,
    // white beyond — what a correct model's 5-step errors look like.
    let mut passed = 0;
    for seed in 0..50 {
        let w = white(77 + seed, 3004);
        let e: Vec<f64> = (4..3004).map(|t| w[t - 4..=t].iter().sum()).collect();
        let s = ResidualSettings {
            ma_order: 4,
            ..Default::default()
        };
        let a = analyze_residuals(&e, &s, "residual").unwrap();
        assert!(a.ljung_box.is_none());
        assert!(a.autocorrelation.values[1] > 0.7);
        passed += usize::from(a.white);
        // Against white-noise bounds the same sequence fails.
        let plain = analyze_residuals(&e, &ResidualSettings::default(), "residual").unwrap();
        assert!(!plain.white);
    }
    assert!(
        passed >= 46,
        "{passed}/50 MA(4) sequences passed beyond lag 4"
    );
}

#[test]
fn normality_measures_separate_normal_from_uniform() {
    let mut rng = SplitMix64::new(9);
    let g: Vec<f64> = (0..4000).map(|_| 2.0 + 3.0 * rng.normal()).collect();
    let nm = normality(&g, None, 100);
    assert!(nm.p_value > 0.01 && nm.plot_correlation.unwrap() > 0.998);
    assert!(nm.plot.theoretical_quantiles.len() == 100);
    // The probability plot of N(2, 3²) is the line 2 + 3q.
    let (q, y) = (&nm.plot.theoretical_quantiles, &nm.plot.sorted_residuals);
    let mid = q.len() / 2;
    let slope = (y[mid + 30] - y[mid - 30]) / (q[mid + 30] - q[mid - 30]);
    assert!((slope - 3.0).abs() < 0.3 && (y[mid] - 2.0).abs() < 0.2);
    // Uniform: excess kurtosis −1.2, JB ≈ N/6·0.36 = 240.
    let u: Vec<f64> = (0..4000).map(|_| rng.uniform()).collect();
    let nu = normality(&u, None, 100);
    assert!((nu.excess_kurtosis + 1.2).abs() < 0.1);
    assert!(nu.p_value < 1e-20 && nu.plot_correlation.unwrap() < 0.99);
}

#[test]
fn normality_of_a_correlated_gaussian_is_not_rejected() {
    // AR(1), φ = 0.8: Σρ³ = 1 + 2·0.512/0.488 ≈ 3.1, so the plain JB
    // over-rejects (≈ 18 %); the corrected one keeps ≈ 1 %.
    let (mut plain, mut corrected) = (0, 0);
    for seed in 0..100 {
        let e = ar1(500 + seed, 2000, 0.8);
        let r = autocorrelation(&e, 50).unwrap();
        plain += usize::from(normality(&e, None, 10).p_value < 0.01);
        corrected += usize::from(normality(&e, Some(&r), 10).p_value < 0.01);
    }
    assert!(plain >= 8, "plain JB rejected {plain}/100");
    assert!(corrected <= 5, "corrected JB rejected {corrected}/100");
}

#[test]
fn an_input_leaking_into_the_residual_is_found_at_its_lag() {
    let n = 3000;
    let u = white(21, n);
    let w = white(22, n);
    // Residual carries 0.3·u(t − 2): a missing coupling with a delay.
    let e: Vec<f64> = (0..n)
        .map(|t| w[t] + if t >= 2 { 0.3 * u[t - 2] } else { 0.0 })
        .collect();
    let c = input_residual_correlation(&e, &u, "u_3", 20, 0.99).unwrap();
    assert!(c.leak && !c.feedback);
    assert_eq!(c.peak_lag, 2);
    assert!((c.peak_value - 0.3 / 1.09f64.sqrt()).abs() < 0.05);
    assert!(c.lags_outside.contains(&2));
    // Feedback: the input follows the residual three samples later.
    let v = white(24, n);
    let u_fb: Vec<f64> = (0..n)
        .map(|t| v[t] + if t >= 3 { 0.5 * e[t - 3] } else { 0.0 })
        .collect();
    let f = input_residual_correlation(&e, &u_fb, "u_1", 20, 0.99).unwrap();
    assert!(f.feedback && !f.leak, "{f:?}");
    assert!(f.lags_outside.contains(&-3));
    // Unrelated input: no leak.
    let clean = input_residual_correlation(&w, &white(23, n), "u_2", 20, 0.99).unwrap();
    assert!(!clean.leak && !clean.feedback);
}

#[test]
fn cross_correlation_bound_widens_for_coloured_pairs() {
    // Independent AR(1) residual and input (φ = 0.8): P₁ = 1 + 2Σ 0.64^k
    // = 4.56, so the white bound would be √4.56 ≈ 2.1 times too tight.
    let (mut corrected, mut plain, mut total) = (0usize, 0usize, 0usize);
    for seed in 0..60 {
        let e = ar1(300 + seed, 2000, 0.8);
        let u = ar1(900 + seed, 2000, 0.8);
        let c = input_residual_correlation(&e, &u, "u", 30, 0.99).unwrap();
        let white_bound = two_sided_z(0.99) / 2000f64.sqrt();
        assert!((c.bound / white_bound - 4.56f64.sqrt()).abs() < 0.6);
        corrected += c.lags_outside.len();
        plain += c.values.iter().filter(|r| r.abs() > white_bound).count();
        total += c.values.len();
    }
    let (rc, rp) = (corrected as f64 / total as f64, plain as f64 / total as f64);
    assert!(rc < 0.03, "corrected rate {rc}");
    assert!(rp > 0.1, "plain rate {rp}");
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let s = ResidualSettings::default();
    let e = analyze_residuals(&[1.0; 10], &s, "residual").unwrap_err();
    assert_eq!(e.field(), "residual");
    let mut x = white(1, 200);
    x[17] = f64::NAN;
    assert!(matches!(
        analyze_residuals(&x, &s, "residual"),
        Err(ValidationError::NonFinite { index: 17, .. })
    ));
    let bad = ResidualSettings {
        confidence: 1.0,
        ..s
    };
    assert_eq!(
        analyze_residuals(&white(1, 200), &bad, "r")
            .unwrap_err()
            .field(),
        "settings.confidence"
    );
    // A constant residual is analysed (exact model), not rejected.
    let a = analyze_residuals(&[0.0; 100], &s, "residual").unwrap();
    assert!(a.white && !a.offset.significant);
    assert!(input_residual_correlation(&[0.0; 100], &white(2, 100), "u", 5, 0.99).is_none());
}
