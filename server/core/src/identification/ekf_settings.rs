//! Settings of a parallel-EKF identification (the job's JSON `settings`),
//! with their defaults and checks; every refusal names the field.

use serde::{Deserialize, Serialize};

use super::error::IdentifyError;
use crate::simulation::dp_ship::N_THETA;

/// Settings of a parallel-EKF identification (JSON `settings` of the job).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct EkfCampaignSettings {
    /// Sweeps through SI1 → SI2 → SI3 (≥ 1): each further sweep restarts
    /// every stage from the previous sweep's θ̂.
    #[serde(default = "default_sweeps")]
    pub sweeps: usize,
    /// Standard deviation of the measured x and y (m).
    #[serde(default = "default_position_noise")]
    pub position_noise_std_m: f64,
    /// Standard deviation of the measured heading (degrees).
    #[serde(default = "default_heading_noise")]
    pub heading_noise_std_deg: f64,
    /// Initial guess of θ″1 … θ″9 (Bis: A″_h11, A″_h22, A″_h23, A″_h32,
    /// A″_h33, K″1 = K″2, K″3 = K″4, K″5, K″6); default: A″_h,ii = −√(L/g)/T_i
    /// from the profile's time constants, no coupling, K″ = 5·10⁻³.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub theta_init: Option<Vec<f64>>,
    /// Standard deviation of that guess (P(0) of θ″); default 0.1 (0.3 for
    /// A″_h33, or 1.2·|guess| if larger) for A″_h, 5·10⁻³ for K″.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub theta_init_std: Option<Vec<f64>>,
    /// Random-walk step of the bias b_h per sample (Bis force, surge, sway, yaw).
    #[serde(default = "default_bias_walk")]
    pub bias_walk_std_bis: [f64; 3],
    /// Standard deviation of the initial bias (Bis force).
    #[serde(default = "default_bias_initial")]
    pub bias_initial_std_bis: [f64; 3],
    /// Process noise on the momentum per sample (Bis); a little keeps the
    /// filter from locking on biased θ″ under position noise.
    #[serde(default = "default_momentum_noise")]
    pub momentum_noise_std_bis: f64,
    /// Parameter random walk per sample (eq. 38); 0 for constant θ″.
    #[serde(default)]
    pub q_theta: f64,
    /// Held-out runs; default: the plan's validation runs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub validation_run_ids: Option<Vec<String>>,
    /// Horizon of the k-step predictions of validation.
    #[serde(default = "default_k")]
    pub k: usize,
    /// After the staged EKF, refine all nine θ″ jointly on every estimation
    /// run by prediction error (maximum likelihood of the Kalman predictor's
    /// innovations) and report the calibrated std; `false`: the paper's
    /// staging alone (θ″ and std of the EKF).
    #[serde(default = "default_refine")]
    pub refine: bool,
}

fn default_refine() -> bool {
    true
}

fn default_sweeps() -> usize {
    2
}
fn default_position_noise() -> f64 {
    1.0
}
fn default_heading_noise() -> f64 {
    0.2
}
fn default_bias_walk() -> [f64; 3] {
    [3e-6, 3e-6, 6e-7]
}
fn default_bias_initial() -> [f64; 3] {
    [1e-3, 1e-3, 2e-4]
}
fn default_momentum_noise() -> f64 {
    1e-5
}
fn default_k() -> usize {
    10
}

impl Default for EkfCampaignSettings {
    fn default() -> Self {
        EkfCampaignSettings {
            sweeps: default_sweeps(),
            position_noise_std_m: default_position_noise(),
            heading_noise_std_deg: default_heading_noise(),
            theta_init: None,
            theta_init_std: None,
            bias_walk_std_bis: default_bias_walk(),
            bias_initial_std_bis: default_bias_initial(),
            momentum_noise_std_bis: default_momentum_noise(),
            q_theta: 0.0,
            validation_run_ids: None,
            k: default_k(),
            refine: default_refine(),
        }
    }
}

pub(crate) fn nine(
    field: &str,
    v: &Option<Vec<f64>>,
) -> Result<Option<[f64; N_THETA]>, IdentifyError> {
    let Some(v) = v else { return Ok(None) };
    let arr: [f64; N_THETA] = v.as_slice().try_into().map_err(|_| {
        IdentifyError::invalid(
            field,
            format!("θ″ has nine entries (θ″1 … θ″9), got {}", v.len()),
        )
    })?;
    if let Some(i) = arr.iter().position(|x| !x.is_finite()) {
        return Err(IdentifyError::invalid(
            format!("{field}[{i}]"),
            "must be a finite number",
        ));
    }
    Ok(Some(arr))
}

pub(crate) fn check_settings(s: &EkfCampaignSettings) -> Result<(), IdentifyError> {
    let pos = |field: &str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(IdentifyError::invalid(
                format!("settings.{field}"),
                format!("must be a positive number, got {v}"),
            ))
        }
    };
    let nonneg = |field: &str, v: f64| {
        if v.is_finite() && v >= 0.0 {
            Ok(())
        } else {
            Err(IdentifyError::invalid(
                format!("settings.{field}"),
                format!("must be a number ≥ 0, got {v}"),
            ))
        }
    };
    if s.sweeps == 0 || s.sweeps > 20 {
        return Err(IdentifyError::invalid(
            "settings.sweeps",
            format!("must be 1–20, got {}", s.sweeps),
        ));
    }
    if s.k == 0 {
        return Err(IdentifyError::invalid(
            "settings.k",
            "the horizon k must be ≥ 1",
        ));
    }
    pos("position_noise_std_m", s.position_noise_std_m)?;
    pos("heading_noise_std_deg", s.heading_noise_std_deg)?;
    for (i, &v) in s.bias_walk_std_bis.iter().enumerate() {
        nonneg(&format!("bias_walk_std_bis[{i}]"), v)?;
    }
    for (i, &v) in s.bias_initial_std_bis.iter().enumerate() {
        pos(&format!("bias_initial_std_bis[{i}]"), v)?;
    }
    nonneg("momentum_noise_std_bis", s.momentum_noise_std_bis)?;
    nonneg("q_theta", s.q_theta)?;
    if let Some(std) = nine("settings.theta_init_std", &s.theta_init_std)? {
        for (i, &v) in std.iter().enumerate() {
            pos(&format!("theta_init_std[{i}]"), v)?;
        }
    }
    nine("settings.theta_init", &s.theta_init)?;
    Ok(())
}
