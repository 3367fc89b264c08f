//! Least squares of τ̄ = g(η)‾ over steady segments (thesis eq. 2.1).
//!
//! The thesis averages τ_w/(cθ·cφ), τ_w/sθ and τ_q separately (eq.
//! 2.2–2.4); here every steady segment contributes all its equations to one
//! least-squares fit per unit group, which reduces to those averages in
//! their special cases, uses the roll and surge/sway equations too, and
//! gives standard deviations:
//!
//! - forces (N): X̄ = (W−B)·sθ‾, Ȳ = −(W−B)·(cθsφ)‾, Z̄ = −(W−B)·(cθcφ)‾;
//! - moments (N·m): K̄ = (z_G·W − z_B·B)·(cθsφ)‾,
//!   M̄ = (z_G·W − z_B·B)·sθ‾ + τ_θ.
//!
//! Each group's noise variance is estimated from its residuals (RSS/(rows −
//! parameters)), so the standard deviations cover thrust noise, current and
//! controller ripple as they show between segments.

use serde::{Deserialize, Serialize};

use super::error::RestoringError;
use super::params::RestoringParams;
use super::segments::{StaticRecord, SteadySegment, SteadySettings, find_steady_segments};

/// How the static runs are used.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct RestoringSettings {
    /// What counts as a steady segment.
    #[serde(default)]
    pub steady: SteadySettings,
    /// Fewest steady segments accepted (≥ 2: the moment fit has two
    /// parameters and needs a residual degree of freedom).
    #[serde(default = "default_min_segments")]
    pub min_segments: usize,
    /// Smallest RMS spread of the attitudes (sθ about its mean, plus
    /// cθ·sφ) that separates z_G·W − z_B·B from τ_θ, as an angle (rad).
    #[serde(default = "default_spread")]
    pub min_attitude_spread_rad: f64,
}

fn default_min_segments() -> usize {
    3
}
fn default_spread() -> f64 {
    2f64.to_radians()
}

impl Default for RestoringSettings {
    fn default() -> Self {
        RestoringSettings {
            steady: SteadySettings::default(),
            min_segments: default_min_segments(),
            min_attitude_spread_rad: default_spread(),
        }
    }
}

/// The estimate with its uncertainty and the data it rests on.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct RestoringEstimate {
    /// Estimated W − B, z_G·W − z_B·B and τ_θ.
    pub params: RestoringParams,
    /// One standard deviation of each parameter, same fields and units.
    pub std: RestoringParams,
    /// Correlation of the z_G·W − z_B·B and τ_θ estimates (near ±1 when the
    /// attitudes barely separate them).
    pub moment_correlation: f64,
    /// RMS of τ̄ − g(η)‾ over the segments, per DOF [X Y Z K M N] (N, N·m):
    /// large values point at forces the model lacks (e.g. tether pull in
    /// surge, x_G ≠ x_B in pitch, a yaw moment).
    pub residual_rms: [f64; 6],
    /// Residual degrees of freedom of the force and moment fits.
    pub dof: [usize; 2],
    /// The steady segments used.
    pub segments: Vec<SteadySegment>,
}

