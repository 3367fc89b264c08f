//! What a run is — its role, grid speed, excited DOFs and signal — from
//! three sources in order of precedence: what the supervisor said (`user`),
//! the planned experiment it was matched to (`plan`), and what the data show
//! (`inferred`, see [`super::describe`]). Every value says where it came
//! from and, unless the supervisor gave it, why.

use serde::{Deserialize, Serialize};

use super::describe::InferredDescription;
use crate::planning::campaign::{ExperimentFamily, SignalKind};
use crate::planning::plan::Experiment;
use crate::planning::vessel::VesselKind;
use crate::planning::waveform::Waveform;
use crate::planning::{Dof, KNOT};

/// What a run is for in an identification (thesis ch. 3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum RunRole {
    /// Held velocities or attitudes: restoring forces, never dynamics.
    Static,
    /// One (or a few) DOFs excited about a grid speed: estimation data.
    Dynamic,
    /// Every DOF excited at once at a grid speed: estimation data.
    Recursive,
    /// Held out: never fitted, the model is tested on it.
    Validation,
}

impl RunRole {
    /// Every role.
    pub const ALL: [RunRole; 4] = [
        RunRole::Static,
        RunRole::Dynamic,
        RunRole::Recursive,
        RunRole::Validation,
    ];

    /// Snake-case name, as in JSON.
    pub fn name(self) -> &'static str {
        match self {
            RunRole::Static => "static",
            RunRole::Dynamic => "dynamic",
            RunRole::Recursive => "recursive",
            RunRole::Validation => "validation",
        }
    }

    /// The role of a name.
    pub fn from_name(name: &str) -> Option<RunRole> {
        RunRole::ALL.into_iter().find(|r| r.name() == name)
    }

    /// The role a planned family plays (the DP manoeuvres are dynamic runs).
    pub fn of_family(family: ExperimentFamily) -> RunRole {
        use ExperimentFamily::*;
        match family {
            Static => RunRole::Static,
            Dynamic | DpSurge | DpSwayYaw | DpAzimuth => RunRole::Dynamic,
            Recursive => RunRole::Recursive,
            Validation => RunRole::Validation,
        }
    }

    /// The ROV family of the role.
    pub fn family(self) -> ExperimentFamily {
        match self {
            RunRole::Static => ExperimentFamily::Static,
            RunRole::Dynamic => ExperimentFamily::Dynamic,
            RunRole::Recursive => ExperimentFamily::Recursive,
            RunRole::Validation => ExperimentFamily::Validation,
        }
    }

    /// Roles a vessel kind's runs can play: a DP vessel's plan has no static
    /// or recursive runs (its dynamic runs are the SI1–SI3 manoeuvres).
    pub fn allowed_for(kind: VesselKind) -> &'static [RunRole] {
        match kind {
            VesselKind::Rov6 => &RunRole::ALL,
            VesselKind::Dp3 => &[RunRole::Dynamic, RunRole::Validation],
        }
    }
}

/// The excitation signal a run was flown with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum RunSignal {
    /// Square wave: regular half-periods.
    Square,
    /// Pseudo-random binary sequence: levels held for multiples of a chip.
    Prbs,
    /// Sum of sinusoids.
    Multisine,
    /// i.i.d. binary levels held for a clock period.
    RandomBinary,
    /// Anything else: steps, holds, manual driving.
    Other,
}

impl RunSignal {
    /// Every signal.
    pub const ALL: [RunSignal; 5] = [
        RunSignal::Square,
        RunSignal::Prbs,
        RunSignal::Multisine,
        RunSignal::RandomBinary,
        RunSignal::Other,
    ];

    /// Snake-case name, as in JSON.
    pub fn name(self) -> &'static str {
        match self {
            RunSignal::Square => "square",
            RunSignal::Prbs => "prbs",
            RunSignal::Multisine => "multisine",
            RunSignal::RandomBinary => "random_binary",
            RunSignal::Other => "other",
        }
    }

    /// The signal of a name.
    pub fn from_name(name: &str) -> Option<RunSignal> {
        RunSignal::ALL.into_iter().find(|r| r.name() == name)
    }

    /// The signal of a planned waveform.
    pub fn of_waveform(w: &Waveform) -> RunSignal {
        match w {
            Waveform::Prbs { .. } => RunSignal::Prbs,
            Waveform::Square { .. } => RunSignal::Square,
            Waveform::Multisine { .. } => RunSignal::Multisine,
            Waveform::RandomBinary { .. } => RunSignal::RandomBinary,
            _ => RunSignal::Other,
        }
    }
}

impl From<SignalKind> for RunSignal {
    fn from(s: SignalKind) -> Self {
        match s {
            SignalKind::Prbs => RunSignal::Prbs,
            SignalKind::Square => RunSignal::Square,
            SignalKind::Multisine => RunSignal::Multisine,
            SignalKind::RandomBinary => RunSignal::RandomBinary,
        }
    }
}

/// Where a value of a run's description came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum Source {
    /// Given by the supervisor (upload metadata or a later edit): wins.
    User,
    /// From the planned experiment the run was matched to.
    Plan,
    /// Inferred from the data; confirm or correct it.
    Inferred,
}

