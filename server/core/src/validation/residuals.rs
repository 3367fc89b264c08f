//! Residual analysis of a prediction-error sequence e(k) = x(k) − x̂(k|k−1)
//! (thesis eq. 2.19, sec. 2.6): is what the model leaves over white,
//! zero-mean, normal and independent of the inputs?
//!
//! - autocorrelation with the approximate 99 % bounds ±2.576/√N of a white
//!   sequence (Bartlett's wider bounds beyond an MA order for k-step errors),
//!   summarized by the Ljung–Box portmanteau statistic;
//! - input–residual cross-correlation for lags −L..L;
//! - the number of zero crossings against its white-noise law
//!   Bin(N−1, ½): mean (N−1)/2, variance (N−1)/4 — few crossings betray an
//!   offset or slow residual dynamics;
//! - a normal-probability ("norm") plot with Jarque–Bera normality test.

use serde::Serialize;

use super::correlation::{autocorrelation, cross_correlation};
use super::distributions::{binomial_sf, chi_square_sf, normal_quantile, normal_sf};
use super::error::ValidationError;

/// Fewest samples a residual analysis accepts.
pub const MIN_RESIDUAL_SAMPLES: usize = 8;

/// How a residual sequence is tested.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResidualSettings {
    /// Largest lag L of the correlation functions (≥ 1, < N).
    pub max_lag: usize,
    /// MA order q the sequence has even for a correct model: 0 for 1-step
    /// errors, k − 1 for k-step errors (they overlap k − 1 noise samples).
    /// Whiteness is judged on the lags beyond q.
    pub ma_order: usize,
    /// Confidence level of the bounds and tests (0.99 in the thesis).
    pub confidence: f64,
    /// Points kept in the probability plot for display (≥ 2).
    pub plot_points: usize,
}

impl Default for ResidualSettings {
    fn default() -> Self {
        ResidualSettings {
            max_lag: 50,
            ma_order: 0,
            confidence: 0.99,
            plot_points: 200,
        }
    }
}

/// Everything the residual tests say about one error sequence.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct ResidualAnalysis {
    /// Samples analysed.
    pub n_samples: usize,
    /// Root mean square of the residual (its own units).
    pub rms: f64,
    /// Standard deviation about the mean.
    pub std: f64,
    /// Is the mean zero?
    pub offset: OffsetTest,
    /// Sample autocorrelation and its bounds.
    pub autocorrelation: AutocorrelationTest,
    /// Ljung–Box portmanteau test on lags 1..L; `None` for k-step errors
    /// (ma_order > 0), whose correlated lags make it meaningless.
    pub ljung_box: Option<LjungBox>,
    /// Zero crossings against a white sequence.
    pub zero_crossings: ZeroCrossings,
    /// Normality of the residual.
    pub normality: Normality,
    /// Whiteness verdict at the chosen confidence: Ljung–Box for 1-step
    /// errors, the count of lags beyond the MA order outside their bounds
    /// otherwise.
    pub white: bool,
    /// The p-value behind `white`.
    pub whiteness_p_value: f64,
}

/// Test of a zero mean, with the sample size discounted for correlation.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct OffsetTest {
    /// Mean of the residual.
    pub mean: f64,
    /// Its standard error σ/√N_eff.
    pub std_error: f64,
    /// Effective sample size N / (1 + 2 Σ r(k)), within [1, N].
    pub effective_samples: f64,
    /// Two-sided p-value of "mean = 0".
    pub p_value: f64,
    /// `p_value` below 1 − confidence.
    pub significant: bool,
}