/// Find the steady segments of every record and fit g(η) to them. Records
/// are separate experiments, never concatenated.
pub fn estimate_restoring(
    records: &[StaticRecord<'_>],
    settings: &RestoringSettings,
) -> Result<RestoringEstimate, RestoringError> {
    if records.is_empty() {
        return Err(RestoringError::invalid("records", "no static record given"));
    }
    let mut segments = Vec::new();
    for (i, rec) in records.iter().enumerate() {
        segments.extend(find_steady_segments(rec, i, &settings.steady)?);
    }
    fit_restoring(segments, settings)
}

/// Fit g(η) to steady segments already found (or chosen by hand).
pub fn fit_restoring(
    segments: Vec<SteadySegment>,
    settings: &RestoringSettings,
) -> Result<RestoringEstimate, RestoringError> {
    let required = settings.min_segments.max(2);
    if !(settings.min_attitude_spread_rad.is_finite() && settings.min_attitude_spread_rad > 0.0) {
        return Err(RestoringError::invalid(
            "settings.min_attitude_spread_rad",
            "must be finite and > 0",
        ));
    }
    let n = segments.len();
    if n < required {
        return Err(RestoringError::TooFewSteadySegments {
            field: "segments".to_owned(),
            found: n,
            required,
            message: format!(
                "{n} steady segment{} found, {required} needed: hold station at several pitch \
                 angles (e.g. θ = −10°, 0°, +10°) for at least {} s each, thrusters only \
                 countering g(η) and the tether",
                if n == 1 { "" } else { "s" },
                settings.steady.min_duration_s
            ),
        });
    }
    let nf = n as f64;

    // Forces: one parameter W − B; each segment's regressor has unit norm.
    let a_force = |s: &SteadySegment| [s.regressors[0], -s.regressors[1], -s.regressors[2]];
    let (mut ata, mut aty) = (0.0, 0.0);
    for s in &segments {
        for (a, y) in a_force(s).iter().zip(&s.tau_mean[..3]) {
            ata += a * a;
            aty += a * y;
        }
    }
    let wb = aty / ata;

    // Moments: [bg, τ_θ]; roll rows (cθsφ, 0), pitch rows (sθ, 1). The
    // information on bg once τ_θ is eliminated decides identifiability.
    let mean_s = segments.iter().map(|s| s.regressors[0]).sum::<f64>() / nf;
    let info_bg: f64 = segments
        .iter()
        .map(|s| s.regressors[1].powi(2) + (s.regressors[0] - mean_s).powi(2))
        .sum();
    let spread = (info_bg / nf).sqrt();
    if spread < settings.min_attitude_spread_rad.sin() {
        return Err(not_identifiable(&segments, spread, settings));
    }
    let (mut s11, mut s12, mut s22, mut r1, mut r2) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for s in &segments {
        let (k_reg, m_reg) = (s.regressors[1], s.regressors[0]);
        s11 += k_reg * k_reg + m_reg * m_reg;
        s12 += m_reg;
        s22 += 1.0;
        r1 += k_reg * s.tau_mean[3] + m_reg * s.tau_mean[4];
        r2 += s.tau_mean[4];
    }
    let det = s11 * s22 - s12 * s12;
    let bg = (s22 * r1 - s12 * r2) / det;
    let tether = (s11 * r2 - s12 * r1) / det;
    let params = RestoringParams {
        weight_minus_buoyancy_n: wb,
        zg_weight_minus_zb_buoyancy_nm: bg,
        tether_pitch_moment_nm: tether,
    };

    // Residuals per DOF and per group.
    let mut sq = [0.0; 6];
    for s in &segments {
        let fitted = [
            wb * s.regressors[0],
            -wb * s.regressors[1],
            -wb * s.regressors[2],
            bg * s.regressors[1],
            bg * s.regressors[0] + tether,
            0.0,
        ];
        for j in 0..6 {
            sq[j] += (s.tau_mean[j] - fitted[j]).powi(2);
        }
    }
    let dof = [3 * n - 1, 2 * n - 2];
    let var_f = (sq[0] + sq[1] + sq[2]) / dof[0] as f64;
    let var_m = (sq[3] + sq[4]) / dof[1] as f64;
    let std = RestoringParams {
        weight_minus_buoyancy_n: (var_f / ata).sqrt(),
        zg_weight_minus_zb_buoyancy_nm: (var_m * s22 / det).sqrt(),
        tether_pitch_moment_nm: (var_m * s11 / det).sqrt(),
    };
    Ok(RestoringEstimate {
        params,
        std,
        moment_correlation: -s12 / (s11 * s22).sqrt(),
        residual_rms: sq.map(|v| (v / nf).sqrt()),
        dof,
        segments,
    })
}

fn not_identifiable(
    segments: &[SteadySegment],
    spread: f64,
    settings: &RestoringSettings,
) -> RestoringError {
    let range = |f: fn(&SteadySegment) -> f64| {
        segments
            .iter()
            .map(f)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            })
    };
    let (t0, t1) = range(|s| s.pitch_deg);
    let (p0, p1) = range(|s| s.roll_deg);
    RestoringError::NotIdentifiable {
        field: "eta.theta".to_owned(),
        message: format!(
            "the {} steady segments hold θ within {:.1}°…{:.1}° and φ within {:.1}°…{:.1}° \
             (attitude spread {:.2}°, {:.2}° needed), so z_G·W − z_B·B cannot be separated \
             from the tether pitch moment τ_θ. Missing experiment: static holds at two or more \
             pitch angles (e.g. θ = −10°, 0°, +10°) or at a roll angle (e.g. φ = ±10°)",
            segments.len(),
            t0,
            t1,
            p0,
            p1,
            spread.asin().to_degrees(),
            settings.min_attitude_spread_rad.to_degrees()
        ),
    }
}
