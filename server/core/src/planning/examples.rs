//! Reference vessels from the two source documents, used for the demo
//! campaign and as test fixtures.

use std::collections::BTreeMap;

use super::campaign::{
    CampaignSpec, Durations, Excitation, ExperimentFamily, SpeedGrid, SpeedUnit,
};
use super::dof::{Dof, KNOT};
use super::vessel::{
    DofLimits, DpPrior, InputChannels, Thruster, ThrusterKind, VesselKind, VesselProfile,
};

/// The Surveyor ROV of the thesis (≈ 5 t, 9 hydraulic thrusters, τ logged per
/// DOF, 20 Hz controller logged at 10 Hz). Velocity limits follow the
/// experiment plan of ch. 3: sway/heave ±1.5 kn, roll/pitch/yaw ±0.3 rad/s,
/// forward speed up to 4.3 kn. Forces and time constants are engineering
/// guesses for a vehicle of that size; the pilots override them.
pub fn surveyor_rov() -> VesselProfile {
    let lin = |v: f64, f: f64, t: f64| DofLimits {
        max_velocity: v,
        max_force: f,
        max_force_rate: f / 2.0,
        max_accel: Some(0.3),
        time_constant_s: t,
        max_angle: None,
    };
    let ang = |f: f64, t: f64| DofLimits {
        max_velocity: 0.3,
        max_force: f,
        max_force_rate: f / 2.0,
        max_accel: Some(0.3),
        time_constant_s: t,
        max_angle: None,
    };
    let limits = BTreeMap::from([
        (Dof::Surge, lin(4.3 * KNOT, 10_000.0, 4.0)),
        (Dof::Sway, lin(1.5 * KNOT, 6_000.0, 3.0)),
        (Dof::Heave, lin(1.5 * KNOT, 8_000.0, 3.0)),
        (Dof::Roll, ang(5_000.0, 1.5)),
        (Dof::Pitch, ang(5_000.0, 1.5)),
        (Dof::Yaw, ang(5_000.0, 2.0)),
    ]);
    VesselProfile {
        name: "Surveyor ROV".into(),
        kind: VesselKind::Rov6,
        dofs: Dof::ALL.to_vec(),
        inputs: InputChannels::GeneralizedForces,
        limits,
        controller_rate_hz: 20.0,
        logger_rate_hz: 10.0,
        dp_prior: None,
        heading_unit: None,
        autopilot: None,
    }
}

/// Fossen, Sagatun & Sørensen's supply vessel (L = 76.2 m): two main
/// propellers, three tunnel thrusters, one azimuth at α = 90°, with the
/// thruster configuration matrix T″ of eq. 29 and the inertia M″ of eq. 30
/// (non-dimensional, Bis system).
/// Time constants follow the identified A″ of eq. 51 scaled by √(L/g):
/// surge 2.787/0.0318 ≈ 88 s, sway 2.787/0.0628 ≈ 44 s, yaw 2.787/0.2428 ≈ 11 s.
pub fn supply_vessel() -> VesselProfile {
    let time_unit = (76.2_f64 / 9.81).sqrt();
    let dof = |v: f64, f: f64, a_ii: f64| DofLimits {
        max_velocity: v,
        max_force: f,
        max_force_rate: f / 10.0,
        max_accel: None,
        time_constant_s: time_unit / a_ii,
        max_angle: None,
    };
    let limits = BTreeMap::from([
        (Dof::Surge, dof(4.0, 1.3e6, 0.0318)),
        (Dof::Sway, dof(1.0, 5.5e5, 0.0628)),
        (Dof::Yaw, dof(0.035, 1.6e7, 0.2428)),
    ]);
    let thr = example_thruster;
    VesselProfile {
        name: "Supply vessel (Fossen et al. 1995)".into(),
        kind: VesselKind::Dp3,
        dofs: Dof::HORIZONTAL.to_vec(),
        inputs: InputChannels::Thrusters {
            thrusters: vec![
                thr("port main propeller", ThrusterKind::Main),
                thr("starboard main propeller", ThrusterKind::Main),
                thr("aft tunnel thruster I", ThrusterKind::Tunnel),
                thr("aft tunnel thruster II", ThrusterKind::Tunnel),
                thr("bow tunnel thruster", ThrusterKind::Tunnel),
                thr("bow azimuth thruster", ThrusterKind::Azimuth),
            ],
            configuration: vec![
                vec![1.0, 1.0, 0.0, 0.0, 0.0, 0.0],
                vec![0.0, 0.0, 1.0, 1.0, 1.0, 1.0],
                vec![0.0472, -0.0472, -0.4108, -0.3858, 0.4554, 0.3373],
            ],
        },
        limits,
        controller_rate_hz: 1.0,
        logger_rate_hz: 1.0,
        // M″ of eq. 30 (semi-empirical added mass, Faltinsen 1990).
        dp_prior: Some(DpPrior {
            length_m: 76.2,
            inertia_bis: Some(vec![
                vec![1.1274, 0.0, 0.0],
                vec![0.0, 1.8902, -0.0744],
                vec![0.0, -0.0744, 0.1278],
            ]),
        }),
        heading_unit: None,
        autopilot: None,
    }
}

