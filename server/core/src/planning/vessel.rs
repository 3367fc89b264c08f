//! Vessel profiles: what the vessel is, which DOFs are modeled, how it is
//! actuated (τ per DOF, or thruster commands through τ = T K u, eq. 4/7 of
//! Fossen et al.), and the limits the pilots give.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::dof::Dof;
use super::error::{PlanError, positive};

mod actuation;
pub use actuation::{InputChannels, LoggedAngle, Thruster, ThrusterKind, ThrusterSignal};

/// 6-DOF ROV (the Surveyor of the thesis) or 3-DOF DP surface vessel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum VesselKind {
    /// Remotely operated vehicle, up to 6 DOF, LPV-scheduled on forward speed.
    Rov6,
    /// Dynamically positioned surface vessel, surge–sway–yaw LF model.
    Dp3,
}

/// Limits per DOF, in SI units, as given by the pilots.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct DofLimits {
    /// Largest velocity excursion |ν_i| (m/s or rad/s). For surge this is the
    /// vessel's maximum forward speed: no grid speed may exceed it.
    pub max_velocity: f64,
    /// Largest generalized force |τ_i| (N or N·m).
    pub max_force: f64,
    /// Largest rate of change of τ_i (N/s or N·m/s): hydraulic thrusters
    /// cannot follow jumps, so force schedules are slew-limited to this.
    pub max_force_rate: f64,
    /// Largest rate of change of a velocity reference (m/s² or rad/s²);
    /// velocity schedules are slew-limited to it when given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_accel: Option<f64>,
    /// Expected dominant time constant T_i ≈ m_i/d_i of the DOF (s); it sets the
    /// square-wave period, the PRBS clock and the settling time of static runs.
    pub time_constant_s: f64,
    /// Roll and pitch: the largest attitude the pilots accept in a static
    /// hold (rad, at most 60°). Static runs hold 10°, or this when smaller.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_angle: Option<f64>,
}

/// Largest `max_angle` accepted (rad): 60°.
pub const MAX_HOLD_ANGLE_RAD: f64 = std::f64::consts::FRAC_PI_3;

/// What a DP vessel's identification takes as known (Fossen et al. 1995,
/// sec. 4.1): the inertia M″ including added mass, non-dimensional in the
/// Bis system of the ship's length L (lengths in L, time in √(L/g), mass in
/// the displacement mass m, forces in m·g, moments in m·g·L). The thruster
/// configuration `inputs.configuration` of such a vessel is the T″ of eq. 29
/// in the same system: force rows are direction cosines, the yaw row is the
/// lever arm divided by L. Logs stay SI (m, s, rad); the parallel EKF converts
/// them (x″ = x/L, t″ = t/√(L/g)).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct DpPrior {
    /// Ship length L (m): the Bis length unit.
    pub length_m: f64,
    /// M″ = M/m (Bis), 3 × 3 in the DOF order surge, sway, yaw; symmetric
    /// positive definite (eq. 27, 30). Without it the parallel EKF
    /// estimates the shape of M″ by least squares on the runs and fixes its
    /// scale at the rigid-body mass (M″11 = M″22 = 1); the model's notes say
    /// what that leaves undetermined.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inertia_bis: Option<Vec<Vec<f64>>>,
}

impl DpPrior {
    /// Acceleration of gravity of the Bis units (m/s²).
    pub const GRAVITY: f64 = 9.81;

    /// The Bis time unit √(L/g) (s).
    pub fn time_unit_s(&self) -> f64 {
        (self.length_m / Self::GRAVITY).sqrt()
    }

    /// The Bis velocity unit √(L·g) (m/s).
    pub fn velocity_unit_mps(&self) -> f64 {
        (self.length_m * Self::GRAVITY).sqrt()
    }

