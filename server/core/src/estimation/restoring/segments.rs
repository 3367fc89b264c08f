//! Steady segments of a static run: the vehicle holds station (ν ≈ 0) at a
//! constant attitude with a constant thrust τ for several seconds, so that
//! M·ν̇ + (C(ν) + D(ν))·ν vanishes and τ = g(η) (thesis eq. 2.1).

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::error::RestoringError;
use crate::timeseries::median;

/// A record of a static run on a uniform grid.
#[derive(Debug, Clone, Copy)]
pub struct StaticRecord<'a> {
    /// Sample time h (s).
    pub h: f64,
    /// Body velocities ν = [u v w p q r] (m/s, rad/s), N × 6.
    pub nu: &'a DMatrix<f64>,
    /// Positions and Euler angles η = [x y z φ θ ψ] (m, rad), N × 6.
    pub eta: &'a DMatrix<f64>,
    /// Generalized forces τ = [X Y Z K M N] (N, N·m), N × 6.
    pub tau: &'a DMatrix<f64>,
}

/// What counts as steady.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct SteadySettings {
    /// Largest |u|, |v|, |w| of a steady sample (m/s).
    #[serde(default = "default_linear")]
    pub max_linear_speed_m_s: f64,
    /// Largest |p|, |q|, |r| of a steady sample (rad/s).
    #[serde(default = "default_angular")]
    pub max_angular_rate_rad_s: f64,
    /// Largest deviation of φ and θ from the segment mean (rad).
    #[serde(default = "default_angle")]
    pub max_angle_deviation_rad: f64,
    /// Largest deviation of each τ component from the segment mean (N,
    /// N·m); `None` for 5 × the record's own thrust noise (robust scale of
    /// τ about its 1-s running median over the quiet samples).
    #[serde(default)]
    pub tau_tolerance: Option<[f64; 6]>,
    /// Shortest segment kept (s).
    #[serde(default = "default_duration")]
    pub min_duration_s: f64,
}

fn default_linear() -> f64 {
    0.05
}
fn default_angular() -> f64 {
    0.01
}
fn default_angle() -> f64 {
    1f64.to_radians()
}
fn default_duration() -> f64 {
    5.0
}

impl Default for SteadySettings {
    fn default() -> Self {
        SteadySettings {
            max_linear_speed_m_s: default_linear(),
            max_angular_rate_rad_s: default_angular(),
            max_angle_deviation_rad: default_angle(),
            tau_tolerance: None,
            min_duration_s: default_duration(),
        }
    }
}

/// Thrust noise tolerances are this many robust standard deviations.
const TOLERANCE_SIGMAS: f64 = 5.0;
/// Half-width of the running median that τ noise is measured against (s).
const NOISE_WINDOW_S: f64 = 1.0;
/// MAD → standard deviation for Gaussian noise.
const MAD_TO_STD: f64 = 1.482_602_218_505_602;

/// One steady segment and the means the fit uses.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct SteadySegment {
    /// Index of the record in the list given.
    pub record: usize,
    /// First sample.
    pub start: usize,
    /// One past the last sample.
    pub end: usize,
    /// Start time from the record start (s).
    pub start_s: f64,
    /// Duration (s).
    pub duration_s: f64,
    /// Mean roll φ (deg).
    pub roll_deg: f64,
    /// Mean pitch θ (deg).
    pub pitch_deg: f64,
    /// Mean τ (N, N·m).
    pub tau_mean: [f64; 6],
    /// Standard deviation of τ within the segment (N, N·m).
    pub tau_std: [f64; 6],
    /// Means of the regressors of g(η): [sθ, cθ·sφ, cθ·cφ]. τ is linear in
    /// the parameters, so averaging both sides keeps τ̄ = g(η)‾ exact.
    pub regressors: [f64; 3],
}

pub(crate) fn check_record(rec: &StaticRecord<'_>) -> Result<usize, RestoringError> {
    if !(rec.h.is_finite() && rec.h > 0.0) {
        return Err(RestoringError::invalid(
            "h",
            format!("sample time must be finite and > 0, got {}", rec.h),
        ));
    }
    let n = rec.tau.nrows();
    for (field, m) in [("nu", rec.nu), ("eta", rec.eta), ("tau", rec.tau)] {
        if m.ncols() != 6 {
            return Err(RestoringError::invalid(
                field,
                format!("needs 6 columns in Fossen's order, has {}", m.ncols()),
            ));
        }
        if m.nrows() != n {
            return Err(RestoringError::invalid(
                field,
                format!("has {} rows, tau has {n}", m.nrows()),
            ));
        }
        if let Some(i) = (0..n).find(|&i| m.row(i).iter().any(|v| !v.is_finite())) {
            return Err(RestoringError::non_finite(field, i));
        }
    }
    Ok(n)
}

