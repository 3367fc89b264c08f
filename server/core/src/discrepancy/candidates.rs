//! The library of physically meaningful candidate terms and their regressor
//! signatures in M·ν̇ + C(ν)ν + D(ν)ν + g(η) = τ.
//!
//! A candidate either adds a force φ(ν, η)·θ to the left-hand side of a DOF's
//! equation (damping, Coriolis, restoring, constant load, current, missing
//! coupling), or changes the force that actually acts, τ_a = A(τ_c)
//! (actuator lag, delay, saturation, dead zone — functions of the command τ,
//! not of ν). Actuator candidates carry one shape parameter that enters
//! non-linearly and is found by a profile search.

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use crate::planning::Dof;

/// Odd restoring shapes of the general g(η) (thesis eq. 1.4). The even
/// shape cos θ cos φ is left to [`Effect::ConstantLoad`]: at trial attitudes
/// it differs from a constant by O(φ², θ²) and no run tells them apart.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum RestoringShape {
    /// sin θ (surge W−B, pitch z_G W − z_B B, yaw y_G W − y_B B).
    SinTheta,
    /// cos θ sin φ (sway W−B, roll z_G W − z_B B, yaw x_G W − x_B B).
    CosThetaSinPhi,
}

/// One candidate piece of missing physics.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(tag = "effect", rename_all = "snake_case")]
pub enum Effect {
    /// Quadratic damping d·|ν_i|ν_i in DOF i.
    QuadraticDamping {
        /// The DOF.
        dof: Dof,
    },
    /// Cubic damping c·ν_i³ in DOF i: drag that grows faster than |ν_i|ν_i
    /// at the top of the speed range (and less near zero).
    CubicDamping {
        /// The DOF.
        dof: Dof,
    },
    /// Cross-flow damping d·|ν_j|·ν_i in DOF i's equation (j ≠ i): the
    /// damping of ν_i grows with the size of another velocity, whatever its
    /// sign (e.g. sway damping growing with |r| in a turn).
    CrossDamping {
        /// The equation i (and the velocity damped).
        dof: Dof,
        /// The velocity j whose size scales the damping.
        from: Dof,
    },
    /// Coriolis–centripetal C(ν)ν with the structure C(ν) takes from the
    /// baseline M (Fossen), one scale factor θ (≈ 1 when M is right) over
    /// all DOFs.
    CoriolisFromM,
    /// One Coriolis product ν_a·ν_b in DOF `dof`'s equation, free coefficient.
    CoriolisProduct {
        /// The equation it enters.
        dof: Dof,
        /// First velocity of the product.
        a: Dof,
        /// Second velocity of the product.
        b: Dof,
    },
    /// A restoring shape of g(η) the baseline lacks or has wrong.
    Restoring {
        /// The equation it enters.
        dof: Dof,
        /// sin θ or cos θ sin φ.
        shape: RestoringShape,
    },
    /// A constant force or moment: tether, buoyancy or CG-offset error.
    ConstantLoad {
        /// The DOF.
        dof: Dof,
    },
    /// Ocean current: damping acts on ν − ν_c with ν_c = R(ψ)ᵀ[V_N V_E]ᵀ;
    /// two coefficients (north and east current, m/s) shared by all DOFs.
    Current,
    /// A horizontal pull fixed in NED at the body origin — a tether leading
    /// to the ship, a towed load: τ_t = R(Θ)ᵀ[F_N F_E 0]ᵀ in surge and
    /// sway, turning with the heading in the body frame; two coefficients
    /// (north and east pull, N). Unlike a current it does not scale with
    /// the damping.
    TetherPull,
    /// Coupling a diagonal baseline misses: M_ij ν̇_j + D̄_ij ν_j in DOF i.
    Coupling {
        /// The equation i.
        dof: Dof,
        /// The velocity j.
        from: Dof,
    },
    /// First-order lag τ_a = τ_c/(1 + s·T_a) between command and thrust.
    ActuatorLag {
        /// The DOF.
        dof: Dof,
    },
    /// Pure delay τ_a(t) = τ_c(t − d·h) of d log samples, a fraction of a
    /// sample included (over each held interval the mean of the commands
    /// it straddles).
    InputDelay {
        /// The DOF.
        dof: Dof,
    },
    /// One pure delay of d log samples (a fraction included) on every
    /// DOF's command: a transport delay of the command link or the
    /// logger's time stamps.
    CommonInputDelay,
    /// One first-order lag τ_a = τ_c/(1 + s·T_a) on every DOF's command:
    /// thrusters of one kind answering alike.
    CommonActuatorLag,
    /// Thrust saturation τ_a = clip(τ_c, ±τ_max).
    Saturation {
        /// The DOF.
        dof: Dof,
    },
    /// Dead zone: no thrust for |τ_c| < δ, τ_c − sign(τ_c)·δ beyond.
    DeadZone {
        /// The DOF.
        dof: Dof,
    },
}

