//! Settings of the λ-filter campaign identification
//! ([`super::lambda_campaign::identify_lambda_campaign`]): the model's
//! structure and scheduling, and which physics it estimates or carries.

use serde::{Deserialize, Serialize};

use super::error::IdentifyError;
use crate::planning::dof::Dof;

/// The coupling structure to identify.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum StructureChoice {
    /// Port–starboard symmetry (default for 6-DOF and 3-DOF vessels) plus
    /// any pair the partial coherence between DOFs proposes; for other DOF
    /// sets the coherence proposal alone.
    #[default]
    Auto,
    /// Port–starboard (xz-plane) symmetry: surge, heave and pitch couple
    /// among themselves, sway, roll and yaw among themselves (Fossen 2011,
    /// sec. 7.5: the longitudinal and lateral subsystems).
    Symmetric,
    /// Each DOF alone (the thesis's first, uncoupled LPV model).
    Diagonal,
    /// Every entry of A and B free.
    Coupled,
    /// The user's pattern in `settings.coupling` (rows: ν_i, columns: DOFs).
    Custom,
}

/// How predictions schedule between grid points.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum SchedulingChoice {
    /// Nearest grid point (thesis eq. 2.17).
    Nearest,
    /// Blend of the neighbouring sub-models (eq. 2.18).
    #[default]
    Interpolate,
}

/// Settings of a λ-filter identification (JSON `settings` of the job).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct LambdaCampaignSettings {
    /// Coupling structure.
    #[serde(default)]
    pub structure: StructureChoice,
    /// Free entries for `custom`: n × n booleans in the order of the vessel's DOFs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coupling: Option<Vec<Vec<bool>>>,
    /// Partial-coherence threshold of the `auto` proposal (0–1).
    #[serde(default = "default_threshold")]
    pub coupling_threshold: f64,
    /// Time constant T of λ(s) = 1/(1+sT) (s); default: half the shortest
    /// expected time constant of the vessel, at least 5 samples.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub t_lambda_s: Option<f64>,
    /// Held-out runs; default: the plan's validation runs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub validation_run_ids: Option<Vec<String>>,
    /// Horizon of the k-step predictions of validation.
    #[serde(default = "default_k")]
    pub k: usize,
    /// Scheduling of predictions on forward speed.
    #[serde(default)]
    pub scheduling: SchedulingChoice,
    /// Estimate g(η) (W − B, z_G·W − z_B·B) jointly with M and D̄ from every
    /// run where the attitude moves, sharpened by static attitude holds when
    /// there are any (6-DOF vessels).
    #[serde(default = "default_true")]
    pub estimate_restoring: bool,
    /// Estimate a constant load b per DOF and grid point (tether, the heave
    /// part of W − B, the offset of the damping's linearization at speed).
    #[serde(default = "default_true")]
    pub constant_loads: bool,
    /// Take the couplings of C(ν)ν at the grid speed from the estimated M
    /// (Fossen 2011, eq. 6.43; 6-DOF and 3-DOF horizontal models), so the
    /// structure constrains the damping D and D̄ = D + J_C(M, u₀).
    #[serde(default = "default_true")]
    pub coriolis_from_m: bool,
    /// Rate of the vehicle's feedback controller (Hz); default: the vessel
    /// profile's `controller_rate_hz`. When it runs faster than the log
    /// (e.g. a 20 Hz loop logged at 10 Hz), M and D̄ are corrected for the
    /// commands the log does not show, with the controller's gains read
    /// from the log (see `intersample`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub controller_rate_hz: Option<f64>,
    /// Extend the model a short way below its lowest grid speed (up to 0.6
    /// of the first spacing, not below 0 m/s, as far as it stays physical
    /// and stable: damping extrapolated linearly in speed, the load
    /// quadratically) instead of holding the lowest sub-model there
    /// (thesis). Interpolated scheduling on three or more grid speeds.
    #[serde(default = "default_true")]
    pub extend_below_grid: bool,
    /// Extend the model a short way above its highest grid speed likewise
    /// (up to 0.6 of the last spacing, as far as it stays physical and no
    /// less stable than the top sub-model) instead of holding the highest
    /// sub-model there.
    #[serde(default = "default_true")]
    pub extend_above_grid: bool,
    /// Fit M symmetric: the rows of each sub-model re-estimated under
    /// M = Mᵀ by least squares over their joint uncertainty, with σ scaled
    /// by how far the unconstrained rows were from it. Off: the rows fitted
    /// freely and the nearest symmetric M stored with D̄ unchanged, which
    /// on the independent truth cost up to 0.5 of yaw free-run fit.
    #[serde(default = "default_true")]
    pub symmetric_inertia: bool,
    /// Carry the second-order Coriolis–centripetal force C(δ)δ of the
    /// estimated M in the model (δ = ν about straight-ahead motion at the
    /// scheduled speed): the centripetal forces of turning, heaving and
    /// rolling that no linear sub-model holds, with no parameter added
    /// (models with a surge DOF).
    #[serde(default = "default_true")]
    pub coriolis_second_order: bool,
    /// Estimate diagonal quadratic damping D_q|δ|δ with M and D̄: hull
    /// damping grows with the motion's amplitude, which no linear
    /// sub-model follows (in surge, X_|u|u as the remainder beyond each
    /// grid point's tangent, which the sub-models' D̄ and load carry).
    /// Entries the data find negative or within 2σ of zero are left out,
    /// with a note. The model applies it linearly implicit over each step,
    /// so even a D_q far larger than the motion supports (a DOF barely
    /// moved) damps and cannot diverge. On the independent truth it lifts
    /// the free runs where damping is largely quadratic (yaw 0.892 → 0.967)
    /// and below the grid (surge 0.928 → 0.972, heave 0.813 → 0.913 on
    /// vessel 5), keeps 97–100 % of parameters within ±3σ, and meets the
    /// fit criteria on all 12 seeded vessels (9 without). False: linear
    /// damping only (the thesis's model).
    #[serde(default = "default_true")]
    pub quadratic_damping: bool,
    /// Estimate one current fixed in NED for the campaign, acting through
    /// the damping of the velocity through the water ν_r = ν − ν_c(ψ), and
    /// keep it when the data hold it beyond their noise (χ² of no current
    /// above its 99 % point). Needs surge, sway and yaw modelled and the
    /// heading `psi` logged on every run; predictions then integrate ψ from
    /// the model's own rates. Absent: on for horizontal models (surge, sway,
    /// yaw; a surface vessel), off for models with heave, roll or pitch (an
    /// ROV: discovery tests a current there by identifying again with it).
    /// True: on for any model with surge, sway and yaw. False: constant
    /// loads only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ned_current: Option<bool>,
}

