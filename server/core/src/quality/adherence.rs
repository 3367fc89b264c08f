//! Plan adherence: did the logged column follow its planned schedule?
//!
//! The schedule is resampled to the log rate (linear interpolation) and
//! slid along the log; at every lag L (schedule sample j ↔ log sample
//! j + L) the Pearson correlation over the overlap — valid log samples
//! only — is computed from FFT cross-correlations and prefix sums in
//! O((N + M) log(N + M)) for a log of N and a schedule of M samples. The
//! lag of the largest correlation is the schedule's start in the log.

use std::ops::Range;

use realfft::RealFftPlanner;
use realfft::num_complex::Complex;

use super::words::{num, pct};
use super::{Adherence, QualityError};
use crate::timeseries::interp_linear;

/// Smallest correlation at the lag for a column to count as following its
/// schedule: r ≥ 0.8 leaves ≤ 36 % of the logged variance unexplained by
/// the (scaled, shifted) schedule — thruster lag and saturation, not a
/// different manoeuvre.
pub const MIN_ADHERENCE_CORRELATION: f64 = 0.8;

/// Accepted range of the amplitude ratio (std logged / std planned): ±30 %,
/// beyond which the run's signal-to-noise ratio and operating region differ
/// from the plan's (a half-amplitude run halves the SNR).
pub const AMPLITUDE_RATIO_RANGE: [f64; 2] = [0.7, 1.3];

/// Smallest fraction of the schedule that must fall on valid log samples.
pub const MIN_COVERAGE: f64 = 0.9;

/// Lags whose overlap is shorter than this fraction of the shorter of the
/// schedule and the valid log are not considered (a short overlap can
/// correlate by chance).
pub const MIN_OVERLAP_FRACTION: f64 = 0.5;

/// Compares `log` (sampled at `fs`, valid on `blocks`) with a schedule
/// sampled at `schedule_rate_hz`. Inputs are validated by the caller
/// (finite, ≥ 2 schedule samples, positive rates).
pub(crate) fn adherence(
    log_column: &str,
    schedule_column: &str,
    log: &[f64],
    blocks: &[Range<usize>],
    fs: f64,
    schedule: &[f64],
    schedule_rate_hz: f64,
) -> Result<Adherence, QualityError> {
    let plan = resample(schedule, schedule_rate_hz, fs);
    let fit = best_lag(log, blocks, &plan)?;
    let ratio_ok = fit
        .amplitude_ratio
        .is_some_and(|r| (AMPLITUDE_RATIO_RANGE[0]..=AMPLITUDE_RATIO_RANGE[1]).contains(&r));
    let followed =
        fit.correlation >= MIN_ADHERENCE_CORRELATION && ratio_ok && fit.coverage >= MIN_COVERAGE;
    let ratio_text = fit.amplitude_ratio.map_or_else(
        || "undefined (the schedule holds one value)".to_owned(),
        num,
    );
    let lag_s = fit.lag as f64 / fs;
    let message = if followed {
        format!(
            "{log_column} followed the planned {schedule_column}: starting {} s into the log, \
             correlation {}, amplitude ratio {}, coverage {}",
            num(lag_s),
            num(fit.correlation),
            ratio_text,
            pct(fit.coverage)
        )
    } else {
        let mut why = Vec::new();
        if fit.correlation < MIN_ADHERENCE_CORRELATION {
            why.push(format!(
                "correlation {} < {}",
                num(fit.correlation),
                MIN_ADHERENCE_CORRELATION
            ));
        }
        if !ratio_ok {
            why.push(match fit.amplitude_ratio {
                Some(r) => format!(
                    "amplitude ratio {} outside {}–{}",
                    num(r),
                    AMPLITUDE_RATIO_RANGE[0],
                    AMPLITUDE_RATIO_RANGE[1]
                ),
                None => format!("amplitude ratio {ratio_text}"),
            });
        }
        if fit.coverage < MIN_COVERAGE {
            why.push(format!(
                "coverage {} < {}",
                pct(fit.coverage),
                pct(MIN_COVERAGE)
            ));
        }
        format!(
            "{log_column} did not follow the planned {schedule_column} (best match {} s into the log): {}",
            num(lag_s),
            why.join(", ")
        )
    };
    Ok(Adherence {
        log_column: log_column.to_owned(),
        schedule_column: schedule_column.to_owned(),
        lag_s,
        correlation: fit.correlation,
        amplitude_ratio: fit.amplitude_ratio,
        nrmse: fit.nrmse,
        coverage: fit.coverage,
        followed,
        message,
    })
}

