//! An independent DP ship: the supply vessel of Fossen, Sagatun & Sørensen
//! (1995, sec. 4, L = 76.2 m) as a 3-DOF low-frequency model in the Bis
//! system (lengths in L, time in √(L/g), mass in the displacement mass m,
//! forces in m·g, moments in m·g·L), flown through decoupled manoeuvres and
//! logged the way a DP system records: t (s), thruster commands
//! `thr_1 … thr_6`, and the measured pose x, y (m), ψ (rad, wrapped) at 1 Hz —
//! no velocities unless asked for.
//!
//!   M ν̇ + C(ν)ν + D ν = T K u + b,   η̇ = R(ψ) ν,   ḃ = w_b,
//!
//! with M, T, K the paper's eq. 29, 30, 49 and D = −A_h M from eq. 48;
//! C(ν) is Fossen's (2011, eq. 6.43–6.44 for a 3-DOF ship with the
//! sway–yaw coupled inertia) skew-symmetric form from M. Commands are, by
//! default, u = |p|·p (eq. 5) of pitch ratios p held at random levels,
//! slewed at 5 % per second ([`DpInputs::Pitch`]); a trial may instead fly
//! binary commands from a maximum-length shift-register sequence
//! ([`DpInputs::Prbs`]). Integration: RK4, 10 steps per logged sample,
//! commands held.

use nalgebra::{Matrix3, Vector3};

use crate::rng::{Rng, derive_seed};

mod commands;

use commands::{binary, m_sequence, pitch};

/// Ship length L (m).
pub const LENGTH_M: f64 = 76.2;
/// Gravity of the Bis units (m/s²).
pub const GRAVITY: f64 = 9.81;

/// M″ (eq. 30).
pub const M: [[f64; 3]; 3] = [
    [1.1274, 0.0, 0.0],
    [0.0, 1.8902, -0.0744],
    [0.0, -0.0744, 0.1278],
];
/// A″_h (eq. 48).
pub const A_H: [[f64; 3]; 3] = [
    [-0.0318, 0.0, 0.0],
    [0.0, -0.0602, 0.0618],
    [0.0, -0.0075, -0.2454],
];
/// T″ (eq. 29): port and starboard main, two aft tunnels, bow tunnel, bow
/// azimuth at 90°.
pub const T: [[f64; 6]; 3] = [
    [1.0, 1.0, 0.0, 0.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 1.0, 1.0, 1.0],
    [0.0472, -0.0472, -0.4108, -0.3858, 0.4554, 0.3373],
];
/// K″ (eq. 49).
pub const K: [f64; 6] = [9.3e-3, 9.3e-3, 2.0e-3, 2.0e-3, 2.8e-3, 2.6e-3];

/// Which thrusters a run drives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DpManoeuvre {
    /// Both main propellers together (SI1).
    Surge,
    /// The aft tunnels together against the bow tunnel (SI2).
    SwayYaw,
    /// The bow azimuth alone (SI3).
    Azimuth,
    /// Every thruster, independently (held-out validation).
    Validation,
}

impl DpManoeuvre {
    /// The seatrial family name of the run (`dp_surge`, …, `validation`).
    pub fn family(self) -> &'static str {
        match self {
            DpManoeuvre::Surge => "dp_surge",
            DpManoeuvre::SwayYaw => "dp_sway_yaw",
            DpManoeuvre::Azimuth => "dp_azimuth",
            DpManoeuvre::Validation => "validation",
        }
    }
}

/// One logged run.
#[derive(Debug, Clone)]
pub struct DpLog {
    /// Run name, e.g. `SI2-2`.
    pub name: String,
    /// What it flew.
    pub manoeuvre: DpManoeuvre,
    /// The CSV log (header `t,thr_1,…,thr_6,x,y,psi[,u,v,r]`; the other
    /// layouts' headers are in [`crate::dp_layouts`]).
    pub csv: String,
}

/// How to fly and log.
#[derive(Debug, Clone, Copy)]
pub struct DpTrial {
    /// Samples per run (1 Hz).
    pub samples: usize,
    /// Runs per manoeuvre SI1–SI3.
    pub repetitions: usize,
    /// Position noise (m) and heading noise (rad).
    pub position_noise_m: f64,
    /// Heading noise (rad).
    pub heading_noise_rad: f64,
    /// Initial bias std and its random walk per sample (Bis force, surge,
    /// sway, yaw).
    pub bias_initial: [f64; 3],
    /// Bias random walk per sample.
    pub bias_walk: [f64; 3],
    /// Also log body velocities u, v (m/s), r (rad/s) without noise.
    pub log_velocities: bool,
    /// How the commands are made.
    pub inputs: DpInputs,
    /// Validation runs at the end of the campaign (`VAL`, `VAL-2`, …).
    pub validation_runs: usize,
}