    fn validate(&self) -> Result<(), PlanError> {
        positive("dp_prior.length_m", self.length_m)?;
        let Some(m) = &self.inertia_bis else {
            return Ok(());
        };
        if m.len() != 3 || m.iter().any(|r| r.len() != 3) {
            return Err(PlanError::invalid(
                "dp_prior.inertia_bis",
                "M″ must be 3 × 3 (surge, sway, yaw)",
            ));
        }
        if m.iter().flatten().any(|v| !v.is_finite()) {
            return Err(PlanError::invalid(
                "dp_prior.inertia_bis",
                "every entry must be a finite number",
            ));
        }
        let mat = nalgebra::Matrix3::from_fn(|i, j| m[i][j]);
        let scale = mat.abs().max();
        if (mat - mat.transpose()).abs().max() > 1e-9 * scale || mat.cholesky().is_none() {
            return Err(PlanError::invalid(
                "dp_prior.inertia_bis",
                "M″ must be symmetric positive definite (M = Mᵀ > 0, eq. 9)",
            ));
        }
        Ok(())
    }
}

/// Unit of the logged heading `psi` (the other angles are radians).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum HeadingUnit {
    /// Radians (the log contract).
    #[default]
    Rad,
    /// Degrees, as many DP systems and gyro compasses record it; converted
    /// to radians on reading.
    Deg,
}

impl HeadingUnit {
    /// Radians in one unit.
    pub fn radians(self) -> f64 {
        match self {
            HeadingUnit::Rad => 1.0,
            HeadingUnit::Deg => std::f64::consts::PI / 180.0,
        }
    }

    /// The unit's symbol: "rad" or "°".
    pub fn symbol(self) -> &'static str {
        match self {
            HeadingUnit::Rad => "rad",
            HeadingUnit::Deg => "°",
        }
    }
}

/// A vessel as the planner needs it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct VesselProfile {
    /// Name, e.g. "Surveyor ROV" (1–200 characters, not blank).
    #[cfg_attr(
        feature = "openapi",
        schema(min_length = 1, max_length = 200, pattern = r"\S")
    )]
    pub name: String,
    /// ROV or DP vessel.
    pub kind: VesselKind,
    /// Modeled DOFs (surge is required: it is the LPV scheduling variable), each once.
    #[cfg_attr(feature = "openapi", schema(min_items = 1, max_items = 6))]
    pub dofs: Vec<Dof>,
    /// Input channels.
    pub inputs: InputChannels,
    /// Limits for every modeled DOF.
    #[serde(deserialize_with = "super::dof::deserialize_dof_map")]
    pub limits: BTreeMap<Dof, DofLimits>,
    /// Rate of the vessel's controller, at which references are fed (Hz).
    pub controller_rate_hz: f64,
    /// Rate of the data logger (Hz); the thesis logged a 20 Hz controller at 10 Hz.
    pub logger_rate_hz: f64,
    /// DP vessels: the ship length L (Bis scale) and, when known, the
    /// inertia M″, for the parallel EKF identification (`parallel_ekf`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dp_prior: Option<DpPrior>,
    /// Unit of the logged heading `psi` (default radians); an upload's
    /// `meta.heading_unit` overrides it for that run.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub heading_unit: Option<HeadingUnit>,
    /// ROVs: the vessel's own autopilot (its loops' gains and restoring
    /// feed-forward). Given, simulated flights of the plan (predicted
    /// precision, the demo) fly through it instead of loops designed from
    /// the limits.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub autopilot: Option<super::autopilot::Autopilot>,
}

impl VesselProfile {
    /// The limits of a modeled DOF. Only valid after [`VesselProfile::validate`].
    pub fn limit(&self, dof: Dof) -> &DofLimits {
        &self.limits[&dof]
    }

    /// Maximum forward speed (m/s): the surge velocity limit.
    pub fn max_forward_speed(&self) -> f64 {
        self.limit(Dof::Surge).max_velocity
    }

    /// The thrusters, if the vessel is actuated by thruster commands.
    pub fn thrusters(&self) -> &[Thruster] {
        match &self.inputs {
            InputChannels::Thrusters { thrusters, .. } => thrusters,
            InputChannels::GeneralizedForces => &[],
        }
    }