/// The schedule at the log's sample times `j / fs` over its own duration.
fn resample(schedule: &[f64], rate: f64, fs: f64) -> Vec<f64> {
    let t: Vec<f64> = (0..schedule.len()).map(|k| k as f64 / rate).collect();
    let duration = (schedule.len() - 1) as f64 / rate;
    let m = (duration * fs + 1e-9).floor() as usize + 1;
    let at: Vec<f64> = (0..m).map(|j| j as f64 / fs).collect();
    interp_linear(&t, schedule, &at)
}

/// The match at the best lag.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Fit {
    /// Log index of the schedule's first sample.
    pub lag: i64,
    pub correlation: f64,
    /// `None` when the schedule holds one value over the overlap.
    pub amplitude_ratio: Option<f64>,
    pub nrmse: Option<f64>,
    pub coverage: f64,
}

/// A schedule whose spread over the overlap is below this fraction of its
/// level and of the log's spread holds one value (interpolation leaves
/// rounding noise ~1e-16 of the level, which must not become a ratio of
/// 1e12).
const CONSTANT_SCHEDULE: f64 = 1e-9;

/// Slides `plan` (M samples) along `log` (N samples, valid on `blocks`) and
/// returns the lag of the largest Pearson correlation over the overlap.
pub(crate) fn best_lag(
    log: &[f64],
    blocks: &[Range<usize>],
    plan: &[f64],
) -> Result<Fit, QualityError> {
    let (n, m) = (log.len(), plan.len());
    // Mask and globally centred log (0 outside the valid blocks), centred
    // plan: the Pearson sums below re-centre on each overlap; centring first
    // only keeps them well conditioned.
    let mut mask = vec![0.0; n];
    for b in blocks {
        mask[b.clone()].iter_mut().for_each(|v| *v = 1.0);
    }
    let n_valid: f64 = mask.iter().sum();
    let log_mean = if n_valid > 0.0 {
        log.iter().zip(&mask).map(|(x, w)| x * w).sum::<f64>() / n_valid
    } else {
        0.0
    };
    let a: Vec<f64> = log
        .iter()
        .zip(&mask)
        .map(|(x, w)| if *w > 0.0 { x - log_mean } else { 0.0 })
        .collect();
    let plan_mean = plan.iter().sum::<f64>() / m as f64;
    let p: Vec<f64> = plan.iter().map(|v| v - plan_mean).collect();
    let p2: Vec<f64> = p.iter().map(|v| v * v).collect();

    // Prefix sums over the log: count, Σa, Σa².
    let prefix = |f: &dyn Fn(usize) -> f64| {
        let mut c = Vec::with_capacity(n + 1);
        let mut s = 0.0;
        c.push(0.0);
        for t in 0..n {
            s += f(t);
            c.push(s);
        }
        c
    };
    let cn = prefix(&|t| mask[t]);
    let ca = prefix(&|t| a[t]);
    let caa = prefix(&|t| a[t] * a[t]);

    // Cross-correlations r(L) = Σ_t u(t) v(t − L), L ∈ −(M−1)..=N−1.
    let xc = Correlator::new(n + m - 1);
    let (a_hat, mask_hat) = (xc.forward(&a)?, xc.forward(&mask)?);
    let (p_hat, p2_hat) = (xc.forward(&p)?, xc.forward(&p2)?);
    let s_ap = xc.correlate(&a_hat, &p_hat)?;
    let s_p = xc.correlate(&mask_hat, &p_hat)?;
    let s_pp = xc.correlate(&mask_hat, &p2_hat)?;

    let total_pp: f64 = p2.iter().sum();
    let total_aa = caa[n];
    let min_overlap = ((MIN_OVERLAP_FRACTION * (m as f64).min(n_valid)).ceil()).max(2.0);
    let mut best: Option<(f64, i64)> = None;
    let mut fallback: Option<(f64, i64)> = None; // largest overlap
    for lag in -(m as i64 - 1)..=(n as i64 - 1) {
        let lo = lag.max(0) as usize;
        let hi = ((lag + m as i64).min(n as i64)) as usize;
        let cnt = cn[hi] - cn[lo];
        if fallback.is_none_or(|(c, _)| cnt > c) {
            fallback = Some((cnt, lag));
        }
        if cnt < min_overlap {
            continue;
        }
        let k = xc.index(lag);
        let (sa, saa) = (ca[hi] - ca[lo], caa[hi] - caa[lo]);
        let (sp, spp, sap) = (s_p[k], s_pp[k], s_ap[k]);
        let va = saa - sa * sa / cnt;
        let vp = spp - sp * sp / cnt;
        // Overlaps where either side is (numerically) constant carry no
        // correlation.
        if va <= 1e-9 * total_aa || vp <= 1e-9 * total_pp {
            continue;
        }
        let r = (sap - sa * sp / cnt) / (va * vp).sqrt();
        if best.is_none_or(|(b, _)| r > b) {
            best = Some((r, lag));
        }
    }
    let (correlation, lag) = match best {
        Some((r, lag)) => (r.clamp(-1.0, 1.0), lag),
        None => (0.0, fallback.map_or(0, |(_, l)| l)),
    };
    Ok(fit_at(log, &mask, plan, lag, correlation))
}