/// The commands a trial flies.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DpInputs {
    /// Pitch ratios p held at random levels of alternating sign (|p| and
    /// hold per manoeuvre as in Fossen et al.'s Fig. 5–7), u = |p|·p, p
    /// slewed at 5 % per sample, quiet for the first 10 samples; every run
    /// `samples` long.
    Pitch,
    /// Binary commands u = ±`level`: chip c of a maximum-length sequence
    /// (period 2ⁿ − 1 chips, a random nonzero start state per run) held
    /// over the samples k with ⌊k / chip_s⌋ = c, u slewed at `slew` per
    /// sample from u = 0 at k = 0 (no quiet start). SI2's bow tunnel flies
    /// the aft tunnels' sequence delayed by ⌊m/2⌋ of its m chips; the
    /// validation run holds independent random signs per chip of
    /// `validation`. Each manoeuvre has its own run length.
    Prbs {
        /// Command magnitude |u|.
        level: f64,
        /// Largest change of u per sample.
        slew: f64,
        /// SI1 (main propellers).
        surge: PrbsRun,
        /// SI2 (aft tunnels against the bow tunnel).
        sway_yaw: PrbsRun,
        /// SI3 (bow azimuth).
        azimuth: PrbsRun,
        /// Validation (chip and samples; `order` unused).
        validation: PrbsRun,
    },
}

/// Sequence and length of one PRBS manoeuvre.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PrbsRun {
    /// Shift-register order n (3 … 10).
    pub order: u32,
    /// Chip length (samples, may be fractional).
    pub chip_s: f64,
    /// Samples per run (1 Hz).
    pub samples: usize,
}

impl Default for DpTrial {
    fn default() -> Self {
        DpTrial {
            samples: 600,
            repetitions: 2,
            position_noise_m: 1.0,
            heading_noise_rad: 0.2f64.to_radians(),
            bias_initial: [3e-4, 3e-4, 5e-5],
            bias_walk: [3e-6, 3e-6, 6e-7],
            log_velocities: false,
            inputs: DpInputs::Pitch,
            validation_runs: 1,
        }
    }
}

fn mat(a: &[[f64; 3]; 3]) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| a[i][j])
}

/// C(ν)ν of the 3-DOF ship with inertia `m` (rigid body and added mass
/// together): C = [[0, 0, −m22 v − m23 r], [0, 0, m11 u], [m22 v + m23 r, −m11 u, 0]].
fn coriolis(m: &Matrix3<f64>, nu: &Vector3<f64>) -> Vector3<f64> {
    let (u, v, r) = (nu[0], nu[1], nu[2]);
    let c13 = -m[(1, 1)] * v - m[(1, 2)] * r;
    let c23 = m[(0, 0)] * u;
    Vector3::new(c13 * r, c23 * r, -c13 * u - c23 * v)
}

/// State derivative of (ν, η) under force `f` (thrust plus bias).
fn deriv(
    m_inv: &Matrix3<f64>,
    m: &Matrix3<f64>,
    d: &Matrix3<f64>,
    s: &[f64; 6],
    f: &Vector3<f64>,
) -> [f64; 6] {
    let nu = Vector3::new(s[0], s[1], s[2]);
    let nu_dot = m_inv * (f - coriolis(m, &nu) - d * nu);
    let (sn, cs) = s[5].sin_cos();
    [
        nu_dot[0],
        nu_dot[1],
        nu_dot[2],
        cs * nu[0] - sn * nu[1],
        sn * nu[0] + cs * nu[1],
        nu[2],
    ]
}

/// Samples of a run of `kind`.
fn run_samples(kind: DpManoeuvre, trial: &DpTrial) -> usize {
    match trial.inputs {
        DpInputs::Pitch => trial.samples,
        DpInputs::Prbs {
            surge,
            sway_yaw,
            azimuth,
            validation,
            ..
        } => match kind {
            DpManoeuvre::Surge => surge.samples,
            DpManoeuvre::SwayYaw => sway_yaw.samples,
            DpManoeuvre::Azimuth => azimuth.samples,
            DpManoeuvre::Validation => validation.samples,
        },
    }
}

