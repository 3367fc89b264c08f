//! Other thruster layouts and logs on the DP ship of [`crate::dp_ship`]: the
//! same hull (M″, A″_h, C(ν), bias random walk, noise, 1 Hz sampling, the
//! [`DpInputs`](crate::dp_ship::DpInputs) of the trial), flown and logged
//! three ways.
//!
//! - [`DpLayout::Paper`]: the paper's six thrusters, exactly
//!   [`fly_dp_campaign`](crate::dp_ship::fly_dp_campaign).
//! - [`DpLayout::AzimuthsTunnels`]: four thrusters, T″ = [`AZ_T`],
//!   K″ = [`AZ_K`]: bow and stern tunnels and two aft azimuths fixed at
//!   ±30°. SI1 (`dp_surge`) drives both azimuths with one command, so
//!   their sway forces and yaw moments cancel; SI2 (`dp_sway_yaw`) drives
//!   the stern tunnel against the bow tunnel as the paper's SI2 drives the
//!   aft tunnels against the bow tunnel; there is no SI3; validation drives
//!   all four independently. Header
//!   `t,thr_1,thr_2,thr_3,thr_4,x,y,psi[,u,v,r]`.
//! - [`DpLayout::AzimuthsTunnelsShaftSpeed`]: the same four thrusters as
//!   fixed-pitch propellers whose logger records shaft speed (rpm,
//!   [`AZ_RATED_RPM`]) instead of the command: n = sign(u)·√|u|·n_rated,
//!   two decimals. Same header.
//! - [`DpLayout::SteeredAzimuths`]: the four thrusters with the aft
//!   azimuths turning during each run (levels held 60–180 s; SI1 turns
//!   them mirrored so that sway and yaw still cancel, validation each
//!   alone) and logging their angle: header
//!   `t,thr_1,thr_2,thr_3,thr_4,azi_3,azi_4,x,y,psi[,u,v,r]`, degrees.
//! - [`DpLayout::Forces`]: the paper's thrusters and commands, but the log
//!   carries the commanded generalized forces τ = T″K″u in SI (the bias b
//!   is the disturbance and is not included): τ_X, τ_Y = τ″·m·g (N),
//!   τ_N = τ″_N·m·g·L (N·m), m = [`DISPLACEMENT_KG`]. Header
//!   `t,tau_X,tau_Y,tau_N,x,y,psi[,u,v,r]`, forces written with 13
//!   significant digits.
//!
//! Thruster geometry in Bis: a thruster at body position (x, y) (in L, y to
//! starboard) pushing at angle α from the bow has the T″ column
//! (cos α, sin α, x·sin α − y·cos α).

use crate::dp_ship::{
    DpLog, DpManoeuvre, DpTrial, Group, Layout, Logged, PAPER, Steering, fly_layout,
};
use crate::rng::Rng;

/// Displacement mass m (kg) that turns Bis forces into N (m·g) and moments
/// into N·m (m·g·L). Fossen, Sagatun & Sørensen (1995) give no displacement
/// (nor L) for the supply vessel, so 4.591e6 kg is an assumed value, not
/// the paper's. Fossen's MSS `supply.m`, for the same Bis model and L = 76.2 m,
/// uses 6.0e6 kg instead.
pub const DISPLACEMENT_KG: f64 = 4.591e6;

/// cos 30° = √3/2.
const COS30: f64 = 0.866_025_403_784_438_6;
/// Yaw arm of the aft azimuths: x·sin α − y·cos α at (−0.45, ∓0.06), ±30°.
const AZ_ARM: f64 = 0.173_038_475_772_933_7;

/// T″ of [`DpLayout::AzimuthsTunnels`]: bow tunnel (x = 0.45 L, α = 90°),
/// stern tunnel (x = −0.40 L, α = 90°), port aft azimuth (−0.45 L,
/// −0.06 L) at α = +30°, starboard aft azimuth (−0.45 L, +0.06 L) at −30°.
pub const AZ_T: [[f64; 4]; 3] = [
    [0.0, 0.0, COS30, COS30],
    [1.0, 1.0, 0.5, -0.5],
    [0.45, -0.40, -AZ_ARM, AZ_ARM],
];
/// K″ of [`DpLayout::AzimuthsTunnels`]: bow tunnel, stern tunnel, and one
/// coefficient shared by the two azimuths.
pub const AZ_K: [f64; 4] = [2.4e-3, 2.0e-3, 6.0e-3, 6.0e-3];