/// Normalized autocorrelation r(0..=L) with its confidence bounds.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct AutocorrelationTest {
    /// Lags 0..=L (samples).
    pub lags: Vec<usize>,
    /// r(lag), r(0) = 1.
    pub values: Vec<f64>,
    /// Half-width of the confidence band per lag: z/√N for a white
    /// sequence, z·√((1 + 2Σ_{i<lag, i≤q} r(i)²)/N) (Bartlett) beyond an MA
    /// order q. 0 at lag 0.
    pub bounds: Vec<f64>,
    /// Confidence level of the bounds.
    pub confidence: f64,
    /// MA order q: lags ≤ q are expected to be correlated.
    pub ma_order: usize,
    /// Lags beyond q where |r| exceeds its bound.
    pub lags_outside: Vec<usize>,
    /// Fraction of the lags q+1..=L outside the bounds.
    pub fraction_outside: f64,
    /// The fraction a white sequence gives: 1 − confidence.
    pub expected_fraction: f64,
    /// P(at least this many lags outside) for a white sequence (binomial).
    pub count_p_value: f64,
}

/// Ljung–Box portmanteau statistic Q = N(N+2) Σ_{k=1}^{L} r(k)²/(N−k),
/// χ²(L) for a white sequence.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct LjungBox {
    /// Q.
    pub statistic: f64,
    /// Degrees of freedom (L).
    pub dof: usize,
    /// P(χ²(L) > Q).
    pub p_value: f64,
}

/// Sign changes of the residual against those of a white, zero-mean,
/// symmetric sequence: Bin(N−1, ½).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct ZeroCrossings {
    /// Sign changes between successive non-zero samples.
    pub count: usize,
    /// Expected count (N−1)/2, N the non-zero samples.
    pub expected: f64,
    /// Its standard deviation √(N−1)/2.
    pub std: f64,
    /// (count − expected)/std: negative for too few crossings.
    pub z: f64,
    /// Two-sided p-value.
    pub p_value: f64,
}

/// Shape of the residual distribution.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct Normality {
    /// Sample skewness m₃/m₂^{3/2}.
    pub skewness: f64,
    /// Sample excess kurtosis m₄/m₂² − 3 (0 for a normal; > 0 heavy tails).
    pub excess_kurtosis: f64,
    /// Jarque–Bera statistic with Lomnicki's correction for
    /// autocorrelation (Lobato & Velasco 2004):
    /// JB = N·S²/(6·Σρ(k)³) + N·K²/(24·Σρ(k)⁴), sums over k = −L..L (each
    /// at least 1). For a white residual the sums are 1 and this is the
    /// plain JB = N/6 (S² + K²/4); χ²(2) for a normal sequence.
    pub jarque_bera: f64,
    /// P(χ²(2) > JB).
    pub p_value: f64,
    /// Correlation of the probability plot (1 for a perfect line); `None`
    /// for a constant residual, whose plot is a flat line.
    pub plot_correlation: Option<f64>,
    /// The normal-probability plot, thinned for display.
    pub plot: ProbabilityPlot,
}

/// Normal-probability plot: sorted residuals against the normal quantiles
/// of their plotting positions (Blom, (i − 3/8)/(N + 1/4)). A straight line
/// means normal; its slope is σ, its intercept the mean.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct ProbabilityPlot {
    /// Standard-normal quantiles (x axis).
    pub theoretical_quantiles: Vec<f64>,
    /// Sorted residuals (y axis, residual units).
    pub sorted_residuals: Vec<f64>,
}

/// Cross-correlation of one input with a residual.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct CrossCorrelation {
    /// Input name.
    pub input: String,
    /// Lags −L..=L (samples); positive: the residual after the input.
    pub lags: Vec<i64>,
    /// r_eu(lag).
    pub values: Vec<f64>,
    /// Pointwise bound z·√(P₁/N), P₁ = max(1, Σ_k r_e(k) r_u(k)) (Ljung
    /// 1999, eq. 16.63): the white-residual bound z/√N, widened when both
    /// the residual and the input are coloured.
    pub bound: f64,
    /// Bound for the whole family of lags 0..=L (Bonferroni), used to
    /// decide a leak without false alarms from many lags.
    pub family_bound: f64,
    /// Lags where |r| exceeds `bound`.
    pub lags_outside: Vec<i64>,
    /// Lag of the largest |r| at lags ≥ 0.
    pub peak_lag: i64,
    /// r at `peak_lag`.
    pub peak_value: f64,
    /// |r| beyond `family_bound` at a lag ≥ 0: the input reaches the
    /// residual, i.e. the model misses a coupling or a delay.
    pub leak: bool,
    /// |r| beyond `family_bound` at a lag < 0 only: the residual precedes
    /// the input — feedback from a controller, expected in closed loop.
    pub feedback: bool,
}