    /// An azimuth's logged angle needs a DP vessel with its length (the
    /// yaw arm in T″ is over L), a finite position, and a configuration
    /// column that is the thruster's T″ at some angle (a unit direction,
    /// the yaw arm its position gives there, within 0.02).
    fn check_logged_angle(
        &self,
        i: usize,
        t: &Thruster,
        a: &LoggedAngle,
        configuration: &[Vec<f64>],
    ) -> Result<(), PlanError> {
        let field = format!("inputs.thrusters[{i}].logged_angle");
        if t.kind != ThrusterKind::Azimuth {
            return Err(PlanError::invalid(
                field,
                "only an azimuth thruster turns: its kind must be azimuth",
            ));
        }
        let Some(length) = self
            .dp_prior
            .as_ref()
            .filter(|_| self.kind == VesselKind::Dp3)
            .map(|p| p.length_m)
        else {
            return Err(PlanError::invalid(
                field,
                "a logged azimuth angle needs a DP vessel with dp_prior.length_m (T″'s yaw arm is over L)",
            ));
        };
        for (name, v) in [("x_m", a.x_m), ("y_m", a.y_m)] {
            if !v.is_finite() || v.abs() > 10.0 * length {
                return Err(PlanError::invalid(
                    format!("{field}.{name}"),
                    "must be a finite position within the ship (m from the origin)",
                ));
            }
        }
        let col: Vec<f64> = configuration
            .iter()
            .filter_map(|r| r.get(i))
            .copied()
            .collect();
        if col.len() == 3 {
            let alpha = col[1].atan2(col[0]);
            let want = a.column(alpha, length);
            if col.iter().zip(want).any(|(c, w)| (c - w).abs() > 0.02) {
                return Err(PlanError::invalid(
                    "inputs.configuration",
                    format!(
                        "column thr_{}: thruster '{}' logs its angle: its column of T″ must be (cos α, sin α, (x sin α − y cos α)/L) at the planned angle α; at α = {}° its position gives ({}), the column is ({})",
                        i + 1,
                        t.name,
                        crate::numbers::sig3(alpha.to_degrees()),
                        want.map(crate::numbers::sig3).join(", "),
                        col.iter()
                            .map(|v| crate::numbers::sig3(*v))
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Checks the profile for completeness and physical sense.
    pub fn validate(&self) -> Result<(), PlanError> {
        super::check_name("name", &self.name)?;
        if self.dofs.is_empty() {
            return Err(PlanError::invalid(
                "dofs",
                "at least one DOF must be modeled",
            ));
        }
        for (i, d) in self.dofs.iter().enumerate() {
            if self.dofs[..i].contains(d) {
                return Err(PlanError::invalid(
                    format!("dofs[{i}]"),
                    format!("{} is listed twice", d.name()),
                ));
            }
            if self.kind == VesselKind::Dp3 && !Dof::HORIZONTAL.contains(d) {
                return Err(PlanError::invalid(
                    format!("dofs[{i}]"),
                    format!(
                        "a 3-DOF DP vessel models surge, sway and yaw only, not {}",
                        d.name()
                    ),
                ));
            }
        }
        if !self.dofs.contains(&Dof::Surge) {
            return Err(PlanError::invalid(
                "dofs",
                "surge must be modeled: forward speed is the scheduling variable",
            ));
        }
        positive("controller_rate_hz", self.controller_rate_hz)?;
        positive("logger_rate_hz", self.logger_rate_hz)?;
        if self.controller_rate_hz > 1000.0 || self.logger_rate_hz > 1000.0 {
            return Err(PlanError::over_limit(
                "controller_rate_hz",
                "sample rates above 1000 Hz are not supported",
                1000.0,
            ));
        }
        for &d in &self.dofs {
            let Some(l) = self.limits.get(&d) else {
                return Err(PlanError::invalid(
                    format!("limits.{}", d.name()),
                    format!("limits for the modeled DOF {} are missing", d.name()),
                ));
            };
            let f = |name: &str| format!("limits.{}.{name}", d.name());
            positive(&f("max_velocity"), l.max_velocity)?;
            positive(&f("max_force"), l.max_force)?;
            positive(&f("max_force_rate"), l.max_force_rate)?;
            positive(&f("time_constant_s"), l.time_constant_s)?;
            if let Some(a) = l.max_accel {
                positive(&f("max_accel"), a)?;
            }
            if let Some(a) = l.max_angle {
                if !matches!(d, Dof::Roll | Dof::Pitch) {
                    return Err(PlanError::invalid(
                        f("max_angle"),
                        "only roll and pitch hold an attitude",
                    ));
                }
                positive(&f("max_angle"), a)?;
                if a > MAX_HOLD_ANGLE_RAD {
                    return Err(PlanError::over_limit(
                        f("max_angle"),
                        format!(
                            "{a} rad is beyond 60°, where the Euler angles near their singularity"
                        ),
                        MAX_HOLD_ANGLE_RAD,
                    ));
                }
            }
            if l.time_constant_s > 3600.0 {
                return Err(PlanError::over_limit(
                    f("time_constant_s"),
                    "a time constant above one hour cannot be identified in a sea trial",
                    3600.0,
                ));
            }
        }
        if let Some(d) = self.limits.keys().find(|d| !self.dofs.contains(d)) {
            return Err(PlanError::invalid(
                format!("limits.{}", d.name()),
                format!("{} is not among the modeled DOFs", d.name()),
            ));
        }
        if let Some(prior) = &self.dp_prior {
            if self.kind != VesselKind::Dp3 || self.dofs != Dof::HORIZONTAL {
                return Err(PlanError::invalid(
                    "dp_prior",
                    "only a DP vessel modelling surge, sway and yaw (in that order) has a DP prior",
                ));
            }
            prior.validate()?;
        }
        if let Some(a) = &self.autopilot {
            if self.kind != VesselKind::Rov6 {
                return Err(PlanError::invalid(
                    "autopilot",
                    "only ROV profiles declare an autopilot (a DP vessel's plan is flown by thruster commands)",
                ));
            }
            a.validate(&self.dofs)?;
        }
        if let InputChannels::Thrusters {
            thrusters,
            configuration,
        } = &self.inputs
        {
            if thrusters.is_empty() {
                return Err(PlanError::invalid(
                    "inputs.thrusters",
                    "at least one thruster is needed",
                ));
            }
            for (i, t) in thrusters.iter().enumerate() {
                super::check_name(&format!("inputs.thrusters[{i}].name"), &t.name)?;
                positive(&format!("inputs.thrusters[{i}].max_command"), t.max_command)?;
                positive(&format!("inputs.thrusters[{i}].max_rate"), t.max_rate)?;
                if let Some(g) = &t.coefficient_group {
                    super::check_name(&format!("inputs.thrusters[{i}].coefficient_group"), g)?;
                }
                t.signal
                    .validate(&format!("inputs.thrusters[{i}].signal"))?;
                if let Some(a) = &t.logged_angle {
                    self.check_logged_angle(i, t, a, configuration)?;
                }
            }
            if configuration.len() != self.dofs.len() {
                return Err(PlanError::invalid(
                    "inputs.configuration",
                    format!(
                        "T must have one row per modeled DOF ({} rows), got {}",
                        self.dofs.len(),
                        configuration.len()
                    ),
                ));
            }
            for (r, row) in configuration.iter().enumerate() {
                if row.len() != thrusters.len() {
                    return Err(PlanError::invalid(
                        format!("inputs.configuration[{r}]"),
                        format!(
                            "T must have one column per thruster ({}), got {}",
                            thrusters.len(),
                            row.len()
                        ),
                    ));
                }
                if let Some(c) = row.iter().position(|x| !x.is_finite()) {
                    return Err(PlanError::invalid(
                        format!("inputs.configuration[{r}][{c}]"),
                        "must be a finite number",
                    ));
                }
            }
            for c in 0..thrusters.len() {
                if configuration.iter().all(|row| row[c] == 0.0) {
                    return Err(PlanError::invalid(
                        "inputs.configuration",
                        format!(
                            "column thr_{}: thruster '{}' acts on no modeled DOF: its column of T is zero",
                            c + 1,
                            thrusters[c].name
                        ),
                    ));
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests;
