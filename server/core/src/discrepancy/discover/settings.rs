//! What [`discover`](super::discover) is told: the filter, the search's limits, the library and the vessel.

use serde::{Deserialize, Serialize};

use crate::discrepancy::candidates::LibrarySettings;
use crate::discrepancy::error::DiscoveryError;
use crate::planning::VesselProfile;

/// Settings of [`discover`]. Defaults suit a 10 Hz ROV log.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(default)]
pub struct DiscoverySettings {
    /// T of the state-variable filter λ(s) = 1/(1+sT) (s).
    pub svf_time_constant_s: f64,
    /// k of the k-step predictions (thesis: 10).
    pub k_step: usize,
    /// Bartlett window of the HAC covariance (s).
    pub hac_window_s: f64,
    /// Least significance z of a term.
    pub min_z: f64,
    /// Largest ΔBIC of a term (negative: evidence for it).
    pub max_delta_bic: f64,
    /// Least held-out free-run fit gain (summed over channels) to accept a term.
    pub min_cv_gain: f64,
    /// Least size of a term's force against the command in its DOF (RMS
    /// over RMS, λ-filtered, on the estimation runs): below it a term is
    /// too small to matter, however significant.
    pub min_force_share: f64,
    /// A look-alike whose held-out gain reaches this share of the winner's is
    /// reported as ambiguous.
    pub ambiguity_ratio: f64,
    /// Most terms added.
    pub max_terms: usize,
    /// Candidates cross-validated per step.
    pub cv_candidates: usize,
    /// Longest actuator lag searched (s).
    pub max_lag_s: f64,
    /// Longest input delay searched (s).
    pub max_delay_s: f64,
    /// Segment length of the location report (s).
    pub segment_s: f64,
    /// Window of the test whether a fitted current is constant (s).
    pub drift_window_s: f64,
    /// Points per plot series.
    pub plot_points: usize,
    /// Candidate families.
    pub library: LibrarySettings,
    /// The vessel, for deciding-experiment proposals within its limits.
    pub vessel: Option<VesselProfile>,
}

impl Default for DiscoverySettings {
    fn default() -> Self {
        DiscoverySettings {
            svf_time_constant_s: 0.5,
            k_step: 10,
            hac_window_s: 3.0,
            min_z: 4.0,
            max_delta_bic: -10.0,
            min_cv_gain: 0.01,
            min_force_share: 0.02,
            ambiguity_ratio: 0.8,
            max_terms: 4,
            cv_candidates: 5,
            max_lag_s: 3.0,
            max_delay_s: 1.0,
            segment_s: 30.0,
            drift_window_s: 15.0,
            plot_points: 400,
            library: LibrarySettings::default(),
            vessel: None,
        }
    }
}

impl DiscoverySettings {
    pub(crate) fn validate(&self) -> Result<(), DiscoveryError> {
        let pos = |name: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(DiscoveryError::invalid(
                    format!("settings.{name}"),
                    "must be finite and > 0",
                ))
            }
        };
        pos("svf_time_constant_s", self.svf_time_constant_s)?;
        pos("hac_window_s", self.hac_window_s)?;
        pos("min_z", self.min_z)?;
        pos("max_lag_s", self.max_lag_s)?;
        pos("max_delay_s", self.max_delay_s)?;
        pos("segment_s", self.segment_s)?;
        pos("drift_window_s", self.drift_window_s)?;
        pos("ambiguity_ratio", self.ambiguity_ratio)?;
        if !(self.min_force_share.is_finite() && (0.0..1.0).contains(&self.min_force_share)) {
            return Err(DiscoveryError::invalid(
                "settings.min_force_share",
                "must be in [0, 1)",
            ));
        }
        if !(self.min_cv_gain.is_finite() && self.max_delta_bic.is_finite()) {
            return Err(DiscoveryError::invalid(
                "settings.min_cv_gain",
                "must be finite",
            ));
        }
        if self.k_step == 0 || self.k_step > 1000 {
            return Err(DiscoveryError::invalid(
                "settings.k_step",
                "must be in 1..=1000",
            ));
        }
        if self.max_terms > 20 {
            return Err(DiscoveryError::invalid(
                "settings.max_terms",
                "must be at most 20",
            ));
        }
        if self.plot_points < 2 {
            return Err(DiscoveryError::invalid(
                "settings.plot_points",
                "must be at least 2",
            ));
        }
        if let Some(v) = &self.vessel {
            v.validate()
                .map_err(|e| DiscoveryError::invalid("settings.vessel", e.to_string()))?;
        }
        Ok(())
    }
}