/// Thrusters flown by one command sequence in a manoeuvre, with the hold
/// (samples) and |p| range of its [`DpInputs::Pitch`] levels.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Group {
    /// Thruster columns (0-based) that share the sequence.
    pub cols: &'static [usize],
    /// Hold of each pitch level (samples).
    pub hold: (f64, f64),
    /// Range of |p|.
    pub level: (f64, f64),
}

/// What a log carries between t and the pose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Logged {
    /// The thruster commands `thr_1 … thr_r`.
    Commands,
    /// The commanded generalized forces τ″ = T″K″u (bias excluded) in SI,
    /// `tau_X,tau_Y,tau_N` (N, N, N·m), for a displacement mass (kg).
    Forces(f64),
    /// The propellers' shaft speeds n_j (rpm, signed) in `thr_1 … thr_r`,
    /// for the rated speeds (rpm) given: fixed-pitch propellers whose
    /// thrust goes with |n|·n, so the command is u = |n|·n/n_rated² and the
    /// logger records n = sign(u)·√|u|·n_rated (two decimals).
    ShaftSpeed(&'static [f64]),
}

/// A thruster layout on the paper's hull: T″ by rows (3 × r), K″ (r), the
/// manoeuvres of a campaign with their run codes, the groups each
/// manoeuvre flies, and what the log carries.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Layout {
    /// Rows of T″.
    pub t: [&'static [f64]; 3],
    /// K″ per thruster.
    pub k: &'static [f64],
    /// SI manoeuvres in campaign order, e.g. `(Surge, "SI1")`.
    pub runs: &'static [(DpManoeuvre, &'static str)],
    /// The groups a manoeuvre flies, in the order their commands are drawn.
    pub plan: fn(DpManoeuvre) -> &'static [Group],
    /// Commands or forces.
    pub logged: Logged,
    /// Azimuths that turn during a run and log their angle.
    pub steering: Option<Steering>,
}

/// Azimuths that turn during a run: their column of T″ follows the angle
/// α(t), (cos α, sin α, x·sin α − y·cos α) at their position (x, y) in L,
/// and the log carries `azi_j` (degrees, three decimals) after the
/// thruster columns.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Steering {
    /// Steered thruster columns (0-based) with their position (x, y) in L.
    pub azimuths: &'static [(usize, f64, f64)],
    /// The angles (rad) a manoeuvre of n samples flies, per sample one per
    /// steered azimuth, drawn after the commands.
    pub angles: fn(DpManoeuvre, usize, &mut Rng) -> Vec<Vec<f64>>,
}

/// The paper's six thrusters, flown as in Fig. 5–7.
pub(crate) const PAPER: Layout = Layout {
    t: [&T[0], &T[1], &T[2]],
    k: &K,
    runs: &[
        (DpManoeuvre::Surge, "SI1"),
        (DpManoeuvre::SwayYaw, "SI2"),
        (DpManoeuvre::Azimuth, "SI3"),
    ],
    plan: paper_plan,
    logged: Logged::Commands,
    steering: None,
};

/// Groups of the paper's manoeuvres: mains together (SI1), aft tunnels
/// against the bow tunnel (SI2), the azimuth alone (SI3), all (validation).
fn paper_plan(kind: DpManoeuvre) -> &'static [Group] {
    match kind {
        DpManoeuvre::Surge => &[Group {
            cols: &[0, 1],
            hold: (80.0, 160.0),
            level: (0.3, 0.6),
        }],
        DpManoeuvre::SwayYaw => &[
            Group {
                cols: &[2, 3],
                hold: (40.0, 120.0),
                level: (0.4, 1.0),
            },
            Group {
                cols: &[4],
                hold: (40.0, 120.0),
                level: (0.4, 1.0),
            },
        ],
        DpManoeuvre::Azimuth => &[Group {
            cols: &[5],
            hold: (60.0, 150.0),
            level: (0.4, 1.0),
        }],
        DpManoeuvre::Validation => &[
            Group {
                cols: &[0, 1],
                hold: (80.0, 160.0),
                level: (0.2, 0.4),
            },
            Group {
                cols: &[2, 3],
                hold: (40.0, 120.0),
                level: (0.3, 0.8),
            },
            Group {
                cols: &[4],
                hold: (40.0, 120.0),
                level: (0.3, 0.8),
            },
            Group {
                cols: &[5],
                hold: (60.0, 150.0),
                level: (0.3, 0.8),
            },
        ],
    }
}