/// Effects grouped by physics, for ranking and look-alike pairs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum Family {
    /// |ν|ν damping.
    QuadraticDamping,
    /// ν³ damping.
    CubicDamping,
    /// |ν_j|ν_i cross-flow damping.
    CrossDamping,
    /// C(ν)ν products.
    Coriolis,
    /// g(η) shapes.
    Restoring,
    /// Constant force/moment (tether).
    ConstantLoad,
    /// Ocean current.
    Current,
    /// A pull fixed in NED (tether to the ship).
    Tether,
    /// Missing off-diagonal M, D̄.
    Coupling,
    /// Actuator lag.
    ActuatorLag,
    /// Input delay.
    InputDelay,
    /// Saturation.
    Saturation,
    /// Dead zone.
    DeadZone,
}

impl Family {
    /// Plain name.
    pub fn name(self) -> &'static str {
        match self {
            Family::QuadraticDamping => "quadratic damping",
            Family::CubicDamping => "cubic damping",
            Family::CrossDamping => "cross-flow damping",
            Family::Coriolis => "Coriolis–centripetal coupling",
            Family::Restoring => "restoring force",
            Family::ConstantLoad => "constant load",
            Family::Current => "ocean current",
            Family::Tether => "pull fixed in NED (tether, towline or mooring)",
            Family::Coupling => "missing coupling",
            Family::ActuatorLag => "actuator lag",
            Family::InputDelay => "input delay",
            Family::Saturation => "actuator saturation",
            Family::DeadZone => "actuator dead zone",
        }
    }
}

/// The non-linear shape parameter of an actuator effect.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShapeKind {
    /// T_a (s).
    LagTime,
    /// d (samples).
    DelaySamples,
    /// τ_max (N or N·m).
    SaturationLevel,
    /// δ (N or N·m).
    DeadZoneWidth,
}

impl ShapeKind {
    /// The parameter's name in reports and parameter tables.
    pub fn name(self) -> &'static str {
        match self {
            ShapeKind::LagTime => "T_a (s)",
            ShapeKind::DelaySamples => "delay (samples)",
            ShapeKind::SaturationLevel => "τ_max",
            ShapeKind::DeadZoneWidth => "δ",
        }
    }
}

/// Coriolis products of each DOF's equation for a diagonal M:
/// (C(ν)ν)_i = Σ ±(m_a − m_b)·ν_a·ν_b over these pairs.
pub const CORIOLIS_PAIRS: [(Dof, [(Dof, Dof); 2]); 6] = [
    (
        Dof::Surge,
        [(Dof::Heave, Dof::Pitch), (Dof::Sway, Dof::Yaw)],
    ),
    (Dof::Sway, [(Dof::Surge, Dof::Yaw), (Dof::Heave, Dof::Roll)]),
    (
        Dof::Heave,
        [(Dof::Sway, Dof::Roll), (Dof::Surge, Dof::Pitch)],
    ),
    (Dof::Roll, [(Dof::Sway, Dof::Heave), (Dof::Pitch, Dof::Yaw)]),
    (
        Dof::Pitch,
        [(Dof::Surge, Dof::Heave), (Dof::Roll, Dof::Yaw)],
    ),
    (Dof::Yaw, [(Dof::Surge, Dof::Sway), (Dof::Roll, Dof::Pitch)]),
];

impl Effect {
    /// Its family.
    pub fn family(&self) -> Family {
        match self {
            Effect::QuadraticDamping { .. } => Family::QuadraticDamping,
            Effect::CubicDamping { .. } => Family::CubicDamping,
            Effect::CrossDamping { .. } => Family::CrossDamping,
            Effect::CoriolisFromM | Effect::CoriolisProduct { .. } => Family::Coriolis,
            Effect::Restoring { .. } => Family::Restoring,
            Effect::ConstantLoad { .. } => Family::ConstantLoad,
            Effect::Current => Family::Current,
            Effect::TetherPull => Family::Tether,
            Effect::Coupling { .. } => Family::Coupling,
            Effect::ActuatorLag { .. } | Effect::CommonActuatorLag => Family::ActuatorLag,
            Effect::InputDelay { .. } | Effect::CommonInputDelay => Family::InputDelay,
            Effect::Saturation { .. } => Family::Saturation,
            Effect::DeadZone { .. } => Family::DeadZone,
        }
    }