/// Amplitude ratio, NRMSE and coverage at `lag`, summed directly.
fn fit_at(log: &[f64], mask: &[f64], plan: &[f64], lag: i64, correlation: f64) -> Fit {
    let (n, m) = (log.len() as i64, plan.len() as i64);
    let idx = (0..m).filter_map(|j| {
        let t = j + lag;
        (t >= 0 && t < n && mask[t as usize] > 0.0).then_some((t as usize, j as usize))
    });
    let (mut cnt, mut sa, mut sp) = (0.0, 0.0, 0.0);
    for (t, j) in idx.clone() {
        cnt += 1.0;
        sa += log[t];
        sp += plan[j];
    }
    let coverage = cnt / m as f64;
    if cnt == 0.0 {
        return Fit {
            lag,
            correlation,
            amplitude_ratio: None,
            nrmse: None,
            coverage,
        };
    }
    let (ma, mp) = (sa / cnt, sp / cnt);
    let (mut va, mut vp, mut se) = (0.0, 0.0, 0.0);
    for (t, j) in idx {
        va += (log[t] - ma).powi(2);
        vp += (plan[j] - mp).powi(2);
        se += (log[t] - plan[j]).powi(2);
    }
    let (sd_a, sd_p) = ((va / cnt).sqrt(), (vp / cnt).sqrt());
    let rmse = (se / cnt).sqrt();
    let (amplitude_ratio, nrmse) = if sd_p > CONSTANT_SCHEDULE * (mp.abs() + sd_a) {
        (Some(sd_a / sd_p), Some(rmse / sd_p))
    } else {
        (None, None)
    };
    Fit {
        lag,
        correlation,
        amplitude_ratio,
        nrmse,
        coverage,
    }
}

/// Linear cross-correlation by zero-padded real FFTs.
struct Correlator {
    nfft: usize,
    forward: std::sync::Arc<dyn realfft::RealToComplex<f64>>,
    inverse: std::sync::Arc<dyn realfft::ComplexToReal<f64>>,
}

impl Correlator {
    /// For correlations of total support `len` (`N + M − 1`).
    fn new(len: usize) -> Self {
        let nfft = len.next_power_of_two().max(2);
        let mut planner = RealFftPlanner::<f64>::new();
        Correlator {
            nfft,
            forward: planner.plan_fft_forward(nfft),
            inverse: planner.plan_fft_inverse(nfft),
        }
    }

    fn forward(&self, x: &[f64]) -> Result<Vec<Complex<f64>>, QualityError> {
        let mut input = self.forward.make_input_vec();
        input[..x.len()].copy_from_slice(x);
        let mut out = self.forward.make_output_vec();
        self.forward
            .process(&mut input, &mut out)
            .map_err(|e| fft_error(&e.to_string()))?;
        Ok(out)
    }

    /// `r[index(L)] = Σ_t u(t) v(t − L)` from `U = FFT(u)`, `V = FFT(v)`.
    fn correlate(&self, u: &[Complex<f64>], v: &[Complex<f64>]) -> Result<Vec<f64>, QualityError> {
        let mut prod: Vec<Complex<f64>> = u.iter().zip(v).map(|(a, b)| a * b.conj()).collect();
        // The DC and Nyquist bins of a real signal's product are real.
        if let Some(first) = prod.first_mut() {
            first.im = 0.0;
        }
        if let Some(last) = prod.last_mut() {
            last.im = 0.0;
        }
        let mut out = self.inverse.make_output_vec();
        self.inverse
            .process(&mut prod, &mut out)
            .map_err(|e| fft_error(&e.to_string()))?;
        let scale = 1.0 / self.nfft as f64;
        out.iter_mut().for_each(|v| *v *= scale);
        Ok(out)
    }