/// Rated shaft speeds (rpm) of [`DpLayout::AzimuthsTunnelsShaftSpeed`]:
/// bow and stern tunnels, the two azimuths.
pub const AZ_RATED_RPM: [f64; 4] = [320.0, 290.0, 180.0, 180.0];

/// Which thrusters a campaign flies and what its logs carry.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DpLayout {
    /// The paper's six thrusters, commands logged
    /// ([`fly_dp_campaign`](crate::dp_ship::fly_dp_campaign)).
    Paper,
    /// Two tunnels and two aft azimuths ([`AZ_T`], [`AZ_K`]), commands
    /// logged; SI1, SI2 and validation only.
    AzimuthsTunnels,
    /// [`DpLayout::AzimuthsTunnels`] logging shaft speeds
    /// ([`AZ_RATED_RPM`]).
    AzimuthsTunnelsShaftSpeed,
    /// [`DpLayout::AzimuthsTunnels`] with the aft azimuths turning during
    /// each run and logging their angle (`azi_3`, `azi_4`, degrees).
    SteeredAzimuths,
    /// The paper's thrusters and commands, generalized forces logged.
    Forces,
}

/// The four-thruster layout.
const AZIMUTHS_TUNNELS: Layout = Layout {
    t: [&AZ_T[0], &AZ_T[1], &AZ_T[2]],
    k: &AZ_K,
    runs: &[(DpManoeuvre::Surge, "SI1"), (DpManoeuvre::SwayYaw, "SI2")],
    plan: azimuths_tunnels_plan,
    logged: Logged::Commands,
    steering: None,
};

/// The aft azimuths of [`AZIMUTHS_TUNNELS`] at their positions (in L).
const AFT_AZIMUTHS: [(usize, f64, f64); 2] = [(2, -0.45, -0.06), (3, -0.45, 0.06)];

/// Angles of [`DpLayout::SteeredAzimuths`]: levels held 60–180 s. SI1
/// turns both azimuths together, port at +a and starboard at −a with a in
/// 15°–45°, so their sway forces and yaw moments still cancel; validation
/// turns each alone (port 10°–60°, starboard −60° … −10°); SI2 holds them
/// at ±30° (idle).
fn steered_angles(kind: DpManoeuvre, n: usize, rng: &mut Rng) -> Vec<Vec<f64>> {
    let deg = std::f64::consts::PI / 180.0;
    let levels = |rng: &mut Rng, lo: f64, hi: f64| {
        let mut out = Vec::with_capacity(n);
        while out.len() < n {
            let hold = rng.range(60.0, 180.0) as usize;
            let a = rng.range(lo, hi) * deg;
            out.extend(std::iter::repeat_n(a, hold.min(n - out.len())));
        }
        out
    };
    match kind {
        DpManoeuvre::Surge => levels(rng, 15.0, 45.0)
            .into_iter()
            .map(|a| vec![a, -a])
            .collect(),
        DpManoeuvre::Validation => {
            let port = levels(rng, 10.0, 60.0);
            let starboard = levels(rng, -60.0, -10.0);
            port.into_iter()
                .zip(starboard)
                .map(|(p, s)| vec![p, s])
                .collect()
        }
        _ => vec![vec![30.0 * deg, -30.0 * deg]; n],
    }
}