/// The two-sided normal quantile of a confidence level.
pub(crate) fn two_sided_z(confidence: f64) -> f64 {
    normal_quantile(0.5 + 0.5 * confidence)
}

fn check_settings(s: &ResidualSettings) -> Result<(), ValidationError> {
    if !(s.confidence > 0.0 && s.confidence < 1.0) {
        return Err(ValidationError::invalid(
            "settings.confidence",
            format!("must lie strictly between 0 and 1, got {}", s.confidence),
        ));
    }
    if s.max_lag == 0 {
        return Err(ValidationError::invalid("settings.max_lag", "must be ≥ 1"));
    }
    if s.ma_order >= s.max_lag {
        return Err(ValidationError::invalid(
            "settings.max_lag",
            format!(
                "must exceed the MA order {} of the residual (k − 1 for k-step errors)",
                s.ma_order
            ),
        ));
    }
    if s.plot_points < 2 {
        return Err(ValidationError::invalid(
            "settings.plot_points",
            "must be ≥ 2",
        ));
    }
    Ok(())
}

/// The full residual analysis of `e` (all samples finite, N > L + 1).
/// `field` names the sequence in errors.
pub fn analyze_residuals(
    e: &[f64],
    settings: &ResidualSettings,
    field: &str,
) -> Result<ResidualAnalysis, ValidationError> {
    check_settings(settings)?;
    if let Some(i) = e.iter().position(|v| !v.is_finite()) {
        return Err(ValidationError::non_finite(field, i));
    }
    let n = e.len();
    let needed = (settings.max_lag + 2).max(MIN_RESIDUAL_SAMPLES);
    if n < needed {
        return Err(ValidationError::too_short(
            field,
            format!(
                "{n} samples; the residual tests with max_lag {} need at least {needed}",
                settings.max_lag
            ),
        ));
    }
    let alpha = 1.0 - settings.confidence;
    let mean = e.iter().sum::<f64>() / n as f64;
    let var = e.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n as f64;
    let rms = (e.iter().map(|v| v * v).sum::<f64>() / n as f64).sqrt();
    let std = var.sqrt();
    // A constant residual (e.g. an exact model on noise-free data) has no
    // correlation structure: treat it as uncorrelated.
    let r = autocorrelation(e, settings.max_lag).unwrap_or_else(|| {
        let mut r = vec![0.0; settings.max_lag + 1];
        r[0] = 1.0;
        r
    });
    let acf = autocorrelation_test(&r, n, settings);
    let ljung_box = (settings.ma_order == 0).then(|| ljung_box(&r, n));
    let (white, whiteness_p_value) = match &ljung_box {
        Some(lb) => (lb.p_value >= alpha, lb.p_value),
        None => (acf.count_p_value >= alpha, acf.count_p_value),
    };
    Ok(ResidualAnalysis {
        n_samples: n,
        rms,
        std,
        offset: offset_test(mean, std, n, &r, alpha),
        autocorrelation: acf,
        ljung_box,
        zero_crossings: zero_crossings(e),
        normality: normality(e, Some(&r), settings.plot_points),
        white,
        whiteness_p_value,
    })
}

fn autocorrelation_test(r: &[f64], n: usize, s: &ResidualSettings) -> AutocorrelationTest {
    let z = two_sided_z(s.confidence);
    let nf = n as f64;
    let mut bounds = Vec::with_capacity(r.len());
    let mut sum_sq = 0.0;
    for lag in 0..r.len() {
        if lag == 0 {
            bounds.push(0.0);
            continue;
        }
        // Bartlett: var r(j) ≈ (1 + 2 Σ_{i=1}^{min(j−1, q)} ρ(i)²)/N.
        if lag > 1 && lag - 1 <= s.ma_order {
            sum_sq += r[lag - 1] * r[lag - 1];
        }
        bounds.push(z * ((1.0 + 2.0 * sum_sq) / nf).sqrt());
    }
    let tested = s.max_lag - s.ma_order;
    let lags_outside: Vec<usize> = (s.ma_order + 1..r.len())
        .filter(|&k| r[k].abs() > bounds[k])
        .collect();
    let alpha = 1.0 - s.confidence;
    AutocorrelationTest {
        lags: (0..r.len()).collect(),
        values: r.to_vec(),
        bounds,
        confidence: s.confidence,
        ma_order: s.ma_order,
        fraction_outside: lags_outside.len() as f64 / tested as f64,
        expected_fraction: alpha,
        count_p_value: binomial_sf(lags_outside.len(), tested, alpha),
        lags_outside,
    }
}