macro_rules! described {
    ($(#[$doc:meta])* $name:ident, $t:ty) => {
        $(#[$doc])*
        #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
        #[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
        pub struct $name {
            /// The value.
            pub value: $t,
            /// Where it came from.
            pub source: Source,
            /// Why: the planned experiment, or the evidence of the inference.
            #[serde(default, skip_serializing_if = "Option::is_none")]
            pub reason: Option<String>,
        }

        impl From<($t, Source, Option<String>)> for $name {
            fn from((value, source, reason): ($t, Source, Option<String>)) -> Self {
                $name {
                    value,
                    source,
                    reason,
                }
            }
        }
    };
}

described!(
    /// A run's role with its source.
    DescribedRole,
    RunRole
);
described!(
    /// A run's grid speed (m/s) with its source.
    DescribedSpeed,
    f64
);
described!(
    /// A run's excited DOFs with their source.
    DescribedDofs,
    Vec<Dof>
);
described!(
    /// A run's excitation signal with its source.
    DescribedSignal,
    RunSignal
);
described!(
    /// Free notes (always the supervisor's).
    DescribedNotes,
    String
);

/// What the supervisor said about a run; `None` = not said.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct UserDescription {
    /// Role.
    pub role: Option<RunRole>,
    /// Grid speed (m/s).
    pub grid_speed_mps: Option<f64>,
    /// Excited DOFs.
    pub excited_dofs: Option<Vec<Dof>>,
    /// Signal.
    pub signal: Option<RunSignal>,
    /// Free notes.
    pub notes: Option<String>,
}

/// What the planned experiment a run was matched to says it is.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanDescription {
    /// The experiment's code.
    pub code: String,
    /// Its family.
    pub family: ExperimentFamily,
    /// Its grid speed (m/s); none for the validation run, which spans the grid.
    pub grid_speed_mps: Option<f64>,
    /// Its excited DOFs.
    pub excited_dofs: Vec<Dof>,
    /// Its excitation signal.
    pub signal: RunSignal,
}

impl PlanDescription {
    /// From a planned experiment. Its signal is that of the first excited
    /// channel other than surge (the speed reference of a dynamic run is
    /// held), else of the first excited channel.
    pub fn of_experiment(e: &Experiment) -> PlanDescription {
        let excited: Vec<_> = e.channels.iter().filter(|c| c.excited).collect();
        let signal = excited
            .iter()
            .find(|c| c.dof != Some(Dof::Surge))
            .or(excited.first())
            .map_or(RunSignal::Other, |c| RunSignal::of_waveform(&c.waveform));
        PlanDescription {
            code: e.code.clone(),
            family: e.family,
            grid_speed_mps: e.grid_speed_mps,
            excited_dofs: e.dofs.clone(),
            signal,
        }
    }
}

/// A run's effective description: each field from the supervisor, the plan
/// or the data (in that order of precedence), with its source.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct RunDescription {
    /// Role: what identification does with the run.
    pub role: Option<DescribedRole>,
    /// The grid speed it was flown at (m/s); none when it spans the grid.
    pub grid_speed_mps: Option<DescribedSpeed>,
    /// DOFs it excites.
    pub excited_dofs: Option<DescribedDofs>,
    /// Its excitation signal.
    pub signal: Option<DescribedSignal>,
    /// The supervisor's notes.
    pub notes: Option<DescribedNotes>,
    /// The experiment family identification treats it as (the plan's family
    /// when the role agrees with the plan, a DP manoeuvre inferred from the
    /// thrusters used, else the role's family).
    pub family: Option<ExperimentFamily>,
    /// Everything inferred from the data, with the evidence, also when a
    /// user or plan value overrides it (none for runs not processed).
    pub inferred: Option<InferredDescription>,
}

/// "0.514 m/s (1.00 kn)".
pub fn speed_words(mps: f64) -> String {
    format!("{mps:.3} m/s ({:.2} kn)", mps / KNOT)
}

/// Names of DOFs, comma-separated ("none" for an empty list).
pub fn dof_words(dofs: &[Dof]) -> String {
    if dofs.is_empty() {
        return "none".into();
    }
    dofs.iter().map(|d| d.name()).collect::<Vec<_>>().join(", ")
}

/// The first of the supervisor's, the plan's and the inferred value, with
/// its source and reason. A matched plan wins over the data even where it
/// says nothing (the validation run's grid speed).
fn first<T>(
    user: Option<T>,
    plan: Option<(Option<T>, &PlanDescription)>,
    inferred: Option<(Option<T>, &str)>,
) -> Option<(T, Source, Option<String>)> {
    match (user, plan, inferred) {
        (Some(v), ..) => Some((v, Source::User, None)),
        (None, Some((v, p)), _) => v.map(|v| {
            (
                v,
                Source::Plan,
                Some(format!("planned experiment {}", p.code)),
            )
        }),
        (None, None, Some((v, why))) => v.map(|v| (v, Source::Inferred, Some(why.to_string()))),
        _ => None,
    }
}