    /// The DOF it is attached to (None for the effects spanning DOFs).
    pub fn dof(&self) -> Option<Dof> {
        match *self {
            Effect::QuadraticDamping { dof }
            | Effect::CubicDamping { dof }
            | Effect::CrossDamping { dof, .. }
            | Effect::CoriolisProduct { dof, .. }
            | Effect::Restoring { dof, .. }
            | Effect::ConstantLoad { dof }
            | Effect::Coupling { dof, .. }
            | Effect::ActuatorLag { dof }
            | Effect::InputDelay { dof }
            | Effect::Saturation { dof }
            | Effect::DeadZone { dof } => Some(dof),
            Effect::CoriolisFromM
            | Effect::Current
            | Effect::TetherPull
            | Effect::CommonInputDelay
            | Effect::CommonActuatorLag => None,
        }
    }

    /// The shape parameter of an actuator effect.
    pub fn shape(&self) -> Option<ShapeKind> {
        match self {
            Effect::ActuatorLag { .. } | Effect::CommonActuatorLag => Some(ShapeKind::LagTime),
            Effect::InputDelay { .. } | Effect::CommonInputDelay => Some(ShapeKind::DelaySamples),
            Effect::Saturation { .. } => Some(ShapeKind::SaturationLevel),
            Effect::DeadZone { .. } => Some(ShapeKind::DeadZoneWidth),
            _ => None,
        }
    }

    /// A force fixed in NED (a current, a pull). Its mean over a campaign
    /// flown near one heading is a constant body-frame load, which a
    /// baseline identified without it has absorbed into its constant loads:
    /// those are refitted with it, or its mean would be counted twice.
    pub fn fixed_in_ned(&self) -> bool {
        matches!(self, Effect::Current | Effect::TetherPull)
    }

    /// An actuator effect on every DOF's command (the common delay or lag).
    pub fn on_every_command(&self) -> bool {
        matches!(self, Effect::CommonInputDelay | Effect::CommonActuatorLag)
    }

    /// It changes the force acting in `dof` (actuator effects).
    pub fn acts_on(&self, dof: Dof) -> bool {
        self.shape().is_some() && (self.dof() == Some(dof) || self.on_every_command())
    }

    /// Number of coefficients that enter linearly.
    pub fn n_linear(&self) -> usize {
        match self {
            Effect::Current | Effect::TetherPull | Effect::Coupling { .. } => 2,
            e if e.shape().is_some() => 0,
            _ => 1,
        }
    }

    /// Names of the linear coefficients, with units.
    pub fn coefficient_names(&self) -> Vec<String> {
        let unit = |d: Dof| d.force_unit();
        match *self {
            Effect::QuadraticDamping { dof } => {
                let s = dof.velocity_symbol();
                let vu = dof.velocity_unit();
                vec![format!(
                    "d_{s}|{s}| ({}·s²/{}²)",
                    unit(dof),
                    vu.trim_end_matches("/s")
                )]
            }
            Effect::CubicDamping { dof } => {
                let s = dof.velocity_symbol();
                let vu = dof.velocity_unit();
                vec![format!(
                    "d_{s}{s}{s} ({}·s³/{}³)",
                    unit(dof),
                    vu.trim_end_matches("/s")
                )]
            }
            Effect::CrossDamping { dof, from } => {
                let (i, j) = (dof.velocity_symbol(), from.velocity_symbol());
                vec![format!(
                    "d_{i}|{j}| ({}/(({})·({})))",
                    unit(dof),
                    dof.velocity_unit(),
                    from.velocity_unit()
                )]
            }
            Effect::CoriolisFromM => vec!["scale of C(ν) from M (–)".into()],
            Effect::CoriolisProduct { dof, a, b } => vec![format!(
                "coefficient of {}·{} in {} ({})",
                a.velocity_symbol(),
                b.velocity_symbol(),
                dof.name(),
                unit(dof)
            )],
            Effect::Restoring { dof, shape } => vec![format!(
                "{} coefficient in {} ({})",
                match shape {
                    RestoringShape::SinTheta => "sin θ",
                    RestoringShape::CosThetaSinPhi => "cos θ sin φ",
                },
                dof.name(),
                unit(dof)
            )],
            Effect::ConstantLoad { dof } => {
                vec![format!("constant {} load ({})", dof.name(), unit(dof))]
            }
            Effect::Current => vec!["V_N (m/s)".into(), "V_E (m/s)".into()],
            Effect::TetherPull => vec!["F_N (N)".into(), "F_E (N)".into()],
            Effect::Coupling { dof, from } => vec![
                format!("M_{}{}", dof.velocity_symbol(), from.velocity_symbol()),
                format!("D̄_{}{}", dof.velocity_symbol(), from.velocity_symbol()),
            ],
            _ => vec![],
        }
    }

