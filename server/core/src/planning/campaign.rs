//! A trial campaign: the LPV forward-speed grid, the experiment families to
//! fly (thesis ch. 3; Fossen et al. sec. 4.2), repetitions, excitation
//! settings and durations. Everything is stored in SI.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::dof::{Dof, KNOT};
use super::error::{PlanError, positive};
use super::vessel::{VesselKind, VesselProfile};

/// Unit in which the grid was entered.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub enum SpeedUnit {
    /// Knots (the thesis's grid, eq. 3.2).
    #[serde(rename = "kn")]
    Knots,
    /// Metres per second.
    #[serde(rename = "m/s")]
    MetersPerSecond,
}

/// The LPV scheduling grid of forward speeds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct SpeedGrid {
    /// Unit of `speeds` as entered.
    pub unit: SpeedUnit,
    /// Forward speeds, ascending (1–50 of them).
    #[cfg_attr(feature = "openapi", schema(min_items = 1, max_items = 50))]
    pub speeds: Vec<f64>,
}

impl SpeedGrid {
    /// The grid in m/s.
    pub fn speeds_si(&self) -> Vec<f64> {
        let k = match self.unit {
            SpeedUnit::Knots => KNOT,
            SpeedUnit::MetersPerSecond => 1.0,
        };
        self.speeds.iter().map(|s| s * k).collect()
    }
}

/// The experiment families.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum ExperimentFamily {
    /// Constant ±speed per DOF until steady state (Tables 3.2–3.3): C(ν)+D(ν).
    Static,
    /// One DOF excited at a time around the grid speed (Tables 3.4–3.5): M.
    Dynamic,
    /// All DOFs excited at once (Table 3.1), for recursive (Kalman) estimation.
    Recursive,
    /// ≥ 300 s, every DOF, constant and changing speeds (sec. 3.5); never used for fitting.
    Validation,
    /// DP manoeuvre 1: uncoupled surge by the main propellers (SI1).
    DpSurge,
    /// DP manoeuvre 2: coupled sway and yaw by the tunnel thrusters (SI2).
    DpSwayYaw,
    /// DP manoeuvre 3: the azimuth thruster alone (SI3).
    DpAzimuth,
}

impl ExperimentFamily {
    /// Families that apply to a vessel kind.
    pub fn allowed_for(kind: VesselKind) -> &'static [ExperimentFamily] {
        use ExperimentFamily::*;
        match kind {
            VesselKind::Rov6 => &[Static, Dynamic, Recursive, Validation],
            VesselKind::Dp3 => &[DpSurge, DpSwayYaw, DpAzimuth, Validation],
        }
    }

    /// Short code used in experiment names.
    pub fn code(self) -> &'static str {
        use ExperimentFamily::*;
        match self {
            Static => "STA",
            Dynamic => "DYN",
            Recursive => "REC",
            Validation => "VAL",
            DpSurge => "SI1",
            DpSwayYaw => "SI2",
            DpAzimuth => "SI3",
        }
    }

    /// Snake-case name.
    pub fn name(self) -> &'static str {
        use ExperimentFamily::*;
        match self {
            Static => "static",
            Dynamic => "dynamic",
            Recursive => "recursive",
            Validation => "validation",
            DpSurge => "dp_surge",
            DpSwayYaw => "dp_sway_yaw",
            DpAzimuth => "dp_azimuth",
        }
    }
}

/// Excitation signal shape.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum SignalKind {
    /// Maximum-length pseudo-random binary sequence.
    #[default]
    Prbs,
    /// Square wave with period 10·T (each level held 5·T).
    Square,
    /// Schroeder-phased multisine (low crest factor).
    Multisine,
    /// Random binary signal (i.i.d. levels held for a clock period).
    RandomBinary,
}

/// What the non-surge reference columns command. Surge is always a speed
/// reference u_ref: forward speed is the scheduling variable the speed
/// controller holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum Quantity {
    /// Velocity references ν_ref flown with the vessel's controllers (the
    /// thesis); roll and pitch are excited by attitude references φ_ref,
    /// θ_ref about level (a rate reference would integrate to large angles
    /// on a metacentrically stable vehicle).
    #[default]
    Velocity,
    /// Open-loop generalized forces τ (N, N·m).
    Force,
}

/// Per-DOF overrides of the excitation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct DofExcitation {
    /// Signal shape for this DOF.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub signal: Option<SignalKind>,
    /// Amplitude about the operating point (SI: m/s, rad/s, N or N·m). Roll
    /// and pitch under velocity references are excited by attitude: an
    /// angle about level (rad), at most the profile's `max_angle` (10°
    /// without one); default 10° or `max_angle` when smaller.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub amplitude: Option<f64>,
    /// PRBS / random-binary clock period (s); square-wave half period.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clock_period_s: Option<f64>,
    /// PRBS register order n (period 2ⁿ−1 chips), 3..=24.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub prbs_order: Option<u32>,
}