/// Ljung–Box Q of the autocorrelation `r` (r[0] = 1, lags 1..) of N samples.
pub fn ljung_box(r: &[f64], n: usize) -> LjungBox {
    let nf = n as f64;
    let lags = r.len().saturating_sub(1).min(n.saturating_sub(1));
    let sum: f64 = (1..=lags).map(|k| r[k] * r[k] / (nf - k as f64)).sum();
    let statistic = nf * (nf + 2.0) * sum;
    LjungBox {
        statistic,
        dof: lags,
        p_value: chi_square_sf(statistic, lags as f64),
    }
}

fn offset_test(mean: f64, std: f64, n: usize, r: &[f64], alpha: f64) -> OffsetTest {
    let nf = n as f64;
    // Correlated samples carry less information about the mean.
    let inflation: f64 = 1.0
        + 2.0
            * r.iter()
                .enumerate()
                .skip(1)
                .map(|(k, v)| (1.0 - k as f64 / nf) * v)
                .sum::<f64>();
    let effective_samples = (nf / inflation.max(1e-12)).clamp(1.0, nf);
    let std_error = std / effective_samples.sqrt();
    let p_value = if std_error > 0.0 {
        2.0 * normal_sf((mean / std_error).abs())
    } else if mean == 0.0 {
        1.0
    } else {
        0.0
    };
    OffsetTest {
        mean,
        std_error,
        effective_samples,
        p_value,
        significant: p_value < alpha,
    }
}

/// Zero crossings of `e`: sign changes between successive non-zero samples
/// (exact zeros carry no sign and are skipped), tested against Bin(N−1, ½).
pub fn zero_crossings(e: &[f64]) -> ZeroCrossings {
    let signs: Vec<bool> = e
        .iter()
        .filter(|v| **v != 0.0 && !v.is_nan())
        .map(|v| *v > 0.0)
        .collect();
    let count = signs.windows(2).filter(|w| w[0] != w[1]).count();
    let pairs = signs.len().saturating_sub(1) as f64;
    let expected = 0.5 * pairs;
    let std = 0.5 * pairs.sqrt();
    let z = if std > 0.0 {
        (count as f64 - expected) / std
    } else {
        0.0
    };
    ZeroCrossings {
        count,
        expected,
        std,
        z,
        p_value: (2.0 * normal_sf(z.abs())).min(1.0),
    }
}

