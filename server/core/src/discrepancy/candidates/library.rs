//! The candidate library: which effects are tried for a baseline over its
//! DOFs, family by family.

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::{CORIOLIS_PAIRS, Effect, RestoringShape};
use crate::planning::Dof;

/// Which candidate families to try.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(default)]
pub struct LibrarySettings {
    /// |ν_i|ν_i per DOF.
    pub quadratic_damping: bool,
    /// ν_i³ per DOF.
    pub cubic_damping: bool,
    /// |ν_j|ν_i for every ordered pair of modeled DOFs (i ≠ j).
    pub cross_damping: bool,
    /// C(ν)ν from M and its single products.
    pub coriolis: bool,
    /// sin θ, cos θ sin φ shapes.
    pub restoring: bool,
    /// Constant force/moment per DOF.
    pub constant_load: bool,
    /// Ocean current (needs surge and sway).
    pub current: bool,
    /// A tether pull fixed in NED (needs surge and sway).
    pub tether_pull: bool,
    /// Off-diagonal M, D̄ entries the baseline lacks.
    pub coupling: bool,
    /// Actuator lag per DOF.
    pub actuator_lag: bool,
    /// Input delay per DOF.
    pub input_delay: bool,
    /// Saturation per DOF.
    pub saturation: bool,
    /// Dead zone per DOF.
    pub dead_zone: bool,
}

impl Default for LibrarySettings {
    fn default() -> Self {
        LibrarySettings {
            quadratic_damping: true,
            cubic_damping: true,
            cross_damping: true,
            coriolis: true,
            restoring: true,
            constant_load: true,
            current: true,
            tether_pull: true,
            coupling: true,
            actuator_lag: true,
            input_delay: true,
            saturation: true,
            dead_zone: true,
        }
    }
}

/// Every candidate the library offers for a baseline over `dofs` with
/// matrices `m`, `d_bar` (coupling only where both entries are zero).
pub fn library(
    dofs: &[Dof],
    m: &DMatrix<f64>,
    d_bar: &DMatrix<f64>,
    s: &LibrarySettings,
) -> Vec<Effect> {
    let has = |d: Dof| dofs.contains(&d);
    let mut out = Vec::new();
    for &dof in dofs {
        if s.quadratic_damping {
            out.push(Effect::QuadraticDamping { dof });
        }
        if s.cubic_damping {
            out.push(Effect::CubicDamping { dof });
        }
        if s.cross_damping {
            for &from in dofs.iter().filter(|&&j| j != dof) {
                out.push(Effect::CrossDamping { dof, from });
            }
        }
        if s.constant_load {
            out.push(Effect::ConstantLoad { dof });
        }
        if s.restoring {
            let shapes: &[RestoringShape] = match dof {
                Dof::Surge | Dof::Pitch => &[RestoringShape::SinTheta],
                Dof::Sway | Dof::Roll => &[RestoringShape::CosThetaSinPhi],
                Dof::Yaw => &[RestoringShape::SinTheta, RestoringShape::CosThetaSinPhi],
                Dof::Heave => &[],
            };
            // Attitude-dependent shapes need attitude DOFs in the model.
            if has(Dof::Roll) || has(Dof::Pitch) {
                for &shape in shapes {
                    out.push(Effect::Restoring { dof, shape });
                }
            }
        }
        if s.actuator_lag {
            out.push(Effect::ActuatorLag { dof });
        }
        if s.input_delay {
            out.push(Effect::InputDelay { dof });
        }
        if s.saturation {
            out.push(Effect::Saturation { dof });
        }
        if s.dead_zone {
            out.push(Effect::DeadZone { dof });
        }
    }
    if s.input_delay && dofs.len() > 1 {
        out.push(Effect::CommonInputDelay);
    }
    if s.actuator_lag && dofs.len() > 1 {
        out.push(Effect::CommonActuatorLag);
    }
    if s.coriolis && dofs.len() > 1 {
        out.push(Effect::CoriolisFromM);
        for (dof, pairs) in CORIOLIS_PAIRS {
            for (a, b) in pairs {
                if has(dof) && has(a) && has(b) {
                    out.push(Effect::CoriolisProduct { dof, a, b });
                }
            }
        }
    }
    if s.current && has(Dof::Surge) && has(Dof::Sway) {
        out.push(Effect::Current);
    }
    if s.tether_pull && has(Dof::Surge) && has(Dof::Sway) {
        out.push(Effect::TetherPull);
    }
    if s.coupling {
        for (i, &dof) in dofs.iter().enumerate() {
            for (j, &from) in dofs.iter().enumerate() {
                if i != j && m[(i, j)] == 0.0 && d_bar[(i, j)] == 0.0 {
                    out.push(Effect::Coupling { dof, from });
                }
            }
        }
    }
    out
}
