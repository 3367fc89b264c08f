//! The prior model a plan is flown with before the campaign exists: a
//! stored model, the vessel profile's rough numbers, or the source
//! documents' vessels (thesis Surveyor-like ROV, Fossen et al.'s supply
//! vessel).

use nalgebra::{Matrix3, Matrix6};
use serde::{Deserialize, Serialize};

use super::DesignError;
use crate::identification::document::{ModelDocument, ModelKind, from_rows};
use crate::identification::ekf_campaign::{default_theta, known};
use crate::planning::dof::Dof;
use crate::planning::vessel::{VesselKind, VesselProfile};
use crate::simulation::dp_ship::DpShip;
use crate::simulation::rov::{LinearDamping, Restoring, RovTruth, Tether};

/// Static attitude hold the rough prior's righting moment is sized for
/// (rad): the planner's 10° hold.
const ROUGH_HOLD_RAD: f64 = 10.0 * std::f64::consts::PI / 180.0;
/// Share of the roll/pitch moment limit the rough prior's righting moment
/// needs to hold [`ROUGH_HOLD_RAD`].
const ROUGH_HOLD_SHARE: f64 = 0.5;

/// Where the prior came from (shown with the prediction).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum PriorSource {
    /// A stored model (its id and version).
    Model {
        /// Model id.
        model_id: String,
        /// Its version.
        version: i64,
    },
    /// The vessel profile's limits and time constants.
    Profile,
    /// The source documents' vessel (thesis ROV or Fossen's supply vessel).
    Reference,
}

/// A vehicle to fly the plan with.
#[derive(Debug, Clone, PartialEq)]
pub enum Prior {
    /// A 6-DOF ROV for `simulation::trials`.
    Rov(Box<RovTruth>),
    /// A DP ship for `simulation::dp_ship`.
    Dp(Box<DpShip>),
}

impl Prior {
    /// The prior a stored model describes: an LPV model's M, D̄ per grid
    /// speed (as the linear damping table, Coriolis and loads left out) and
    /// g(η); a DP ship's M″, T″ and θ″.
    pub fn from_model(doc: &ModelDocument, profile: &VesselProfile) -> Result<Prior, DesignError> {
        match (doc.kind, profile.kind) {
            (ModelKind::Lpv, VesselKind::Rov6) => rov_from_lpv(doc),
            (ModelKind::DpShip, VesselKind::Dp3) => {
                let d = doc.dp_ship.as_ref().ok_or_else(|| {
                    DesignError::new("prior.model_id", "the DP model has no dp_ship section")
                })?;
                let theta: [f64; 9] = d.theta.clone().try_into().map_err(|_| {
                    DesignError::new("prior.model_id", "the DP model does not hold nine θ″")
                })?;
                let m = fixed3(&d.m, "dp_ship.m")?;
                let t = from_rows(&d.t_config)
                    .filter(|t| t.shape() == (3, 6))
                    .ok_or_else(|| DesignError::new("prior.model_id", "T″ is not 3 × 6"))?;
                let thrust = crate::simulation::dp_ship::ThrustLayout {
                    t,
                    groups: crate::simulation::dp_ship::ThrustLayout::paper().groups,
                };
                Ok(Prior::Dp(Box::new(DpShip::from_theta(m, thrust, &theta))))
            }
            (k, v) => Err(DesignError::new(
                "prior.model_id",
                format!(
                    "a {} model cannot fly a {} plan; give a physical model of this vessel (λ-filter for an ROV, parallel EKF for a DP ship) or none",
                    kind_name(k),
                    vessel_name(v)
                ),
            )),
        }
    }

    /// Rough numbers from the profile. ROV: per DOF d_ii = max force / max
    /// velocity (the force that holds the largest excursion), m_ii = d_ii·T_i
    /// with the profile's time constant, no coupling; a righting moment
    /// z_G·W − z_B·B that holds a 10° roll or pitch with half the moment
    /// limit; W − B = 0. DP: θ″ from the time constants (A″_h,ii = −√(L/g)/T_i,
    /// K″ = 5·10⁻³) with the profile's M″, or diag(1, 1, 1/16) without one.
    pub fn from_profile(profile: &VesselProfile) -> Result<Prior, DesignError> {
        match profile.kind {
            VesselKind::Rov6 => {
                let mut m = Matrix6::zeros();
                let mut d = Matrix6::zeros();
                for dof in Dof::ALL {
                    let i = dof.index();
                    let (mi, di) = match profile.limits.get(&dof) {
                        Some(l) => {
                            let di = l.max_force / l.max_velocity;
                            (di * l.time_constant_s, di)
                        }
                        None => (1.0, 1.0),
                    };
                    m[(i, i)] = mi;
                    d[(i, i)] = di;
                }
                let righting = [Dof::Roll, Dof::Pitch]
                    .iter()
                    .filter_map(|d| profile.limits.get(d))
                    .map(|l| {
                        let hold = l.max_angle.unwrap_or(ROUGH_HOLD_RAD).min(ROUGH_HOLD_RAD);
                        ROUGH_HOLD_SHARE * l.max_force / hold.sin()
                    })
                    .fold(f64::INFINITY, f64::min);
                let mut truth = RovTruth::new(m, LinearDamping::constant(d));
                if righting.is_finite() {
                    truth.restoring = lumped_restoring(0.0, righting);
                }
                Ok(Prior::Rov(Box::new(truth)))
            }
            VesselKind::Dp3 => {
                let (m, layout, scale) = known(profile).map_err(ekf_field)?;
                let m = m.unwrap_or_else(|| Matrix3::from_diagonal(&[1.0, 1.0, 1.0 / 16.0].into()));
                Ok(Prior::Dp(Box::new(DpShip::from_theta(
                    m,
                    layout.thrust,
                    &default_theta(profile, &scale),
                ))))
            }
        }
    }

