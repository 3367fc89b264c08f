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
