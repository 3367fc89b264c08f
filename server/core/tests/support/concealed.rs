//! The concealed effects of the open-world discovery cases: what each
//! switches on in the independent truth (`seatrial-truth`), what discovery
//! must call it, its true size, and which labels name physics the truth
//! has anyway.

#![allow(dead_code)]

use nalgebra::{Vector3, Vector6};
use seatrial_core::discrepancy::Effect;
use seatrial_core::planning::dof::Dof;
use seatrial_truth::rng::{Rng, derive_seed};
use seatrial_truth::vessel::{CurrentDrift, Disturbance};
use seatrial_truth::{Campaign, Vessel};

/// The effect concealed from the λ model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Concealed {
    /// The drawn vessel as it is.
    Clean,
    /// A steady current of 0.25 m/s north, 0.15 m/s east.
    Current,
    /// A tether pull fixed in NED (it leads to the ship), of 30 % of the
    /// clean campaign's RMS sway command, towards a bearing drawn from the
    /// seed: in the body frame it turns with the heading, which the
    /// baseline's constant loads cannot follow.
    Tether,
    /// Thrusters following the command through a 0.4 s first-order lag in
    /// every DOF.
    Lag,
    /// Heave thrust clipped at 60 % of the clean campaign's largest heave
    /// command.
    Saturation,
    /// Quadratic sway damping four times the drawn one.
    QuadraticSway,
    /// The thrust acting a pure transport delay after the command in every
    /// DOF: d drawn from the seed in [0.2, 0.4] s, on the integrator's
    /// step (5 ms), so the truth's delay is exact.
    Delay,
    /// A heave dead zone: no thrust for |τ_cmd| < δ, τ_cmd − sign(τ_cmd)·δ
    /// beyond, δ a seeded 15–25 % of the clean campaign's RMS heave command.
    DeadZone,
    /// A sinusoidal sway force fixed in the body frame, at a seeded
    /// 0.08–0.12 Hz and phase, of 30 % of the clean campaign's RMS sway
    /// command: nothing in the library, to be reported as unexplained and
    /// not named.
    Disturbance,
    /// A current of mean 0.25 m/s north, 0.15 m/s east whose north and
    /// east parts drift as slow sinusoids (seeded amplitudes 0.08–0.12 m/s,
    /// periods 300–600 s, phases): its direction and speed wander.
    DriftingCurrent,
    /// The small tier: a 0.04 s first-order actuator lag in every DOF,
    /// under half a log sample at 10 Hz.
    SmallLag,
    /// The small tier: a 0.04 s input delay in every DOF.
    SmallDelay,
    /// The small tier: heave thrust clipped at 70 % of the clean
    /// campaign's largest heave command (a mild saturation).
    MildSaturation,
    /// The small tier: a heave dead zone of a seeded 5–10 % of the clean
    /// campaign's RMS heave command.
    SmallDeadZone,
    /// The small tier: a steady current of 0.05 m/s (0.04 north, 0.03
    /// east).
    SmallCurrent,
    /// The small tier: quadratic yaw damping twice the drawn one, half the
    /// large tier's fourfold.
    QuadraticYaw,
}

impl Concealed {
    pub const ALL: [Concealed; 10] = [
        Concealed::Clean,
        Concealed::Current,
        Concealed::Tether,
        Concealed::Lag,
        Concealed::Saturation,
        Concealed::QuadraticSway,
        Concealed::Delay,
        Concealed::DeadZone,
        Concealed::Disturbance,
        Concealed::DriftingCurrent,
    ];