/// Skewness, kurtosis, Jarque–Bera and the probability plot of `e`, with
/// `autocorrelation` r(0..=L) of `e` when it is not white (`None`: white).
pub fn normality(e: &[f64], autocorrelation: Option<&[f64]>, plot_points: usize) -> Normality {
    let n = e.len();
    let nf = n as f64;
    let mean = e.iter().sum::<f64>() / nf;
    let m = |p: i32| e.iter().map(|v| (v - mean).powi(p)).sum::<f64>() / nf;
    let (m2, m3, m4) = (m(2), m(3), m(4));
    let (skewness, excess_kurtosis) = if m2 > 0.0 {
        (m3 / m2.powf(1.5), m4 / (m2 * m2) - 3.0)
    } else {
        (0.0, 0.0)
    };
    // Correlated samples make S and K vary more than 6/N and 24/N.
    let inflation = |p: i32| {
        autocorrelation.map_or(1.0, |r| {
            (1.0 + 2.0 * r.iter().skip(1).map(|v| v.powi(p)).sum::<f64>()).max(1.0)
        })
    };
    let jarque_bera = nf * skewness * skewness / (6.0 * inflation(3))
        + nf * excess_kurtosis * excess_kurtosis / (24.0 * inflation(4));
    let mut sorted: Vec<f64> = e.to_vec();
    sorted.sort_by(f64::total_cmp);
    let q: Vec<f64> = (0..n)
        .map(|i| normal_quantile((i as f64 + 1.0 - 0.375) / (nf + 0.25)))
        .collect();
    let plot_correlation = pearson(&q, &sorted);
    let keep = thin_indices(n, plot_points);
    Normality {
        skewness,
        excess_kurtosis,
        jarque_bera,
        p_value: chi_square_sf(jarque_bera, 2.0),
        plot_correlation,
        plot: ProbabilityPlot {
            theoretical_quantiles: keep.iter().map(|&i| q[i]).collect(),
            sorted_residuals: keep.iter().map(|&i| sorted[i]).collect(),
        },
    }
}

/// Up to `points` indices of 0..n spread evenly, first and last included.
fn thin_indices(n: usize, points: usize) -> Vec<usize> {
    if n <= points || points < 2 {
        return (0..n).collect();
    }
    let mut idx: Vec<usize> = (0..points)
        .map(|i| ((i as f64) * (n - 1) as f64 / (points - 1) as f64).round() as usize)
        .collect();
    idx.dedup();
    idx
}

fn pearson(a: &[f64], b: &[f64]) -> Option<f64> {
    let n = a.len() as f64;
    let ma = a.iter().sum::<f64>() / n;
    let mb = b.iter().sum::<f64>() / n;
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        sab += (x - ma) * (y - mb);
        saa += (x - ma) * (x - ma);
        sbb += (y - mb) * (y - mb);
    }
    (saa > 0.0 && sbb > 0.0).then(|| sab / (saa * sbb).sqrt())
}

/// Cross-correlation of input `u` (named `input`) with residual `e` for the
/// lags −L..=L, with its bounds and leak/feedback decisions. `None` when
/// the input or the residual is constant or the lengths differ.
pub fn input_residual_correlation(
    e: &[f64],
    u: &[f64],
    input: &str,
    max_lag: usize,
    confidence: f64,
) -> Option<CrossCorrelation> {
    let n = e.len();
    if n < 2 || max_lag == 0 || !(confidence > 0.0 && confidence < 1.0) {
        return None;
    }
    let values = cross_correlation(e, u, max_lag)?;
    let re = autocorrelation(e, max_lag)?;
    let ru = autocorrelation(u, max_lag)?;
    let p1 = 1.0 + 2.0 * (1..=max_lag).map(|k| re[k] * ru[k]).sum::<f64>();
    let scale = (p1.max(1.0) / n as f64).sqrt();
    let bound = two_sided_z(confidence) * scale;
    let alpha = 1.0 - confidence;
    let family_bound = normal_quantile(1.0 - alpha / (2.0 * (max_lag + 1) as f64)) * scale;
    let lags: Vec<i64> = (-(max_lag as i64)..=max_lag as i64).collect();
    let lags_outside = lags
        .iter()
        .zip(&values)
        .filter(|(_, r)| r.abs() > bound)
        .map(|(l, _)| *l)
        .collect();
    let (peak_lag, peak_value) =
        lags.iter()
            .zip(&values)
            .filter(|(l, _)| **l >= 0)
            .fold(
                (0, 0.0),
                |m, (l, r)| {
                    if r.abs() > f64::abs(m.1) { (*l, *r) } else { m }
                },
            );
    let beyond = |neg: bool| {
        lags.iter()
            .zip(&values)
            .any(|(l, r)| (*l < 0) == neg && r.abs() > family_bound)
    };
    let leak = beyond(false);
    let feedback = !leak && beyond(true);
    Some(CrossCorrelation {
        input: input.to_owned(),
        lags,
        values,
        bound,
        family_bound,
        lags_outside,
        peak_lag,
        peak_value,
        leak,
        feedback,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
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
}