fn check_settings(s: &SteadySettings) -> Result<(), RestoringError> {
    let positive = [
        (
            "settings.steady.max_linear_speed_m_s",
            s.max_linear_speed_m_s,
        ),
        (
            "settings.steady.max_angular_rate_rad_s",
            s.max_angular_rate_rad_s,
        ),
        (
            "settings.steady.max_angle_deviation_rad",
            s.max_angle_deviation_rad,
        ),
        ("settings.steady.min_duration_s", s.min_duration_s),
    ];
    for (field, v) in positive {
        if !(v.is_finite() && v > 0.0) {
            return Err(RestoringError::invalid(
                field,
                format!("must be finite and > 0, got {v}"),
            ));
        }
    }
    if let Some(t) = s.tau_tolerance
        && t.iter().any(|v| !(v.is_finite() && *v > 0.0))
    {
        return Err(RestoringError::invalid(
            "settings.steady.tau_tolerance",
            "every entry must be finite and > 0",
        ));
    }
    Ok(())
}

/// The steady segments of one record (`index` labels them), in time order.
pub fn find_steady_segments(
    rec: &StaticRecord<'_>,
    index: usize,
    settings: &SteadySettings,
) -> Result<Vec<SteadySegment>, RestoringError> {
    let n = check_record(rec)?;
    check_settings(settings)?;
    let quiet: Vec<bool> = (0..n)
        .map(|t| {
            (0..6).all(|j| {
                let limit = if j < 3 {
                    settings.max_linear_speed_m_s
                } else {
                    settings.max_angular_rate_rad_s
                };
                rec.nu[(t, j)].abs() <= limit
            })
        })
        .collect();
    let tol = settings
        .tau_tolerance
        .unwrap_or_else(|| noise_tolerance(rec, &quiet));
    let min_len = (settings.min_duration_s / rec.h).ceil() as usize;
    let mut out = Vec::new();
    let mut t = 0;
    while t < n {
        if !quiet[t] {
            t += 1;
            continue;
        }
        // Grow a segment while the sample stays near the segment's mean.
        let start = t;
        let mut sum = [0.0; 8];
        let mut count = 0.0;
        while t < n && quiet[t] {
            let row = sample(rec, t);
            if count > 0.0 {
                let fits = (0..8).all(|j| {
                    let limit = if j < 6 {
                        tol[j]
                    } else {
                        settings.max_angle_deviation_rad
                    };
                    (row[j] - sum[j] / count).abs() <= limit
                });
                if !fits {
                    break;
                }
            }
            for j in 0..8 {
                sum[j] += row[j];
            }
            count += 1.0;
            t += 1;
        }
        if t - start >= min_len.max(2) {
            out.push(summarize(rec, index, start, t));
        }
    }
    Ok(out)
}

/// τ (6) then φ, θ of sample t.
fn sample(rec: &StaticRecord<'_>, t: usize) -> [f64; 8] {
    let mut row = [0.0; 8];
    for (j, r) in row.iter_mut().enumerate().take(6) {
        *r = rec.tau[(t, j)];
    }
    row[6] = rec.eta[(t, 3)];
    row[7] = rec.eta[(t, 4)];
    row
}

fn summarize(rec: &StaticRecord<'_>, index: usize, start: usize, end: usize) -> SteadySegment {
    let len = (end - start) as f64;
    let mut tau_mean = [0.0; 6];
    let mut tau_std = [0.0; 6];
    for j in 0..6 {
        let col = rec.tau.column(j);
        let xs = &col.as_slice()[start..end];
        let m = xs.iter().sum::<f64>() / len;
        tau_mean[j] = m;
        tau_std[j] = (xs.iter().map(|v| (v - m).powi(2)).sum::<f64>() / len).sqrt();
    }
    let mut regressors = [0.0; 3];
    let (mut phi, mut theta) = (0.0, 0.0);
    for t in start..end {
        let (sphi, cphi) = rec.eta[(t, 3)].sin_cos();
        let (sth, cth) = rec.eta[(t, 4)].sin_cos();
        regressors[0] += sth / len;
        regressors[1] += cth * sphi / len;
        regressors[2] += cth * cphi / len;
        phi += rec.eta[(t, 3)] / len;
        theta += rec.eta[(t, 4)] / len;
    }
    SteadySegment {
        record: index,
        start,
        end,
        start_s: start as f64 * rec.h,
        duration_s: len * rec.h,
        roll_deg: phi.to_degrees(),
        pitch_deg: theta.to_degrees(),
        tau_mean,
        tau_std,
        regressors,
    }
}

/// 5 × the robust noise scale of each τ component: 1.4826 × the median
/// absolute deviation from a centred running median (robust to the steps
/// between holds), over the quiet samples. Floored so that noise-free data
/// still tolerate rounding.
fn noise_tolerance(rec: &StaticRecord<'_>, quiet: &[bool]) -> [f64; 6] {
    let n = quiet.len();
    let w = ((NOISE_WINDOW_S / rec.h).round() as usize).max(1);
    let mut tol = [0.0; 6];
    for (j, t_j) in tol.iter_mut().enumerate() {
        let col = rec.tau.column(j);
        let x = col.as_slice();
        let mut dev: Vec<f64> = (0..n)
            .filter(|&t| quiet[t])
            .map(|t| {
                let mut win: Vec<f64> = x[t.saturating_sub(w)..(t + w + 1).min(n)].to_vec();
                (x[t] - median(&mut win)).abs()
            })
            .collect();
        let scale = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let floor = 1e-9 * (1.0 + scale);
        *t_j = if dev.is_empty() {
            floor
        } else {
            (TOLERANCE_SIGMAS * MAD_TO_STD * median(&mut dev)).max(floor)
        };
    }
    tol
}