    /// The small tier of the sensitivity goal, each effect at the
    /// size it names.
    pub const SMALL: [Concealed; 6] = [
        Concealed::SmallLag,
        Concealed::SmallDelay,
        Concealed::MildSaturation,
        Concealed::SmallDeadZone,
        Concealed::SmallCurrent,
        Concealed::QuadraticYaw,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Concealed::Clean => "clean",
            Concealed::Current => "current",
            Concealed::Tether => "tether",
            Concealed::Lag => "actuator lag",
            Concealed::Saturation => "saturation",
            Concealed::QuadraticSway => "quadratic sway damping",
            Concealed::Delay => "input delay",
            Concealed::DeadZone => "dead zone",
            Concealed::Disturbance => "sway disturbance",
            Concealed::DriftingCurrent => "drifting current",
            Concealed::SmallLag => "small actuator lag",
            Concealed::SmallDelay => "small input delay",
            Concealed::MildSaturation => "mild saturation",
            Concealed::SmallDeadZone => "small dead zone",
            Concealed::SmallCurrent => "small current",
            Concealed::QuadraticYaw => "quadratic yaw damping",
        }
    }

    /// Whether the case is graded like the clean one: nothing to name, so
    /// every label that is not physics the truth has is false.
    pub fn nothing_to_name(self) -> bool {
        matches!(self, Concealed::Clean | Concealed::Disturbance)
    }

    /// Whether `e` names this effect (`Some(true)`), a look-alike at the
    /// right place (`Some(false)`: lag ↔ delay, a body-fixed load for the
    /// tether's pull, cubic for quadratic drag in the same DOF), or
    /// something else (`None`). The sway disturbance has no name in the
    /// library: everything is `None`.
    pub fn names(self, e: &Effect) -> Option<bool> {
        match (self, e) {
            (Concealed::Current | Concealed::SmallCurrent, Effect::Current) => Some(true),
            (Concealed::Tether, Effect::TetherPull) => Some(true),
            (
                Concealed::Tether,
                Effect::ConstantLoad {
                    dof: Dof::Surge | Dof::Sway,
                },
            ) => Some(false),
            (
                Concealed::Lag | Concealed::SmallLag,
                Effect::ActuatorLag { .. } | Effect::CommonActuatorLag,
            ) => Some(true),
            (
                Concealed::Lag | Concealed::SmallLag,
                Effect::InputDelay { .. } | Effect::CommonInputDelay,
            ) => Some(false),
            (
                Concealed::Saturation | Concealed::MildSaturation,
                Effect::Saturation { dof: Dof::Heave },
            ) => Some(true),
            (Concealed::QuadraticYaw, Effect::QuadraticDamping { dof: Dof::Yaw }) => Some(true),
            (Concealed::QuadraticYaw, Effect::CubicDamping { dof: Dof::Yaw }) => Some(false),
            (Concealed::QuadraticSway, Effect::QuadraticDamping { dof: Dof::Sway }) => Some(true),
            (Concealed::QuadraticSway, Effect::CubicDamping { dof: Dof::Sway }) => Some(false),
            (
                Concealed::Delay | Concealed::SmallDelay,
                Effect::InputDelay { .. } | Effect::CommonInputDelay,
            ) => Some(true),
            (
                Concealed::Delay | Concealed::SmallDelay,
                Effect::ActuatorLag { .. } | Effect::CommonActuatorLag,
            ) => Some(false),
            (
                Concealed::DeadZone | Concealed::SmallDeadZone,
                Effect::DeadZone { dof: Dof::Heave },
            ) => Some(true),
            (Concealed::DriftingCurrent, Effect::Current) => Some(true),
            _ => None,
        }
    }

    /// The concealed effect's true size in the units discovery reports.
    pub fn truth_text(self, vessel: &Vessel) -> String {
        match self {
            Concealed::Clean => "none concealed".into(),
            Concealed::Current | Concealed::SmallCurrent => format!(
                "V_N {:.3}, V_E {:.3} m/s",
                vessel.current_ned.x, vessel.current_ned.y
            ),
            Concealed::Tether => format!(
                "F_N {:.1}, F_E {:.1} N",
                vessel.tether_ned.x, vessel.tether_ned.y
            ),
            Concealed::Lag => "T_a 0.4 s in every DOF".into(),
            Concealed::SmallLag => "T_a 0.04 s in every DOF".into(),
            Concealed::Saturation | Concealed::MildSaturation => format!(
                "heave τ_max {:.1} N",
                vessel.actuator.limits.map_or(f64::NAN, |l| l[2])
            ),
            Concealed::QuadraticSway => format!(
                "d_v|v| {:.1} N·s²/m² (drawn {:.1})",
                vessel.damping_quadratic[1],
                vessel.damping_quadratic[1] / 4.0
            ),
            Concealed::QuadraticYaw => format!(
                "d_r|r| {:.1} N·m·s²/rad² (drawn {:.1})",
                vessel.damping_quadratic[5],
                vessel.damping_quadratic[5] / 2.0
            ),
            Concealed::Delay | Concealed::SmallDelay => {
                let d = vessel.actuator.delay_s.unwrap_or(f64::NAN);
                format!(
                    "d {d:.3} s = {:.2} log samples (10 Hz) in every DOF",
                    d / 0.1
                )
            }
            Concealed::DeadZone | Concealed::SmallDeadZone => format!(
                "heave δ {:.1} N",
                vessel.actuator.dead_zone.map_or(f64::NAN, |d| d[2])
            ),
            Concealed::Disturbance => match &vessel.disturbance {
                Some(d) => format!(
                    "sway {:.1} N at {:.4} Hz (period {:.1} s), body-fixed, not in the library",
                    d.amplitude[1],
                    d.frequency_hz,
                    1.0 / d.frequency_hz
                ),
                None => "none".into(),
            },
            Concealed::DriftingCurrent => match &vessel.current_drift {
                Some(d) => {
                    let axis = |k: usize, name: &str| {
                        let (m, a) = (vessel.current_ned[k], d.amplitude[k]);
                        format!(
                            "{name} {m:.3} ± {a:.3} ({:.3} to {:.3}, period {:.0} s)",
                            m - a,
                            m + a,
                            d.period_s[k]
                        )
                    };
                    format!("{}, {} m/s", axis(0, "V_N"), axis(1, "V_E"))
                }
                None => "none".into(),
            },
        }
    }

    /// The vessel with the effect switched on.
    pub fn apply(self, vessel: &mut Vessel, clean: &Campaign) {
        match self {
            Concealed::Clean => {}
            Concealed::Current => vessel.current_ned = Vector3::new(0.25, 0.15, 0.0),
            Concealed::Tether => {
                let (sum, n) = clean.runs.iter().fold((0.0, 0usize), |(s, n), r| {
                    let c = r.log.tau.column(1);
                    (s + c.iter().map(|x| x * x).sum::<f64>(), n + c.len())
                });
                let size = 0.3 * (sum / n.max(1) as f64).sqrt();
                let bearing = (seed_bearing(vessel.mass)).to_radians();
                vessel.tether_ned = Vector3::new(size * bearing.cos(), size * bearing.sin(), 0.0);
            }
            Concealed::Lag => vessel.actuator.lag_s = Some(Vector6::repeat(0.4)),
            Concealed::SmallLag => vessel.actuator.lag_s = Some(Vector6::repeat(0.04)),
            Concealed::Saturation | Concealed::MildSaturation => {
                let peak = clean
                    .runs
                    .iter()
                    .map(|r| r.log.tau.column(2).amax())
                    .fold(0.0, f64::max);
                let share = if self == Concealed::Saturation {
                    0.6
                } else {
                    0.7
                };
                let mut lim = Vector6::repeat(f64::INFINITY);
                lim[2] = share * peak;
                vessel.actuator.limits = Some(lim);
            }
            Concealed::SmallCurrent => vessel.current_ned = Vector3::new(0.04, 0.03, 0.0),
            Concealed::QuadraticYaw => vessel.damping_quadratic[5] *= 2.0,
            Concealed::SmallDelay => {
                let h = 1.0 / clean.spec.integration_rate_hz;
                vessel.actuator.delay_s = Some((0.04 / h).round() * h);
            }
            Concealed::SmallDeadZone => {
                let mut rng = case_rng(clean, 5);
                let mut delta = Vector6::zeros();
                delta[2] = rng.range(0.05, 0.10) * rms_command(clean, 2);
                vessel.actuator.dead_zone = Some(delta);
            }
            Concealed::QuadraticSway => vessel.damping_quadratic[1] *= 4.0,
            Concealed::Delay => {
                let mut rng = case_rng(clean, 1);
                // on the integrator's step: the truth's delay is then exact
                let h = 1.0 / clean.spec.integration_rate_hz;
                vessel.actuator.delay_s = Some((rng.range(0.2, 0.4) / h).round() * h);
            }
            Concealed::DeadZone => {
                let mut rng = case_rng(clean, 2);
                let mut delta = Vector6::zeros();
                delta[2] = rng.range(0.15, 0.25) * rms_command(clean, 2);
                vessel.actuator.dead_zone = Some(delta);
            }
            Concealed::Disturbance => {
                let mut rng = case_rng(clean, 3);
                let frequency_hz = rng.range(0.08, 0.12);
                let phase = rng.range(0.0, std::f64::consts::TAU);
                let mut amplitude = Vector6::zeros();
                amplitude[1] = 0.3 * rms_command(clean, 1);
                vessel.disturbance = Some(Disturbance {
                    amplitude,
                    frequency_hz,
                    phase,
                });
            }
            Concealed::DriftingCurrent => {
                let mut rng = case_rng(clean, 4);
                let mut drift = CurrentDrift {
                    amplitude: Vector3::zeros(),
                    period_s: Vector3::zeros(),
                    phase: Vector3::zeros(),
                };
                for k in 0..2 {
                    drift.amplitude[k] = rng.range(0.08, 0.12);
                    drift.period_s[k] = rng.range(300.0, 600.0);
                    drift.phase[k] = rng.range(0.0, std::f64::consts::TAU);
                }
                vessel.current_ned = Vector3::new(0.25, 0.15, 0.0);
                vessel.current_drift = Some(drift);
            }
        }
    }
}