/// Groups of the four-thruster manoeuvres: both azimuths on one command
/// (SI1, levels as the paper's mains), the stern tunnel against the bow
/// tunnel (SI2, as the paper's aft tunnels against its bow tunnel), and
/// each thruster alone (validation). No SI3: there is no azimuth to turn.
fn azimuths_tunnels_plan(kind: DpManoeuvre) -> &'static [Group] {
    const TUNNEL: (f64, f64) = (40.0, 120.0);
    const MAIN: (f64, f64) = (80.0, 160.0);
    match kind {
        DpManoeuvre::Surge => &[Group {
            cols: &[2, 3],
            hold: MAIN,
            level: (0.3, 0.6),
        }],
        DpManoeuvre::SwayYaw => &[
            Group {
                cols: &[1],
                hold: TUNNEL,
                level: (0.4, 1.0),
            },
            Group {
                cols: &[0],
                hold: TUNNEL,
                level: (0.4, 1.0),
            },
        ],
        DpManoeuvre::Azimuth => &[],
        DpManoeuvre::Validation => &[
            Group {
                cols: &[0],
                hold: TUNNEL,
                level: (0.3, 0.8),
            },
            Group {
                cols: &[1],
                hold: TUNNEL,
                level: (0.3, 0.8),
            },
            Group {
                cols: &[2],
                hold: MAIN,
                level: (0.2, 0.4),
            },
            Group {
                cols: &[3],
                hold: MAIN,
                level: (0.2, 0.4),
            },
        ],
    }
}

