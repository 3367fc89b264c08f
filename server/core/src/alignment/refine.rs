//! Sub-sample refinement of the clock offset and its standard error.
//!
//! The slower log is the *reference*, the faster the *other*. Both are
//! smoothed by the same Gaussian prefilter of width σ (see `kernel.rs` for
//! why, `bandwidth.rs` for the width): the reference at its own stamps, the
//! other onto a uniform grid four times finer than σ, which a cubic Hermite
//! interpolant ([`Hermite`]) then evaluates
//! at the reference stamps mapped onto its clock. The prefiltered other is
//! smooth on the grid scale, so the interpolation adds neither bias nor a
//! fraction-dependent noise level.
//!
//! Mismatch for a trial offset `d` (`y` prefiltered reference, `u_d`
//! prefiltered other, over a fixed set of reference samples that stay inside
//! the other log, clear of both logs' ends, for every `d` tried):
//!
//! `J(d) = min over (g, c) of mean_k (y_k − g·u_d,k − c)²`,
//!
//! the residual of the best gain and bias, so two sensors with different
//! zeros (a depth sensor on the controller housing, the INS reference point)
//! or slightly different scales still align. `J` is smooth in `d`; Brent's
//! method minimizes it over `d₀ ± half_width`.
//!
//! Standard error (Cramér–Rao style, sandwich form):
//! `var(d) = V / (n·J''/2)²`, where `J''` is the curvature of the mismatch
//! at its minimum (central second difference) and `V` the long-run variance
//! of the score `Σ_k w_k r_k` (residuals `r`, model derivatives `w` with
//! respect to `d`), Newey–West with a Bartlett kernel over at least the
//! prefilter's correlation length. For white residuals `V = σ²·Σw²` and
//! this is the Cramér–Rao bound `σ² / Σw²`; the measured curvature (rather
//! than the Gauss–Newton `2Σw²/n`) matters because noise in the interpolated
//! record inflates `Σw²` without sharpening the minimum.
//!
//! The reported residual compares the *raw* reference samples with a cubic
//! interpolant of the *raw* other log.

use std::ops::Range;

use super::AlignError;
use super::brent;
use super::hermite::{Cursor, Hermite};
use super::kernel::{SUPPORT, smooth};
use crate::timeseries::median_dt;

/// A reference log paired with the other log, both prefiltered.
#[derive(Debug, Clone)]
pub(crate) struct Pairing<'a> {
    ref_t: &'a [f64],
    /// Prefiltered reference, centered.
    ref_y: Vec<f64>,
    /// Raw reference, centered.
    ref_raw: Vec<f64>,
    /// Prefiltered other on its fine grid.
    other: Hermite,
    /// Raw other.
    other_raw: Hermite,
    other_span: (f64, f64),
    /// `+1` when the reference is the control log (other time = ref − d),
    /// `−1` when it is the navigation log (other time = ref + d).
    sign: f64,
    /// Prefilter reach (s): samples closer to an end see a one-sided kernel.
    reach: f64,
    /// Reference median interval (s).
    dt_ref: f64,
    sigma: f64,
}

/// The refined offset and the statistics of the mismatch at it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Refined {
    /// Offset added to navigation stamps (s).
    pub offset_s: f64,
    /// Standard error of the offset (s).
    pub std_error_s: f64,
    /// RMS of `reference − other − mean` at the offset, raw samples
    /// (shared-channel unit).
    pub residual_rms: f64,
    /// `residual_rms` over the standard deviation of the raw reference.
    pub residual_relative: f64,
    /// Mean reference time of the samples used (reference clock).
    pub t_mid: f64,
}

fn mean(x: &[f64]) -> f64 {
    x.iter().sum::<f64>() / x.len().max(1) as f64
}

impl<'a> Pairing<'a> {
    /// Pairs the two logs with a prefilter of width `sigma` (s): the log
    /// with the longer median interval is the reference (the control log on
    /// a tie). Inputs must be validated (≥ 16 increasing stamps each).
    pub(crate) fn new(
        control_t: &'a [f64],
        control_x: &'a [f64],
        nav_t: &'a [f64],
        nav_x: &'a [f64],
        sigma: f64,
    ) -> Self {
        let dt_c = median_dt(control_t).unwrap_or(1.0);
        let dt_n = median_dt(nav_t).unwrap_or(1.0);
        let (ref_t, ref_x, other_t, other_x, sign, dt_ref) = if dt_c >= dt_n {
            (control_t, control_x, nav_t, nav_x, 1.0, dt_c)
        } else {
            (nav_t, nav_x, control_t, control_x, -1.0, dt_n)
        };
        let (ref_mean, other_mean) = (mean(ref_x), mean(other_x));
        let (o0, o1) = (other_t[0], other_t[other_t.len() - 1]);
        // Four points per σ (the prefiltered record is smooth on that
        // scale), never more than 8 per sample on average (bursty stamps).
        let step = (0.25 * sigma).max((o1 - o0) / (8.0 * other_t.len() as f64));
        let n_fine = (((o1 - o0) / step).floor() as usize).saturating_add(1);
        let fine_t: Vec<f64> = (0..n_fine).map(|k| o0 + k as f64 * step).collect();
        let fine_x = smooth(other_t, other_x, other_mean, sigma, fine_t.iter().copied());
        Pairing {
            ref_t,
            ref_y: smooth(ref_t, ref_x, ref_mean, sigma, ref_t.iter().copied()),
            ref_raw: ref_x.iter().map(|v| v - ref_mean).collect(),
            other: Hermite::new(&fine_t, &fine_x, 0.0),
            other_raw: Hermite::new(other_t, other_x, other_mean),
            other_span: (o0, o1),
            sign,
            reach: SUPPORT * sigma,
            dt_ref,
            sigma,
        }
    }