/// Merges the three sources of a run's description.
pub fn describe_run(
    user: &UserDescription,
    plan: Option<&PlanDescription>,
    inferred: Option<&InferredDescription>,
) -> RunDescription {
    let role = first(
        user.role,
        plan.map(|p| (Some(RunRole::of_family(p.family)), p)),
        inferred.map(|i| (Some(i.role), i.role_reason.as_str())),
    )
    .map(DescribedRole::from);
    let grid_speed_mps = first(
        user.grid_speed_mps,
        plan.map(|p| (p.grid_speed_mps, p)),
        inferred.map(|i| (i.grid_speed_mps, i.grid_speed_reason.as_str())),
    )
    .map(DescribedSpeed::from);
    let excited_dofs = first(
        user.excited_dofs.clone(),
        plan.map(|p| (Some(p.excited_dofs.clone()), p)),
        inferred.map(|i| (Some(i.excited_dofs.clone()), i.excited_dofs_reason.as_str())),
    )
    .map(DescribedDofs::from);
    let signal = first(
        user.signal,
        plan.map(|p| (Some(p.signal), p)),
        inferred.map(|i| (Some(i.signal), i.signal_reason.as_str())),
    )
    .map(DescribedSignal::from);
    let family = role.as_ref().map(|r| {
        let role = r.value;
        match (plan, inferred) {
            (Some(p), _) if RunRole::of_family(p.family) == role => p.family,
            (_, Some(i)) if i.role == role => i.family,
            _ => role.family(),
        }
    });
    RunDescription {
        role,
        grid_speed_mps,
        excited_dofs,
        signal,
        notes: first(user.notes.clone(), None, None).map(DescribedNotes::from),
        family,
        inferred: inferred.cloned(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identification::describe::InferredDescription;

    fn inferred(role: RunRole, family: ExperimentFamily) -> InferredDescription {
        InferredDescription {
            role,
            role_reason: "data".into(),
            family,
            grid_speed_mps: Some(0.5),
            grid_speed_reason: "mean".into(),
            mean_forward_speed_mps: Some(0.52),
            excited_dofs: vec![Dof::Sway],
            excited_dofs_reason: "variance".into(),
            signal: RunSignal::Prbs,
            signal_reason: "chips".into(),
            dofs: vec![],
        }
    }

    #[test]
    fn user_wins_over_plan_and_plan_over_inference() {
        let inf = inferred(RunRole::Dynamic, ExperimentFamily::Dynamic);
        let d = describe_run(&UserDescription::default(), None, Some(&inf));
        assert_eq!(d.role.as_ref().unwrap().source, Source::Inferred);
        assert_eq!(d.grid_speed_mps.as_ref().unwrap().value, 0.5);
        assert_eq!(d.family, Some(ExperimentFamily::Dynamic));
        assert!(d.notes.is_none());

        let plan = PlanDescription {
            code: "STA-1kn-sway+-r1".into(),
            family: ExperimentFamily::Static,
            grid_speed_mps: Some(KNOT),
            excited_dofs: vec![Dof::Sway],
            signal: RunSignal::Other,
        };
        let d = describe_run(&UserDescription::default(), Some(&plan), Some(&inf));
        let role = d.role.unwrap();
        assert_eq!((role.value, role.source), (RunRole::Static, Source::Plan));
        assert!(role.reason.unwrap().contains("STA-1kn-sway+-r1"));
        assert_eq!(d.family, Some(ExperimentFamily::Static));

        let user = UserDescription {
            role: Some(RunRole::Validation),
            grid_speed_mps: Some(1.0),
            notes: Some("flown by the night shift".into()),
            ..UserDescription::default()
        };
        let d = describe_run(&user, Some(&plan), Some(&inf));
        assert_eq!(d.role.as_ref().unwrap().source, Source::User);
        assert_eq!(d.family, Some(ExperimentFamily::Validation));
        assert_eq!(d.grid_speed_mps.unwrap().value, 1.0);
        assert_eq!(d.excited_dofs.unwrap().source, Source::Plan);
        assert_eq!(d.notes.unwrap().source, Source::User);
    }

    #[test]
    fn a_dp_manoeuvre_survives_a_role_that_agrees_with_it() {
        let inf = inferred(RunRole::Dynamic, ExperimentFamily::DpSwayYaw);
        let user = UserDescription {
            role: Some(RunRole::Dynamic),
            ..UserDescription::default()
        };
        assert_eq!(
            describe_run(&user, None, Some(&inf)).family,
            Some(ExperimentFamily::DpSwayYaw)
        );
        let plan = PlanDescription {
            code: "SI1-r1".into(),
            family: ExperimentFamily::DpSurge,
            grid_speed_mps: Some(0.0),
            excited_dofs: vec![Dof::Surge],
            signal: RunSignal::Prbs,
        };
        let d = describe_run(&user, Some(&plan), Some(&inf));
        assert_eq!(d.family, Some(ExperimentFamily::DpSurge));
        assert_eq!(RunRole::from_name("recursive"), Some(RunRole::Recursive));
        assert_eq!(
            RunSignal::from_name("random_binary"),
            Some(RunSignal::RandomBinary)
        );
        assert!(RunRole::from_name("dynamics").is_none());
    }
}