/// Commands (n × r) of a manoeuvre flying `groups` on r thrusters. Pitch:
/// one held-level sequence per group. Prbs: the first group flies the
/// run's m-sequence, later groups the same sequence delayed by ⌊m/2⌋ chips;
/// validation draws independent signs per group.
pub(crate) fn commands(
    kind: DpManoeuvre,
    n: usize,
    inputs: &DpInputs,
    groups: &[Group],
    r: usize,
    rng: &mut Rng,
) -> Vec<Vec<f64>> {
    let mut u = vec![vec![0.0; r]; n];
    let mut set = |cols: &[usize], p: Vec<f64>| {
        for (row, pk) in u.iter_mut().zip(p) {
            for &c in cols {
                row[c] = pk;
            }
        }
    };
    match *inputs {
        DpInputs::Pitch => {
            for g in groups {
                set(g.cols, pitch(rng, n, g.hold, g.level));
            }
        }
        DpInputs::Prbs {
            level,
            slew,
            surge,
            sway_yaw,
            azimuth,
            validation,
        } => {
            if kind == DpManoeuvre::Validation {
                let chips = (n as f64 / validation.chip_s).ceil() as usize + 1;
                for g in groups {
                    let s: Vec<f64> = (0..chips).map(|_| rng.sign()).collect();
                    set(g.cols, binary(&s, validation.chip_s, n, level, slew));
                }
            } else {
                let run = match kind {
                    DpManoeuvre::Surge => surge,
                    DpManoeuvre::SwayYaw => sway_yaw,
                    _ => azimuth,
                };
                let s = m_sequence(rng, run.order);
                let mut delayed = s.clone();
                delayed.rotate_left(s.len() / 2);
                for (i, g) in groups.iter().enumerate() {
                    let chips = if i == 0 { &s } else { &delayed };
                    set(g.cols, binary(chips, run.chip_s, n, level, slew));
                }
            }
        }
    }
    u
}

/// Flies one run of `layout` and writes its log.
fn fly(kind: DpManoeuvre, name: String, trial: &DpTrial, layout: &Layout, seed: u64) -> DpLog {
    let mut rng = Rng::new(seed);
    let n = run_samples(kind, trial);
    let groups = (layout.plan)(kind);
    let u = commands(kind, n, &trial.inputs, groups, layout.k.len(), &mut rng);
    let angles = layout
        .steering
        .map(|s| (s.angles)(kind, n, &mut rng))
        .unwrap_or_default();
    simulate(kind, name, trial, layout, &u, &angles, &mut rng)
}