fn default_threshold() -> f64 {
    0.2
}
fn default_k() -> usize {
    10
}
fn default_true() -> bool {
    true
}

impl Default for LambdaCampaignSettings {
    fn default() -> Self {
        LambdaCampaignSettings {
            structure: StructureChoice::Auto,
            coupling: None,
            coupling_threshold: default_threshold(),
            t_lambda_s: None,
            validation_run_ids: None,
            k: default_k(),
            scheduling: SchedulingChoice::Interpolate,
            estimate_restoring: true,
            constant_loads: true,
            coriolis_from_m: true,
            controller_rate_hz: None,
            extend_below_grid: true,
            extend_above_grid: true,
            symmetric_inertia: true,
            coriolis_second_order: true,
            quadratic_damping: true,
            ned_current: None,
        }
    }
}

impl LambdaCampaignSettings {
    /// Whether the NED current is estimated for a model of `dofs` (see
    /// [`LambdaCampaignSettings::ned_current`]).
    pub fn ned_current_for(&self, dofs: &[Dof]) -> bool {
        match self.ned_current {
            None => super::ned_current::applies(dofs),
            Some(on) => on && super::ned_current::possible(dofs),
        }
    }

    /// Settings a campaign of `n_inputs` input columns for `n` DOFs on
    /// `grid` can run with; the error names the offending field.
    pub(crate) fn check(
        &self,
        n_inputs: usize,
        n: usize,
        grid: &[f64],
    ) -> Result<(), IdentifyError> {
        if n_inputs != n {
            return Err(IdentifyError::invalid(
                "inputs",
                format!("{n_inputs} input columns for {n} DOFs"),
            ));
        }
        if grid.is_empty() {
            return Err(IdentifyError::invalid(
                "campaign.grid",
                "the campaign has no grid speeds",
            ));
        }
        if !(self.coupling_threshold > 0.0 && self.coupling_threshold < 1.0) {
            return Err(IdentifyError::invalid(
                "settings.coupling_threshold",
                format!("must be in (0, 1), got {}", self.coupling_threshold),
            ));
        }
        if let Some(rate) = self.controller_rate_hz
            && !(rate.is_finite() && rate > 0.0)
        {
            return Err(IdentifyError::invalid(
                "settings.controller_rate_hz",
                format!("must be a positive rate in Hz, got {rate}"),
            ));
        }
        if self.k == 0 {
            return Err(IdentifyError::invalid(
                "settings.k",
                "the horizon k must be ≥ 1",
            ));
        }
        Ok(())
    }
}
