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
//! sway–yaw coupled inertia) skew-symmetric form from M. Commands are
//! u = |p|·p (eq. 5) of pitch ratios p held at random levels, slewed at 5 %
//! per second. Integration: RK4, 10 steps per logged sample, commands held.

use nalgebra::{Matrix3, Vector3};

use crate::rng::{Rng, derive_seed};

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
    /// The CSV log (header `t,thr_1,…,thr_6,x,y,psi[,u,v,r]`).
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

/// Random held pitch ratios (alternating sign, |p| in `level`), slewed at
/// 5 % per sample, zero for the first 10 samples.
fn pitch(rng: &mut Rng, n: usize, hold: (f64, f64), level: (f64, f64)) -> Vec<f64> {
    let mut goal = vec![0.0; n];
    let mut k = n.min(10);
    let mut sign = rng.sign();
    while k < n {
        let len = rng.range(hold.0, hold.1).round() as usize;
        let l = sign * rng.range(level.0, level.1);
        sign = -sign;
        for g in goal.iter_mut().skip(k).take(len.max(1)) {
            *g = l;
        }
        k += len.max(1);
    }
    let mut p = 0.0_f64;
    goal.iter()
        .map(|&g| {
            p += (g - p).clamp(-0.05, 0.05);
            p.abs() * p
        })
        .collect()
}

/// Commands (n × 6) of a manoeuvre.
fn commands(kind: DpManoeuvre, n: usize, rng: &mut Rng) -> Vec<[f64; 6]> {
    let mut u = vec![[0.0; 6]; n];
    let mut set = |cols: &[usize], p: Vec<f64>| {
        for (row, pk) in u.iter_mut().zip(p) {
            for &c in cols {
                row[c] = pk;
            }
        }
    };
    match kind {
        DpManoeuvre::Surge => set(&[0, 1], pitch(rng, n, (80.0, 160.0), (0.3, 0.6))),
        DpManoeuvre::SwayYaw => {
            set(&[2, 3], pitch(rng, n, (40.0, 120.0), (0.4, 1.0)));
            set(&[4], pitch(rng, n, (40.0, 120.0), (0.4, 1.0)));
        }
        DpManoeuvre::Azimuth => set(&[5], pitch(rng, n, (60.0, 150.0), (0.4, 1.0))),
        DpManoeuvre::Validation => {
            set(&[0, 1], pitch(rng, n, (80.0, 160.0), (0.2, 0.4)));
            set(&[2, 3], pitch(rng, n, (40.0, 120.0), (0.3, 0.8)));
            set(&[4], pitch(rng, n, (40.0, 120.0), (0.3, 0.8)));
            set(&[5], pitch(rng, n, (60.0, 150.0), (0.3, 0.8)));
        }
    }
    u
}

/// Flies one run and writes its log.
fn fly(kind: DpManoeuvre, name: String, trial: &DpTrial, seed: u64) -> DpLog {
    let mut rng = Rng::new(seed);
    let m = mat(&M);
    let m_inv = m.try_inverse().expect("M″ is invertible");
    let d = -mat(&A_H) * m;
    let time_unit = (LENGTH_M / GRAVITY).sqrt();
    let h = 1.0 / time_unit; // 1 s in Bis time
    let steps = 10;
    let dt = h / steps as f64;
    let n = trial.samples;
    let u = commands(kind, n, &mut rng);
    let mut b: [f64; 3] = std::array::from_fn(|i| trial.bias_initial[i] * rng.normal());
    let heading0 = rng.range(-std::f64::consts::PI, std::f64::consts::PI);
    let mut s = [0.0, 0.0, 0.0, 0.0, 0.0, heading0];
    let mut csv = String::from("t,thr_1,thr_2,thr_3,thr_4,thr_5,thr_6,x,y,psi");
    if trial.log_velocities {
        csv.push_str(",u,v,r");
    }
    csv.push('\n');
    let vel = LENGTH_M / time_unit;
    for (k, uk) in u.iter().enumerate() {
        let x = s[3] * LENGTH_M + trial.position_noise_m * rng.normal();
        let y = s[4] * LENGTH_M + trial.position_noise_m * rng.normal();
        let psi = s[5] + trial.heading_noise_rad * rng.normal();
        let psi =
            (psi + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
        csv.push_str(&format!("{}", k as f64));
        for c in uk {
            csv.push_str(&format!(",{c:.6}"));
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
            for i in 0..3 {
                f[i] += T[i][j] * K[j] * c;
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

/// The campaign of seed `seed`: `repetitions` runs of SI1, SI2, SI3 each,
/// then one validation run with every thruster.
pub fn fly_dp_campaign(trial: &DpTrial, seed: u64) -> Vec<DpLog> {
    let mut out = Vec::new();
    let mut tag = 0;
    for (kind, code) in [
        (DpManoeuvre::Surge, "SI1"),
        (DpManoeuvre::SwayYaw, "SI2"),
        (DpManoeuvre::Azimuth, "SI3"),
    ] {
        for r in 1..=trial.repetitions {
            tag += 1;
            out.push(fly(
                kind,
                format!("{code}-{r}"),
                trial,
                derive_seed(seed, tag),
            ));
        }
    }
    out.push(fly(
        DpManoeuvre::Validation,
        "VAL".into(),
        trial,
        derive_seed(seed, 1000),
    ));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A steady surge under constant thrust settles at u = K·2·c / (−A_h11·M11)
    /// (D·ν = T·K·u with D = −A_h·M), and νᵀC(ν)ν = 0.
    #[test]
    fn steady_surge_and_coriolis_do_no_work() {
        let m = mat(&M);
        let nu = Vector3::new(0.3, -0.2, 0.05);
        assert!(nu.dot(&coriolis(&m, &nu)).abs() < 1e-15);
        let m_inv = m.try_inverse().unwrap();
        let d = -mat(&A_H) * m;
        let c = 0.25;
        let f = Vector3::new(2.0 * K[0] * c, 0.0, 0.0);
        let mut s = [0.0; 6];
        let dt = 0.05;
        for _ in 0..40_000 {
            let k = deriv(&m_inv, &m, &d, &s, &f);
            for i in 0..6 {
                s[i] += dt * k[i];
            }
        }
        let expected = 2.0 * K[0] * c / (-A_H[0][0] * M[0][0]);
        assert!(
            (s[0] / expected - 1.0).abs() < 1e-6,
            "{} vs {expected}",
            s[0]
        );
        assert!(s[1].abs() < 1e-12 && s[2].abs() < 1e-12);
    }

    #[test]
    fn campaign_logs_position_only_at_one_hertz() {
        let logs = fly_dp_campaign(&DpTrial::default(), 7);
        assert_eq!(logs.len(), 7);
        let first = &logs[0].csv;
        assert!(first.starts_with("t,thr_1,thr_2,thr_3,thr_4,thr_5,thr_6,x,y,psi\n"));
        assert_eq!(first.lines().count(), 601);
        assert_eq!(logs[6].manoeuvre.family(), "validation");
    }
}