    /// The source documents' vessel: the Surveyor-like ROV of
    /// `simulation::rov`, or the supply vessel's identified θ″ (eq. 48–49)
    /// with the profile's M″ (the paper's when it gives none) and T″.
    pub fn reference(profile: &VesselProfile) -> Result<Prior, DesignError> {
        match profile.kind {
            VesselKind::Rov6 => Ok(Prior::Rov(Box::new(RovTruth::surveyor_like()))),
            VesselKind::Dp3 => {
                let (m, layout, _) = known(profile).map_err(ekf_field)?;
                let paper = DpShip::supply_vessel();
                Ok(Prior::Dp(Box::new(DpShip::from_theta(
                    m.unwrap_or(paper.m),
                    layout.thrust,
                    &paper.theta(),
                ))))
            }
        }
    }
}

/// g(η) of a lumped W − B and z_G·W − z_B·B (only their differences enter).
fn lumped_restoring(w_minus_b: f64, metacentric: f64) -> Restoring {
    Restoring {
        weight: 1.0 + w_minus_b,
        buoyancy: 1.0,
        r_g: [0.0; 3],
        r_b: [0.0, 0.0, -metacentric],
    }
}

fn rov_from_lpv(doc: &ModelDocument) -> Result<Prior, DesignError> {
    let lpv = doc
        .lpv
        .as_ref()
        .filter(|l| !l.points.is_empty())
        .ok_or_else(|| DesignError::new("prior.model_id", "the LPV model has no grid points"))?;
    if doc.dofs != Dof::ALL {
        return Err(DesignError::new(
            "prior.model_id",
            format!(
                "the ROV simulator flies 6-DOF models; this one models {} DOFs",
                doc.dofs.len()
            ),
        ));
    }
    let six = |rows: &Vec<Vec<f64>>, what: &str| -> Result<Matrix6<f64>, DesignError> {
        from_rows(rows)
            .filter(|m| m.shape() == (6, 6) && m.iter().all(|v| v.is_finite()))
            .map(|m| Matrix6::from_fn(|i, j| m[(i, j)]))
            .ok_or_else(|| {
                DesignError::new(
                    "prior.model_id",
                    format!("{what} is not a finite 6 × 6 matrix"),
                )
            })
    };
    // M does not change with speed: the mean over the grid, symmetrized.
    let mut m = Matrix6::zeros();
    for p in &lpv.points {
        m += six(&p.m, "M")?;
    }
    m /= lpv.points.len() as f64;
    m = (m + m.transpose()) * 0.5;
    if m.cholesky().is_none() {
        return Err(DesignError::new(
            "prior.model_id",
            "the model's M is not positive definite; it cannot be simulated",
        ));
    }
    let mut speeds = Vec::new();
    let mut tables = Vec::new();
    for p in &lpv.points {
        speeds.push(p.speed_mps);
        tables.push(six(&p.d_bar, "D̄")?);
    }
    let mut truth = RovTruth::new(m, LinearDamping { speeds, tables });
    if let Some(r) = &doc.restoring {
        truth.restoring = lumped_restoring(
            r.params.weight_minus_buoyancy_n,
            r.params.zg_weight_minus_zb_buoyancy_nm,
        );
        truth.tether = Tether {
            pitch_moment: -r.params.tether_pitch_moment_nm,
            body_force: [0.0; 3],
        };
    }
    truth
        .damping
        .validate()
        .map_err(|e| DesignError::new("prior.model_id", e.to_string()))?;
    Ok(Prior::Rov(Box::new(truth)))
}

fn fixed3(rows: &Vec<Vec<f64>>, what: &str) -> Result<Matrix3<f64>, DesignError> {
    from_rows(rows)
        .filter(|m| m.shape() == (3, 3) && m.iter().all(|v| v.is_finite()))
        .map(|m| Matrix3::from_fn(|i, j| m[(i, j)]))
        .ok_or_else(|| {
            DesignError::new(
                "prior.model_id",
                format!("{what} is not a finite 3 × 3 matrix"),
            )
        })
}

fn ekf_field(e: crate::identification::IdentifyError) -> DesignError {
    DesignError::new(e.field().to_string(), e.to_string())
}

fn kind_name(k: ModelKind) -> &'static str {
    match k {
        ModelKind::Lpv => "LPV",
        ModelKind::DpShip => "DP ship",
        ModelKind::StateSpace => "black-box state-space",
    }
}

fn vessel_name(v: VesselKind) -> &'static str {
    match v {
        VesselKind::Rov6 => "6-DOF ROV",
        VesselKind::Dp3 => "DP ship",
    }
}