    /// Reference samples whose mapped time stays inside the other log for
    /// every offset in `d0 ± half_width`, with both prefilters clear of the
    /// ends of the logs.
    pub(crate) fn usable(&self, d0: f64, half_width: f64) -> Range<usize> {
        let (o0, o1) = self.other_span;
        let (r0, r1) = (self.ref_t[0], self.ref_t[self.ref_t.len() - 1]);
        let lo = (o0 + self.sign * d0 + half_width + self.reach).max(r0 + self.reach);
        let hi = (o1 + self.sign * d0 - half_width - self.reach).min(r1 - self.reach);
        let a = self.ref_t.partition_point(|&t| t < lo);
        let b = self.ref_t.partition_point(|&t| t <= hi);
        a..b.max(a)
    }

    fn fill(&self, range: &Range<usize>, d: f64, u: &mut Vec<f64>, du: Option<&mut Vec<f64>>) {
        let mut cur = Cursor::default();
        u.clear();
        let times = self.ref_t[range.clone()].iter().map(|&t| t - self.sign * d);
        match du {
            Some(du) => {
                du.clear();
                for s in times {
                    let (v, dv) = self.other.eval(s, &mut cur);
                    u.push(v);
                    du.push(dv);
                }
            }
            None => u.extend(times.map(|s| self.other.eval(s, &mut cur).0)),
        }
    }

    /// Centered second moments (Σ(u−ū)², Σ(u−ū)(y−ȳ), Σ(y−ȳ)²) and means.
    fn moments(u: &[f64], y: &[f64]) -> ([f64; 3], f64, f64) {
        let (mu, my) = (mean(u), mean(y));
        let mut m = [0.0; 3];
        for (a, b) in u.iter().zip(y) {
            let (du, dy) = (a - mu, b - my);
            m[0] += du * du;
            m[1] += du * dy;
            m[2] += dy * dy;
        }
        (m, mu, my)
    }

    /// The mismatch `J(d)` over `range`, using `u` as scratch.
    fn mismatch(&self, range: &Range<usize>, d: f64, u: &mut Vec<f64>) -> f64 {
        self.fill(range, d, u, None);
        let (m, _, _) = Self::moments(u, &self.ref_y[range.clone()]);
        let n = range.len() as f64;
        if m[0] > 0.0 {
            (m[2] - m[1] * m[1] / m[0]).max(0.0) / n
        } else {
            m[2] / n
        }
    }