/// Excitation settings of a campaign.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct Excitation {
    /// Default signal shape for dynamic, recursive and DP experiments.
    #[serde(default)]
    pub signal: SignalKind,
    /// Velocity references or open-loop forces for the non-surge DOFs.
    #[serde(default)]
    pub quantity: Quantity,
    /// Default amplitude as a fraction of the DOF's (or thruster's) limit, in (0, 1].
    #[serde(default = "default_fraction")]
    pub amplitude_fraction: f64,
    /// Overrides per DOF. For surge, `amplitude` is the speed excursion about
    /// the grid speed (m/s); its default is 0.3 kn (Table 3.1).
    #[serde(default, deserialize_with = "super::dof::deserialize_dof_map")]
    pub per_dof: BTreeMap<Dof, DofExcitation>,
}

fn default_fraction() -> f64 {
    0.5
}

impl Default for Excitation {
    fn default() -> Self {
        Excitation {
            signal: SignalKind::Prbs,
            quantity: Quantity::Velocity,
            amplitude_fraction: default_fraction(),
            per_dof: BTreeMap::new(),
        }
    }
}

/// Durations (s). Defaults follow the thesis and the paper.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields, default)]
pub struct Durations {
    /// Hold after steady state in static runs (thesis: ≥ 20 s).
    pub static_hold_s: f64,
    /// Minimum length of a dynamic run (thesis: ≥ 30 s).
    pub dynamic_s: f64,
    /// Minimum length of a recursive run (thesis: ≥ 100 s).
    pub recursive_s: f64,
    /// Length of the validation run (thesis: ≥ 300 s).
    pub validation_s: f64,
    /// Minimum length of a DP manoeuvre (the paper's runs: ≈ 600 samples).
    pub dp_manoeuvre_s: f64,
    /// Set-up time between runs, counted in the total trial time.
    pub setup_s: f64,
}

impl Default for Durations {
    fn default() -> Self {
        Durations {
            static_hold_s: 20.0,
            dynamic_s: 30.0,
            recursive_s: 100.0,
            validation_s: 300.0,
            dp_manoeuvre_s: 600.0,
            setup_s: 60.0,
        }
    }
}

/// Shortest validation run the thesis accepts (sec. 3.5).
pub const MIN_VALIDATION_S: f64 = 300.0;
/// Longest single run the planner schedules (4 h).
pub const MAX_RUN_S: f64 = 4.0 * 3600.0;
/// Largest grid.
pub const MAX_GRID_POINTS: usize = 50;
/// Largest number of repetitions.
pub const MAX_REPETITIONS: u32 = 10;

/// A campaign for one vessel.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct CampaignSpec {
    /// Name, e.g. "Stril Explorer, March" (1–200 characters, not blank).
    #[cfg_attr(
        feature = "openapi",
        schema(min_length = 1, max_length = 200, pattern = r"\S")
    )]
    pub name: String,
    /// Forward-speed grid.
    pub grid: SpeedGrid,
    /// Families to fly (at least one, each once).
    #[cfg_attr(feature = "openapi", schema(min_items = 1))]
    pub families: Vec<ExperimentFamily>,
    /// Repetitions per grid point × DOF (N ≥ 2 for the parallel EKF of DP vessels).
    /// Default: 1 for a ROV, 2 for a DP vessel.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub repetitions: Option<u32>,
    /// Excitation settings.
    #[serde(default)]
    pub excitation: Excitation,
    /// Durations.
    #[serde(default)]
    pub durations: Durations,
    /// Seed of every pseudo-random sequence: the plan is a pure function of it.
    #[serde(default)]
    pub seed: u64,
    /// Deciding experiments from discovery reports (their proposals as
    /// given, at most 8; 6-DOF ROVs only), planned after the plan's own
    /// runs, one run per heading leg.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub deciding: Vec<crate::discrepancy::experiment::ExperimentProposal>,
}

impl CampaignSpec {
    /// Repetitions after defaults.
    pub fn repetitions_for(&self, kind: VesselKind) -> u32 {
        self.repetitions.unwrap_or(match kind {
            VesselKind::Rov6 => 1,
            VesselKind::Dp3 => 2,
        })
    }