/// The campaign of seed `seed` on `layout`: `repetitions` runs of each SI
/// manoeuvre of the layout (SI1–SI3 for the paper's thrusters, SI1–SI2 for
/// [`DpLayout::AzimuthsTunnels`]), then `validation_runs` validation runs,
/// named and seeded as
/// [`fly_dp_campaign`](crate::dp_ship::fly_dp_campaign) does.
pub fn fly_dp_layout_campaign(trial: &DpTrial, layout: DpLayout, seed: u64) -> Vec<DpLog> {
    let layout = match layout {
        DpLayout::Paper => PAPER,
        DpLayout::AzimuthsTunnels => AZIMUTHS_TUNNELS,
        DpLayout::AzimuthsTunnelsShaftSpeed => Layout {
            logged: Logged::ShaftSpeed(&AZ_RATED_RPM),
            ..AZIMUTHS_TUNNELS
        },
        DpLayout::SteeredAzimuths => Layout {
            steering: Some(Steering {
                azimuths: &AFT_AZIMUTHS,
                angles: steered_angles,
            }),
            ..AZIMUTHS_TUNNELS
        },
        DpLayout::Forces => Layout {
            logged: Logged::Forces(DISPLACEMENT_KG),
            ..PAPER
        },
    };
    fly_layout(trial, &layout, seed)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dp_ship::{
        A_H, DpInputs, GRAVITY, K, LENGTH_M, M, PrbsRun, T, commands, fly_dp_campaign, simulate,
    };
    use crate::rng::{Rng, derive_seed};

    /// Binary commands of ±0.5 slewed at 0.1: exact in a 6-decimal log.
    fn prbs_trial() -> DpTrial {
        let run = |order, chip_s, samples| PrbsRun {
            order,
            chip_s,
            samples,
        };
        DpTrial {
            inputs: DpInputs::Prbs {
                level: 0.5,
                slew: 0.1,
                surge: run(3, 87.6, 613),
                sway_yaw: run(5, 20.0, 620),
                azimuth: run(5, 20.0, 620),
                validation: run(0, 20.0, 600),
            },
            log_velocities: true,
            ..DpTrial::default()
        }
    }

    /// The cells of a CSV row from `skip` on.
    fn pose(row: &str, skip: usize) -> Vec<&str> {
        row.split(',').skip(skip).collect()
    }

    /// Column `c` of a log.
    fn col(log: &DpLog, c: usize) -> Vec<f64> {
        log.csv
            .lines()
            .skip(1)
            .map(|l| l.split(',').nth(c).unwrap().parse().unwrap())
            .collect()
    }

    /// Commanded Bis forces τ″ = T″K″u of row-major commands.
    fn tau<const R: usize>(t: &[[f64; R]; 3], k: &[f64; R], u: &[f64]) -> [f64; 3] {
        std::array::from_fn(|i| (0..R).map(|j| t[i][j] * k[j] * u[j]).sum())
    }

    #[test]
    fn paper_layout_is_fly_dp_campaign() {
        for trial in [DpTrial::default(), prbs_trial()] {
            let a = fly_dp_layout_campaign(&trial, DpLayout::Paper, 11);
            let b = fly_dp_campaign(&trial, 11);
            assert_eq!(a.len(), b.len());
            for (a, b) in a.iter().zip(&b) {
                assert_eq!((&a.name, a.manoeuvre), (&b.name, b.manoeuvre));
                assert_eq!(a.csv, b.csv, "{}", a.name);
            }
        }
    }

    /// AZ_T is the geometry it claims; the azimuths share one K″.
    #[test]
    fn azimuth_layout_matches_its_geometry() {
        let at = [
            (0.45, 0.0, 90.0),
            (-0.40, 0.0, 90.0),
            (-0.45, -0.06, 30.0),
            (-0.45, 0.06, -30.0),
        ];
        for (j, &(x, y, a)) in at.iter().enumerate() {
            let (s, c) = f64::to_radians(a).sin_cos();
            let col = [c, s, x * s - y * c];
            for i in 0..3 {
                assert!((AZ_T[i][j] - col[i]).abs() < 1e-15, "T[{i}][{j}]");
            }
        }
        assert_eq!(AZ_K[2], AZ_K[3]);
    }

    #[test]
    fn azimuth_surge_cancels_sway_and_yaw() {
        for trial in [DpTrial::default(), prbs_trial()] {
            let logs = fly_dp_layout_campaign(&trial, DpLayout::AzimuthsTunnels, 5);
            let names: Vec<&str> = logs.iter().map(|l| l.name.as_str()).collect();
            assert_eq!(names, ["SI1-1", "SI1-2", "SI2-1", "SI2-2", "VAL"]);
            let thr = |log: &DpLog| -> Vec<Vec<f64>> {
                let cols: Vec<Vec<f64>> = (1..=4).map(|c| col(log, c)).collect();
                (0..cols[0].len())
                    .map(|k| (0..4).map(|j| cols[j][k]).collect())
                    .collect()
            };
            for log in logs.iter().filter(|l| l.manoeuvre == DpManoeuvre::Surge) {
                let mut surge = 0.0_f64;
                for u in thr(log) {
                    assert_eq!((u[0], u[1]), (0.0, 0.0));
                    assert_eq!(u[2], u[3]);
                    let f = tau(&AZ_T, &AZ_K, &u);
                    assert!(f[1].abs() <= 1e-12 && f[2].abs() <= 1e-12, "{f:?}");
                    surge = surge.max(f[0].abs());
                }
                assert!(surge > 1e-3, "surge thrust {surge}");
            }
            let si2 = thr(&logs[2]);
            assert!(si2.iter().all(|u| u[2] == 0.0 && u[3] == 0.0));
            assert!(si2.iter().any(|u| u[0] != u[1]));
            let val = thr(&logs[4]);
            for (a, b) in [(0, 1), (0, 2), (1, 3), (2, 3)] {
                assert!(
                    val.iter().any(|u| u[a] != u[b]),
                    "thr_{} = thr_{}",
                    a + 1,
                    b + 1
                );
            }
        }
    }

    /// Surge-only motion (v = r = 0, so C(ν)ν = 0 and D ν = (d11 u, 0, 0)
    /// with D = −A_h·M) under a constant SI1 command c settles at
    /// u″ = K″_az·2·cos 30°·c / d11, d11 = −A″_h11·M″11.
    #[test]
    fn azimuth_steady_surge_matches_closed_form() {
        let c = 0.25;
        let trial = DpTrial {
            position_noise_m: 0.0,
            heading_noise_rad: 0.0,
            bias_initial: [0.0; 3],
            bias_walk: [0.0; 3],
            log_velocities: true,
            ..DpTrial::default()
        };
        let u = vec![vec![0.0, 0.0, c, c]; 2500];
        let log = simulate(
            DpManoeuvre::Surge,
            "SI1-1".into(),
            &trial,
            &AZIMUTHS_TUNNELS,
            &u,
            &[],
            &mut Rng::new(3),
        );
        let d11 = -A_H[0][0] * M[0][0];
        let expected = AZ_K[2] * 2.0 * COS30 * c / d11 * (GRAVITY * LENGTH_M).sqrt();
        let (su, sv, sr) = (col(&log, 8), col(&log, 9), col(&log, 10));
        let last = *su.last().unwrap();
        assert!((last / expected - 1.0).abs() < 1e-6, "{last} vs {expected}");
        assert!(sv.iter().chain(&sr).all(|&x| x == 0.0));
    }

    /// The forces log flies the paper run (same pose columns) and writes
    /// m·g·T″K″u of its commands in N and N·m.
    #[test]
    fn forces_log_the_commanded_thrust_in_si() {
        let mg = DISPLACEMENT_KG * GRAVITY;
        let scale = [mg, mg, mg * LENGTH_M];
        for (trial, exact) in [(prbs_trial(), true), (DpTrial::default(), false)] {
            let paper = fly_dp_layout_campaign(&trial, DpLayout::Paper, 9);
            let forces = fly_dp_layout_campaign(&trial, DpLayout::Forces, 9);
            assert_eq!(paper.len(), forces.len());
            for (p, f) in paper.iter().zip(&forces) {
                assert_eq!(p.name, f.name);
                for (lp, lf) in p.csv.lines().zip(f.csv.lines()).skip(1) {
                    assert_eq!(pose(lp, 7), pose(lf, 4), "{}", p.name);
                    let u: Vec<f64> = pose(lp, 1)[..6]
                        .iter()
                        .map(|s| s.parse().unwrap())
                        .collect();
                    let want = tau(&T, &K, &u);
                    let got: Vec<f64> = pose(lf, 1)[..3]
                        .iter()
                        .map(|s| s.parse().unwrap())
                        .collect();
                    for i in 0..3 {
                        let want = want[i] * scale[i];
                        // Pitch commands are logged to 6 decimals: allow
                        // their rounding; PRBS commands are exact.
                        let slack = if exact {
                            1e-9
                        } else {
                            (0..6).map(|j| (T[i][j] * K[j]).abs()).sum::<f64>() * 5e-7 * scale[i]
                        };
                        assert!(
                            (got[i] - want).abs() <= 1e-9 * want.abs() + slack,
                            "{} τ{i}: {} vs {want}",
                            p.name,
                            got[i]
                        );
                    }
                }
            }
            // Exact against the unrounded commands of SI1-1 (run tag 1).
            let mut rng = Rng::new(derive_seed(9, 1));
            let groups = (PAPER.plan)(DpManoeuvre::Surge);
            let n = col(&paper[0], 1).len();
            let u = commands(DpManoeuvre::Surge, n, &trial.inputs, groups, 6, &mut rng);
            for (uk, x) in u.iter().zip(col(&forces[0], 1)) {
                let want = tau(&T, &K, uk)[0] * mg;
                assert!(
                    (x - want).abs() <= 1e-9 * want.abs() + 1e-9,
                    "{x} vs {want}"
                );
            }
        }
    }

    /// The shaft-speed log flies the command run (same pose) and records
    /// n = sign(u)·√|u|·n_rated: |n|·n/n_rated² gives the logged command
    /// back within the rounding of both logs.
    #[test]
    fn shaft_speeds_are_the_commands_through_the_propeller_law() {
        for trial in [prbs_trial(), DpTrial::default()] {
            let commands = fly_dp_layout_campaign(&trial, DpLayout::AzimuthsTunnels, 5);
            let speeds = fly_dp_layout_campaign(&trial, DpLayout::AzimuthsTunnelsShaftSpeed, 5);
            assert_eq!(commands.len(), speeds.len());
            let mut turning = 0;
            for (c, s) in commands.iter().zip(&speeds) {
                assert_eq!(c.name, s.name);
                for (lc, ls) in c.csv.lines().zip(s.csv.lines()).skip(1) {
                    assert_eq!(pose(lc, 5), pose(ls, 5), "{}", c.name);
                    for (j, rated) in AZ_RATED_RPM.into_iter().enumerate() {
                        let u: f64 = pose(lc, 1 + j)[0].parse().unwrap();
                        let n: f64 = pose(ls, 1 + j)[0].parse().unwrap();
                        // n to 0.005 rpm: |n|n/n² within 2·0.005/n_rated·√|u|.
                        let slack = 0.01 / rated * u.abs().sqrt() + 5e-7 + 1e-4 / (rated * rated);
                        assert!(
                            (n.abs() * n / (rated * rated) - u).abs() <= slack,
                            "{} thr_{}: n {n} rpm, u {u}",
                            c.name,
                            j + 1
                        );
                        turning += usize::from(n.abs() > 0.5 * rated);
                    }
                }
            }
            assert!(turning > 100, "the propellers hardly turn: {turning}");
        }
    }

    /// Steered azimuths: SI2 holds them at ±30° (idle), so its runs are the
    /// fixed layout's exactly; SI1 turns them mirrored within 15°–45° and
    /// validation each within its range, and the logged angle is what
    /// was flown: SI1's runs still push surge alone (heading held).
    #[test]
    fn steered_azimuths_turn_as_logged() {
        // No bias: the only sway force or yaw moment would be the azimuths'.
        let trial = DpTrial {
            log_velocities: true,
            bias_initial: [0.0; 3],
            bias_walk: [0.0; 3],
            ..DpTrial::default()
        };
        let fixed = fly_dp_layout_campaign(&trial, DpLayout::AzimuthsTunnels, 6);
        let steered = fly_dp_layout_campaign(&trial, DpLayout::SteeredAzimuths, 6);
        for (f, s) in fixed.iter().zip(&steered) {
            let angles: Vec<(f64, f64)> = col(s, 5).into_iter().zip(col(s, 6)).collect();
            match s.manoeuvre {
                DpManoeuvre::SwayYaw => {
                    for (lf, ls) in f.csv.lines().zip(s.csv.lines()).skip(1) {
                        assert_eq!(pose(lf, 5), pose(ls, 7), "{}", s.name);
                    }
                    assert!(angles.iter().all(|&a| a == (30.0, -30.0)));
                }
                DpManoeuvre::Surge => {
                    assert!(
                        angles
                            .iter()
                            .all(|&(p, q)| p == -q && (15.0..=45.0).contains(&p))
                    );
                    let distinct = angles.windows(2).filter(|w| w[0] != w[1]).count();
                    assert!(distinct >= 3, "{}: {distinct} turns", s.name);
                    // Mirrored: no sway force, no yaw moment, so r stays ~0.
                    let r = col(s, 12);
                    assert!(r.iter().all(|r| r.abs() < 1e-6), "{}", s.name);
                }
                _ => {
                    assert!(
                        angles
                            .iter()
                            .all(|&(p, q)| (10.0..=60.0).contains(&p)
                                && (-60.0..=-10.0).contains(&q))
                    );
                    assert_ne!(f.csv, s.csv);
                }
            }
        }
    }

    #[test]
    fn every_log_has_its_header_and_finite_values() {
        let thr4 = "t,thr_1,thr_2,thr_3,thr_4,x,y,psi";
        let thr6 = "t,thr_1,thr_2,thr_3,thr_4,thr_5,thr_6,x,y,psi";
        let forces = "t,tau_X,tau_Y,tau_N,x,y,psi";
        for velocities in [false, true] {
            let trial = DpTrial {
                log_velocities: velocities,
                samples: 200,
                ..DpTrial::default()
            };
            for (layout, head, runs) in [
                (DpLayout::Paper, thr6, 7),
                (DpLayout::AzimuthsTunnels, thr4, 5),
                (DpLayout::AzimuthsTunnelsShaftSpeed, thr4, 5),
                (
                    DpLayout::SteeredAzimuths,
                    "t,thr_1,thr_2,thr_3,thr_4,azi_3,azi_4,x,y,psi",
                    5,
                ),
                (DpLayout::Forces, forces, 7),
            ] {
                let want = format!("{head}{}", if velocities { ",u,v,r" } else { "" });
                let logs = fly_dp_layout_campaign(&trial, layout, 2);
                assert_eq!(logs.len(), runs, "{layout:?}");
                for log in &logs {
                    let mut lines = log.csv.lines();
                    assert_eq!(lines.next(), Some(want.as_str()), "{layout:?}");
                    let width = want.split(',').count();
                    let rows: Vec<&str> = lines.collect();
                    assert_eq!(rows.len(), 200);
                    for row in rows {
                        let v: Vec<f64> = row.split(',').map(|s| s.parse().unwrap()).collect();
                        assert_eq!(v.len(), width);
                        assert!(v.iter().all(|x| x.is_finite()), "{row}");
                    }
                }
            }
        }
    }
}