/// Flies the commands `u` (n × r) on `layout`, its steered azimuths at
/// `angles` (n × steered, rad; empty without steering), drawing the initial
/// bias and heading, the noise and the bias walk from `rng`, and writes the
/// log.
pub(crate) fn simulate(
    kind: DpManoeuvre,
    name: String,
    trial: &DpTrial,
    layout: &Layout,
    u: &[Vec<f64>],
    angles: &[Vec<f64>],
    rng: &mut Rng,
) -> DpLog {
    let m = mat(&M);
    let m_inv = m.try_inverse().expect("M″ is invertible");
    let d = -mat(&A_H) * m;
    let time_unit = (LENGTH_M / GRAVITY).sqrt();
    let h = 1.0 / time_unit; // 1 s in Bis time
    let steps = 10;
    let dt = h / steps as f64;
    let (t, k) = (layout.t, layout.k);
    let mut b: [f64; 3] = std::array::from_fn(|i| trial.bias_initial[i] * rng.normal());
    let heading0 = rng.range(-std::f64::consts::PI, std::f64::consts::PI);
    let mut s = [0.0, 0.0, 0.0, 0.0, 0.0, heading0];
    let mut csv = String::from("t");
    match layout.logged {
        Logged::Commands | Logged::ShaftSpeed(_) => {
            (1..=k.len()).for_each(|j| csv.push_str(&format!(",thr_{j}")))
        }
        Logged::Forces(_) => csv.push_str(",tau_X,tau_Y,tau_N"),
    }
    let steered = layout.steering.map_or(&[][..], |s| s.azimuths);
    for &(j, _, _) in steered {
        csv.push_str(&format!(",azi_{}", j + 1));
    }
    csv.push_str(",x,y,psi");
    if trial.log_velocities {
        csv.push_str(",u,v,r");
    }
    csv.push('\n');
    let vel = LENGTH_M / time_unit;
    for (kk, uk) in u.iter().enumerate() {
        let x = s[3] * LENGTH_M + trial.position_noise_m * rng.normal();
        let y = s[4] * LENGTH_M + trial.position_noise_m * rng.normal();
        let psi = s[5] + trial.heading_noise_rad * rng.normal();
        let psi =
            (psi + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
        csv.push_str(&format!("{}", kk as f64));
        match layout.logged {
            Logged::Commands => {
                for c in uk {
                    csv.push_str(&format!(",{c:.6}"));
                }
            }
            Logged::ShaftSpeed(rated) => {
                for (c, n) in uk.iter().zip(rated) {
                    // + 0.0 writes −0 as 0.
                    csv.push_str(&format!(",{:.2}", c.signum() * c.abs().sqrt() * n + 0.0));
                }
            }
            Logged::Forces(mass) => {
                let mg = mass * GRAVITY;
                let scale = [mg, mg, mg * LENGTH_M];
                for i in 0..3 {
                    let tau: f64 = (0..uk.len()).map(|j| t[i][j] * k[j] * uk[j]).sum();
                    // + 0.0 writes −0 as 0.
                    csv.push_str(&format!(",{:.12e}", tau * scale[i] + 0.0));
                }
            }
        }
        for (i, _) in steered.iter().enumerate() {
            // + 0.0 writes −0 as 0.
            csv.push_str(&format!(",{:.3}", angles[kk][i].to_degrees() + 0.0));
        }
        csv.push_str(&format!(",{x:.4},{y:.4},{psi:.6}"));
        if trial.log_velocities {
            csv.push_str(&format!(
                ",{:.6},{:.6},{:.8}",
                s[0] * vel,
                s[1] * vel,
                s[2] / time_unit
            ));
        }
        csv.push('\n');
        let mut f = Vector3::new(b[0], b[1], b[2]);
        for (j, &c) in uk.iter().enumerate() {
            let col = match steered.iter().position(|&(s, _, _)| s == j) {
                Some(i) => {
                    let (_, ax, ay) = steered[i];
                    let (sa, ca) = angles[kk][i].sin_cos();
                    [ca, sa, ax * sa - ay * ca]
                }
                None => [t[0][j], t[1][j], t[2][j]],
            };
            for i in 0..3 {
                f[i] += col[i] * k[j] * c;
            }
        }
        for _ in 0..steps {
            let k1 = deriv(&m_inv, &m, &d, &s, &f);
            let at = |k: &[f64; 6], c: f64| std::array::from_fn(|i| s[i] + c * dt * k[i]);
            let k2 = deriv(&m_inv, &m, &d, &at(&k1, 0.5), &f);
            let k3 = deriv(&m_inv, &m, &d, &at(&k2, 0.5), &f);
            let k4 = deriv(&m_inv, &m, &d, &at(&k3, 1.0), &f);
            for i in 0..6 {
                s[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
        }
        for (bi, w) in b.iter_mut().zip(trial.bias_walk) {
            *bi += w * rng.normal();
        }
    }
    DpLog {
        name,
        manoeuvre: kind,
        csv,
    }
}

/// The campaign of `layout` for seed `seed`: `repetitions` runs of each of
/// its SI manoeuvres, then `validation_runs` validation runs.
pub(crate) fn fly_layout(trial: &DpTrial, layout: &Layout, seed: u64) -> Vec<DpLog> {
    let mut out = Vec::new();
    let mut tag = 0;
    for &(kind, code) in layout.runs {
        for r in 1..=trial.repetitions {
            tag += 1;
            let name = format!("{code}-{r}");
            out.push(fly(kind, name, trial, layout, derive_seed(seed, tag)));
        }
    }
    for r in 1..=trial.validation_runs {
        let name = if r == 1 {
            "VAL".to_string()
        } else {
            format!("VAL-{r}")
        };
        let run_seed = derive_seed(seed, 999 + r as u64);
        out.push(fly(DpManoeuvre::Validation, name, trial, layout, run_seed));
    }
    out
}

/// The campaign of seed `seed`: `repetitions` runs of SI1, SI2, SI3 each,
/// then `validation_runs` validation runs with every thruster.
pub fn fly_dp_campaign(trial: &DpTrial, seed: u64) -> Vec<DpLog> {
    fly_layout(trial, &PAPER, seed)
}

#[cfg(test)]
mod tests;