    /// Minimizes the mismatch over `d0 ± half_width` using the reference
    /// samples `range` (from [`Pairing::usable`] with at least that width).
    ///
    /// # Errors
    /// [`AlignError::InsufficientOverlap`] under 8 samples,
    /// [`AlignError::FlatSignal`] when either side is constant over them.
    pub(crate) fn refine(
        &self,
        range: Range<usize>,
        d0: f64,
        half_width: f64,
        field: &str,
    ) -> Result<Refined, AlignError> {
        let n = range.len();
        if n < 8 {
            return Err(AlignError::overlap(
                field,
                format!(
                    "the logs overlap by only {n} usable samples of the slower log; alignment needs more"
                ),
            ));
        }
        let y = &self.ref_y[range.clone()];
        let mut u = Vec::with_capacity(n);
        // Minimize over the departure from d0: clock origins may differ by
        // 1e9 s, far beyond the relative tolerance of the search.
        let (delta, j0) = brent::minimize(
            |e| self.mismatch(&range, d0 + e, &mut u),
            -half_width,
            half_width,
            1e-6 * half_width,
            200,
        );
        let d = d0 + delta;
        let mut du = Vec::with_capacity(n);
        self.fill(&range, d, &mut u, Some(&mut du));
        let (m, mu, my) = Self::moments(&u, y);
        let scale = 1e-12 * (1.0 + my.abs() + mu.abs());
        if m[0] <= scale * scale * n as f64 || m[2] <= scale * scale * n as f64 {
            return Err(AlignError::flat(
                field,
                "the shared channel does not change while the logs overlap; alignment needs a signal both computers saw vary, e.g. a depth change",
            ));
        }
        let gain = m[1] / m[0];
        let bias = my - gain * mu;
        let r: Vec<f64> = u.iter().zip(y).map(|(a, b)| b - gain * a - bias).collect();
        // Model derivative with respect to d, projected off span{1, u}.
        let z: Vec<f64> = du.iter().map(|v| -self.sign * gain * v).collect();
        let mz = mean(&z);
        let beta = z
            .iter()
            .zip(&u)
            .map(|(a, b)| (a - mz) * (b - mu))
            .sum::<f64>()
            / m[0];
        let w: Vec<f64> = z
            .iter()
            .zip(&u)
            .map(|(a, b)| (a - mz) - beta * (b - mu))
            .collect();
        // Curvature of J at its minimum; Gauss–Newton if the difference is
        // not positive (flat or noisy minimum).
        let step = 0.25 * self.sigma;
        let jp = self.mismatch(&range, d + step, &mut u);
        let jm = self.mismatch(&range, d - step, &mut u);
        let curvature = (jp - 2.0 * j0 + jm) / (step * step);
        let info_gn: f64 = w.iter().map(|v| v * v).sum();
        let info = if curvature > 0.0 {
            0.5 * n as f64 * curvature
        } else {
            info_gn
        };
        let lags = ((n as f64).cbrt().ceil() + (2.0 * self.reach / self.dt_ref).ceil()) as usize;
        let std_error_s = (newey_west(&w, &r, lags) / (info * info)).sqrt();

        let mut cur = Cursor::default();
        let e: Vec<f64> = self.ref_t[range.clone()]
            .iter()
            .zip(&self.ref_raw[range.clone()])
            .map(|(&t, b)| b - self.other_raw.eval(t - self.sign * d, &mut cur).0)
            .collect();
        let me = mean(&e);
        let residual_rms = (e.iter().map(|v| (v - me).powi(2)).sum::<f64>() / n as f64).sqrt();
        let raw = &self.ref_raw[range.clone()];
        let mr = mean(raw);
        let ref_std = (raw.iter().map(|v| (v - mr).powi(2)).sum::<f64>() / n as f64).sqrt();
        Ok(Refined {
            offset_s: d,
            std_error_s: if std_error_s.is_finite() {
                std_error_s
            } else {
                f64::MAX
            },
            residual_rms,
            residual_relative: residual_rms / ref_std,
            t_mid: mean(&self.ref_t[range]),
        })
    }
}

/// Newey–West long-run variance of the score `Σ w_k r_k` (Bartlett kernel
/// over `lags` lags, at most half the samples).
fn newey_west(w: &[f64], r: &[f64], lags: usize) -> f64 {
    let s: Vec<f64> = w.iter().zip(r).map(|(a, b)| a * b).collect();
    let n = s.len();
    let lags = lags.min(n / 2);
    let mut total: f64 = s.iter().map(|v| v * v).sum();
    for l in 1..=lags {
        let weight = 1.0 - l as f64 / (lags as f64 + 1.0);
        let c: f64 = s[l..].iter().zip(&s).map(|(a, b)| a * b).sum();
        total += 2.0 * weight * c;
    }
    total.max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_a_noise_free_offset_with_either_reference() {
        let f = |t: f64| (0.3 * t).sin() + 0.5 * (0.11 * t + 1.0).sin();
        let d = 0.437;
        // Control 10 Hz, nav 25 Hz: reference = control.
        let tc: Vec<f64> = (0..600).map(|k| k as f64 * 0.1).collect();
        let xc: Vec<f64> = tc.iter().map(|&t| f(t)).collect();
        let tn: Vec<f64> = (0..1500).map(|k| k as f64 * 0.04 - d).collect();
        let xn: Vec<f64> = tn.iter().map(|&t| 2.0 + 1.1 * f(t + d)).collect();
        for sigma in [0.04, 0.3] {
            let p = Pairing::new(&tc, &xc, &tn, &xn, sigma);
            let r = p.refine(p.usable(0.4, 0.15), 0.4, 0.15, "x").unwrap();
            assert!((r.offset_s - d).abs() < 1e-4, "{sigma}: {r:?}");
        }
        // Nav 5 Hz: reference = nav.
        let tn: Vec<f64> = (0..300).map(|k| k as f64 * 0.2 - d).collect();
        let xn: Vec<f64> = tn.iter().map(|&t| f(t + d)).collect();
        let p = Pairing::new(&tc, &xc, &tn, &xn, 0.1);
        let r = p.refine(p.usable(0.4, 0.15), 0.4, 0.15, "x").unwrap();
        assert!((r.offset_s - d).abs() < 1e-5, "{r:?}");
        assert!(r.residual_relative < 1e-3, "{r:?}");
    }

    #[test]
    fn newey_west_sums_products_with_bartlett_weights() {
        let w = [1.0, -1.0, 1.0, -1.0, 1.0, -1.0, 1.0, -1.0];
        let r = [1.0; 8];
        // Lag 0 gives 8; lag 1 (weight 1/2) adds 2·½·(−7) = −7.
        assert!((newey_west(&w, &r, 1) - 1.0).abs() < 1e-12);
        assert_eq!(newey_west(&w, &[0.0; 8], 3), 0.0);
    }
}