    /// Checks the campaign against the vessel; every error names its field.
    pub fn validate(&self, vessel: &VesselProfile) -> Result<(), PlanError> {
        super::check_name("name", &self.name)?;
        let speeds = &self.grid.speeds;
        if speeds.is_empty() {
            return Err(PlanError::invalid(
                "grid.speeds",
                "the grid needs at least one speed",
            ));
        }
        if speeds.len() > MAX_GRID_POINTS {
            return Err(PlanError::over_limit(
                "grid.speeds",
                format!(
                    "at most {MAX_GRID_POINTS} grid points, got {}",
                    speeds.len()
                ),
                MAX_GRID_POINTS as f64,
            ));
        }
        let max_speed = vessel.max_forward_speed();
        let unit_factor = match self.grid.unit {
            SpeedUnit::Knots => KNOT,
            SpeedUnit::MetersPerSecond => 1.0,
        };
        for (i, (&s, si)) in speeds.iter().zip(self.grid.speeds_si()).enumerate() {
            let field = format!("grid.speeds[{i}]");
            if !s.is_finite() || s < 0.0 {
                return Err(PlanError::invalid(
                    field,
                    format!("a forward speed must be a finite number ≥ 0 (got {s})"),
                ));
            }
            if si > max_speed + 1e-12 {
                return Err(PlanError::over_limit(
                    field,
                    format!(
                        "{s} {} ({si:.3} m/s) is above the vessel's maximum forward speed of {:.3} m/s ({:.2} {})",
                        unit_label(self.grid.unit),
                        max_speed,
                        max_speed / unit_factor,
                        unit_label(self.grid.unit)
                    ),
                    max_speed,
                ));
            }
            if i > 0 && s <= speeds[i - 1] {
                return Err(PlanError::invalid(
                    field,
                    "grid speeds must be strictly ascending (no duplicates)",
                ));
            }
        }
        if self.seed > super::design::MAX_SEED {
            return Err(PlanError::over_limit(
                "seed",
                "seeds are limited to 2^53 − 1 so that JSON clients read them exactly",
                super::design::MAX_SEED as f64,
            ));
        }
        if self.families.is_empty() {
            return Err(PlanError::invalid(
                "families",
                "choose at least one experiment family",
            ));
        }
        let allowed = ExperimentFamily::allowed_for(vessel.kind);
        for (i, f) in self.families.iter().enumerate() {
            if !allowed.contains(f) {
                return Err(PlanError::invalid(
                    format!("families[{i}]"),
                    format!(
                        "'{}' does not apply to a {} vessel; allowed: {}",
                        f.name(),
                        match vessel.kind {
                            VesselKind::Rov6 => "6-DOF ROV",
                            VesselKind::Dp3 => "3-DOF DP",
                        },
                        allowed
                            .iter()
                            .map(|f| f.name())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                ));
            }
            if self.families[..i].contains(f) {
                return Err(PlanError::invalid(
                    format!("families[{i}]"),
                    format!("'{}' is listed twice", f.name()),
                ));
            }
        }
        let reps = self.repetitions_for(vessel.kind);
        if reps == 0 || reps > MAX_REPETITIONS {
            return Err(PlanError::over_limit(
                "repetitions",
                format!("must be between 1 and {MAX_REPETITIONS} (got {reps})"),
                MAX_REPETITIONS as f64,
            ));
        }
        if vessel.kind == VesselKind::Dp3 && reps < 2 {
            return Err(PlanError::over_limit(
                "repetitions",
                "the parallel EKF needs every DP manoeuvre flown N ≥ 2 times (Fossen et al., eq. 20–25)",
                2.0,
            ));
        }
        let e = &self.excitation;
        if !(e.amplitude_fraction.is_finite()
            && e.amplitude_fraction > 0.0
            && e.amplitude_fraction <= 1.0)
        {
            return Err(PlanError::over_limit(
                "excitation.amplitude_fraction",
                format!(
                    "must be in (0, 1]: a fraction of each limit (got {})",
                    e.amplitude_fraction
                ),
                1.0,
            ));
        }
        for d in e.per_dof.keys() {
            if !vessel.dofs.contains(d) {
                return Err(PlanError::invalid(
                    format!("excitation.per_dof.{}", d.name()),
                    format!("{} is not a modeled DOF of this vessel", d.name()),
                ));
            }
        }
        let du = &self.durations;
        for (name, v) in [
            ("static_hold_s", du.static_hold_s),
            ("dynamic_s", du.dynamic_s),
            ("recursive_s", du.recursive_s),
            ("validation_s", du.validation_s),
            ("dp_manoeuvre_s", du.dp_manoeuvre_s),
        ] {
            let field = format!("durations.{name}");
            positive(&field, v)?;
            if v > MAX_RUN_S {
                return Err(PlanError::over_limit(
                    field,
                    format!("a single run may last at most {MAX_RUN_S} s (4 h)"),
                    MAX_RUN_S,
                ));
            }
        }
        if !(du.setup_s.is_finite() && du.setup_s >= 0.0 && du.setup_s <= MAX_RUN_S) {
            return Err(PlanError::invalid(
                "durations.setup_s",
                "must be a finite number of seconds ≥ 0",
            ));
        }
        if self.families.contains(&ExperimentFamily::Validation)
            && du.validation_s < MIN_VALIDATION_S
        {
            return Err(PlanError::over_limit(
                "durations.validation_s",
                format!(
                    "validation data must cover at least {MIN_VALIDATION_S} s (thesis sec. 3.5), got {}",
                    du.validation_s
                ),
                MIN_VALIDATION_S,
            ));
        }
        super::deciding::validate(&self.deciding, vessel)
    }
}

fn unit_label(u: SpeedUnit) -> &'static str {
    match u {
        SpeedUnit::Knots => "kn",
        SpeedUnit::MetersPerSecond => "m/s",
    }
}