    /// Position of lag `L` in a correlation (negative lags wrap).
    fn index(&self, lag: i64) -> usize {
        if lag >= 0 {
            lag as usize
        } else {
            (self.nfft as i64 + lag) as usize
        }
    }
}

fn fft_error(e: &str) -> QualityError {
    QualityError::spec(
        "planned",
        format!("FFT for the plan correlation failed: {e}"),
    )
}

#[cfg(test)]
#[allow(clippy::single_range_in_vec_init)] // vectors of blocks
mod tests {
    use super::*;

    fn pearson_direct(log: &[f64], mask: &[f64], plan: &[f64], lag: i64) -> f64 {
        let pts: Vec<(f64, f64)> = (0..plan.len() as i64)
            .filter_map(|j| {
                let t = j + lag;
                (t >= 0 && (t as usize) < log.len() && mask[t as usize] > 0.0)
                    .then(|| (log[t as usize], plan[j as usize]))
            })
            .collect();
        let n = pts.len() as f64;
        let (ma, mp) = (
            pts.iter().map(|p| p.0).sum::<f64>() / n,
            pts.iter().map(|p| p.1).sum::<f64>() / n,
        );
        let cov: f64 = pts.iter().map(|p| (p.0 - ma) * (p.1 - mp)).sum();
        let va: f64 = pts.iter().map(|p| (p.0 - ma).powi(2)).sum();
        let vp: f64 = pts.iter().map(|p| (p.1 - mp).powi(2)).sum();
        cov / (va * vp).sqrt()
    }

    #[test]
    fn fft_correlation_equals_direct_pearson_with_gaps() {
        let plan: Vec<f64> = (0..150)
            .map(|j| ((j * 7919) % 31) as f64 - 15.0 + (j as f64 * 0.1).sin())
            .collect();
        let mut log: Vec<f64> = (0..400).map(|t| 50.0 + ((t * 13) % 7) as f64).collect();
        for j in 0..150 {
            log[120 + j] += 0.9 * plan[j];
        }
        let blocks = vec![0..200, 230..400];
        let fit = best_lag(&log, &blocks, &plan).unwrap();
        assert_eq!(fit.lag, 120);
        let mut mask = vec![0.0; 400];
        for b in &blocks {
            mask[b.clone()].iter_mut().for_each(|v| *v = 1.0);
        }
        let direct = pearson_direct(&log, &mask, &plan, 120);
        assert!(
            (fit.correlation - direct).abs() < 1e-9,
            "{fit:?} vs {direct}"
        );
        assert!((fit.coverage - 120.0 / 150.0).abs() < 1e-12);
    }

    #[test]
    fn resample_keeps_duration() {
        let s = resample(&[0.0, 1.0, 2.0, 3.0, 4.0], 2.0, 4.0);
        assert_eq!(s.len(), 9);
        assert!((s[3] - 1.5).abs() < 1e-12);
        assert_eq!(resample(&[1.0, 3.0], 1.0, 0.5), vec![1.0]);
    }

    #[test]
    fn constant_log_matches_nothing() {
        let plan: Vec<f64> = (0..50).map(|j| (j as f64).sin()).collect();
        let fit = best_lag(&[2.0; 100], &[0..100], &plan).unwrap();
        assert_eq!(fit.correlation, 0.0);
        assert_eq!(fit.amplitude_ratio, Some(0.0));
    }

    #[test]
    fn a_hold_has_no_amplitude_ratio_rather_than_1e12() {
        // A held level with the rounding noise of interpolation (1e-16 of
        // the level) against a log that moves about it.
        let plan: Vec<f64> = (0..100)
            .map(|j| 250.0 * (1.0 + 1e-16 * ((j % 3) as f64 - 1.0)))
            .collect();
        let log: Vec<f64> = (0..100).map(|t| 250.0 + 3.0 * (t as f64).sin()).collect();
        let fit = best_lag(&log, &[0..100], &plan).unwrap();
        assert_eq!((fit.amplitude_ratio, fit.nrmse), (None, None));
        let a = adherence("tau_X", "surge_hold", &log, &[0..100], 1.0, &plan, 1.0).unwrap();
        assert!(!a.followed);
        assert!(
            a.message
                .contains("amplitude ratio undefined (the schedule holds one value)"),
            "{}",
            a.message
        );
    }
}