    /// A short label a control engineer reads.
    pub fn label(&self) -> String {
        match *self {
            Effect::QuadraticDamping { dof } => {
                let s = dof.velocity_symbol();
                format!("quadratic damping |{s}|{s} in {}", dof.name())
            }
            Effect::CubicDamping { dof } => {
                let s = dof.velocity_symbol();
                format!("cubic damping {s}³ in {}", dof.name())
            }
            Effect::CrossDamping { dof, from } => format!(
                "cross-flow damping |{}|{} in {}",
                from.velocity_symbol(),
                dof.velocity_symbol(),
                dof.name()
            ),
            Effect::CoriolisFromM => "Coriolis–centripetal C(ν)ν from M".into(),
            Effect::CoriolisProduct { dof, a, b } => format!(
                "Coriolis product {}·{} in {}",
                a.velocity_symbol(),
                b.velocity_symbol(),
                dof.name()
            ),
            Effect::Restoring { dof, shape } => format!(
                "restoring {} in {}",
                match shape {
                    RestoringShape::SinTheta => "sin θ",
                    RestoringShape::CosThetaSinPhi => "cos θ sin φ",
                },
                dof.name()
            ),
            Effect::ConstantLoad { dof } => {
                format!(
                    "constant {} in {} (tether/bias)",
                    load_word(dof),
                    dof.name()
                )
            }
            Effect::Current => "ocean current (relative velocity ν − ν_c)".into(),
            Effect::TetherPull => {
                "pull fixed in NED (tether, towline or mooring; turns with heading)".into()
            }
            Effect::Coupling { dof, from } => {
                format!("missing coupling from {} into {}", from.name(), dof.name())
            }
            Effect::ActuatorLag { dof } => format!("actuator lag in {}", dof.name()),
            Effect::InputDelay { dof } => format!("input delay in {}", dof.name()),
            Effect::CommonInputDelay => "input delay in every DOF (command link)".into(),
            Effect::CommonActuatorLag => "actuator lag in every DOF (thrusters alike)".into(),
            Effect::Saturation { dof } => format!("thrust saturation in {}", dof.name()),
            Effect::DeadZone { dof } => format!("thrust dead zone in {}", dof.name()),
        }
    }

    /// Row indices (into the baseline DOFs) of the equations it enters.
    pub fn rows(&self, dofs: &[Dof], d_ref: &DMatrix<f64>) -> Vec<usize> {
        let idx = |d: Dof| dofs.iter().position(|&x| x == d);
        match *self {
            e if e == Effect::CoriolisFromM || e.on_every_command() => (0..dofs.len()).collect(),
            Effect::Current => match (idx(Dof::Surge), idx(Dof::Sway)) {
                (Some(iu), Some(iv)) => (0..dofs.len())
                    .filter(|&i| d_ref[(i, iu)] != 0.0 || d_ref[(i, iv)] != 0.0)
                    .collect(),
                _ => vec![],
            },
            Effect::TetherPull => match (idx(Dof::Surge), idx(Dof::Sway)) {
                (Some(iu), Some(iv)) => vec![iu.min(iv), iu.max(iv)],
                _ => vec![],
            },
            _ => self.dof().and_then(idx).into_iter().collect(),
        }
    }
}

fn load_word(dof: Dof) -> &'static str {
    if dof.is_angular() { "moment" } else { "force" }
}

/// What regressors need besides (ν, η): the DOFs and the M, D̄ the
/// structured terms (C(ν) from M, current through D̄) are built from.
#[derive(Debug, Clone, Copy)]
pub struct TermContext<'a> {
    /// Modeled DOFs.
    pub dofs: &'a [Dof],
    /// M that C(ν) is built from.
    pub m_ref: &'a DMatrix<f64>,
    /// D̄ that acts on the current.
    pub d_ref: &'a DMatrix<f64>,
}

impl TermContext<'_> {
    /// Index of a DOF among the modeled ones.
    pub fn index(&self, d: Dof) -> Option<usize> {
        self.dofs.iter().position(|&x| x == d)
    }
}

pub use crate::models::coriolis::coriolis_force;

mod library;
pub use library::{LibrarySettings, library};

mod force;
pub use force::Trig;

#[cfg(test)]
mod tests;