/// The draws of a case's effect, from the campaign seed and the case.
fn case_rng(clean: &Campaign, case: u64) -> Rng {
    Rng::new(derive_seed(clean.seed, 0x0C0_4CEA1 + case))
}

/// The RMS of the logged command in DOF `j` over the clean campaign.
fn rms_command(clean: &Campaign, j: usize) -> f64 {
    let (sum, n) = clean.runs.iter().fold((0.0, 0usize), |(s, n), r| {
        let c = r.log.tau.column(j);
        (s + c.iter().map(|x| x * x).sum::<f64>(), n + c.len())
    });
    (sum / n.max(1) as f64).sqrt()
}

/// A bearing (°) from the drawn vessel, so each seed pulls its own way.
fn seed_bearing(mass: f64) -> f64 {
    (mass * 137.508).rem_euclid(360.0)
}

/// Whether the truth has `e` as physics of its own, beyond the concealed
/// effect: quadratic damping in every DOF (a cubic term approximates it),
/// linear damping growing with |u| (cross-flow |u|ν_i), C(ν)ν from M, g(η),
/// the heave load W − B, and the couplings z_G puts in M_RB. Naming one of
/// these is not a false label, though it is not the concealed effect.
pub fn in_truth(vessel: &Vessel, e: &Effect) -> bool {
    let i = |d: Dof| d.index();
    match *e {
        Effect::QuadraticDamping { dof } | Effect::CubicDamping { dof } => {
            vessel.damping_quadratic[i(dof)] > 0.0
        }
        Effect::CrossDamping {
            dof,
            from: Dof::Surge,
        } => vessel.damping_linear_per_speed[i(dof)] > 0.0,
        Effect::CoriolisFromM | Effect::CoriolisProduct { .. } | Effect::Restoring { .. } => true,
        Effect::ConstantLoad { dof: Dof::Heave } => vessel.w_minus_b != 0.0,
        Effect::Coupling { dof, from } => {
            let m = vessel.m();
            m[(i(dof), i(from))] != 0.0
        }
        _ => false,
    }
}

/// The truth's own value of a coefficient discovery reports for physics
/// the truth has: a Coriolis product's coefficient (the mixed term of the
/// quadratic C(ν)ν, Fossen 2011 eq. 6.43, from the truth's M) or a
/// quadratic damping coefficient.
pub fn truth_coefficient(vessel: &Vessel, e: &Effect) -> Option<f64> {
    match *e {
        Effect::CoriolisProduct { dof, a, b } if a != b => {
            let m = vessel.m();
            let f = |i: Option<usize>, j: Option<usize>| {
                let mut nu = Vector6::zeros();
                for k in [i, j].into_iter().flatten() {
                    nu[k] = 1.0;
                }
                seatrial_truth::forces::coriolis_force(&m, &nu)[dof.index()]
            };
            let (ia, ib) = (Some(a.index()), Some(b.index()));
            Some(f(ia, ib) - f(ia, None) - f(None, ib) + f(None, None))
        }
        Effect::QuadraticDamping { dof } => Some(vessel.damping_quadratic[dof.index()]),
        _ => None,
    }
}