/// A thruster with full command 1 slewed at 10 %/s, no coefficient group.
fn example_thruster(name: &str, kind: ThrusterKind) -> Thruster {
    Thruster {
        name: name.into(),
        kind,
        max_command: 1.0,
        max_rate: 0.1,
        coefficient_group: None,
        signal: Default::default(),
        logged_angle: None,
    }
}

/// The supply vessel's hull with two tunnels (bow at x = 0.45 L, stern at
/// x = −0.40 L) and two aft azimuths at (−0.45 L, ∓0.06 L) fixed at ±30°,
/// T″ in Bis: a layout outside the paper's, for tests and the docs.
pub fn supply_vessel_azimuths_tunnels() -> VesselProfile {
    let mut p = supply_vessel();
    p.name = "Supply vessel, two tunnels and two azimuths".into();
    let thr = example_thruster;
    p.inputs = InputChannels::Thrusters {
        thrusters: vec![
            thr("bow tunnel", ThrusterKind::Tunnel),
            thr("stern tunnel", ThrusterKind::Tunnel),
            thr("port azimuth", ThrusterKind::Azimuth),
            thr("starboard azimuth", ThrusterKind::Azimuth),
        ],
        configuration: vec![
            vec![0.0, 0.0, 0.866, 0.866],
            vec![1.0, 1.0, 0.5, -0.5],
            vec![0.45, -0.4, -0.173, 0.173],
        ],
    };
    p
}

/// The thesis's campaign for the Surveyor: grid {0.5, …, 3.5} kn (4.0 kn
/// proved unsafe, thesis sec. 1.6), all four ROV families, one repetition.
pub fn surveyor_campaign(seed: u64) -> CampaignSpec {
    CampaignSpec {
        name: "Surveyor ROV – LPV campaign 0.5–3.5 kn".into(),
        grid: SpeedGrid {
            unit: SpeedUnit::Knots,
            speeds: vec![0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5],
        },
        families: vec![
            ExperimentFamily::Static,
            ExperimentFamily::Dynamic,
            ExperimentFamily::Recursive,
            ExperimentFamily::Validation,
        ],
        repetitions: None,
        excitation: Excitation::default(),
        durations: Durations::default(),
        seed,
        deciding: Vec::new(),
    }
}

/// Fossen et al.'s three decoupled manoeuvres SI1 → SI2 → SI3 at rest,
/// N = 2 each for the parallel EKF.
pub fn supply_vessel_campaign(seed: u64) -> CampaignSpec {
    CampaignSpec {
        name: "Supply vessel – decoupled DP manoeuvres SI1→SI2→SI3".into(),
        grid: SpeedGrid {
            unit: SpeedUnit::MetersPerSecond,
            speeds: vec![0.0],
        },
        families: vec![
            ExperimentFamily::DpSurge,
            ExperimentFamily::DpSwayYaw,
            ExperimentFamily::DpAzimuth,
        ],
        repetitions: Some(2),
        excitation: Excitation::default(),
        durations: Durations::default(),
        seed,
        deciding: Vec::new(),
    }
}

/// The supply vessel's full trial campaign: SI1–SI3 (N = 2) and a 600 s
/// validation run held out for the model check (the demo's DP campaign).
pub fn supply_vessel_trial_campaign(seed: u64) -> CampaignSpec {
    let mut c = supply_vessel_campaign(seed);
    c.families.push(ExperimentFamily::Validation);
    c.durations.validation_s = 600.0;
    c
}

/// A deciding experiment as discovery proposes one (see
/// `CampaignSpec::deciding`): every DOF's force column, `dof` a square wave
/// of `amplitude` × its force limit about a surge offset of 0.3 × the surge
/// limit, the others held; 120 s legs at `headings` (deg).
pub fn deciding_proposal(
    v: &VesselProfile,
    dof: Dof,
    amplitude: f64,
    headings: Vec<f64>,
) -> crate::discrepancy::experiment::ExperimentProposal {
    let channels = v
        .dofs
        .iter()
        .map(|&d| {
            let l = v.limit(d);
            let excited = d == dof;
            super::plan::ChannelPlan {
                column: d.force_column().into(),
                unit: d.force_unit().into(),
                dof: Some(d),
                thruster: None,
                excited,
                waveform: if excited {
                    super::waveform::Waveform::Square {
                        period_s: 10.0 * l.time_constant_s,
                    }
                } else {
                    super::waveform::Waveform::Constant
                },
                offset: if d == Dof::Surge {
                    0.3 * l.max_force
                } else {
                    0.0
                },
                amplitude: if excited {
                    amplitude * l.max_force
                } else {
                    0.0
                },
                limit: l.max_force,
                rate_limit: Some(l.max_force_rate),
                analysis: None,
            }
        })
        .collect();
    crate::discrepancy::experiment::ExperimentProposal {
        separates: ["quadratic damping in sway".into(), "Coriolis from M".into()],
        family: ExperimentFamily::Dynamic,
        dof,
        signal: super::SignalKind::Square,
        grid_speed_mps: 0.4,
        headings_deg: headings,
        duration_s: 120.0,
        channels,
        predicted_separation_sigma: 6.5,
        instruction: "sway square wave at a steady surge offset".into(),
    }
}
