//! Sea-trial campaigns of the two vessels, logged as CSV strings.
//!
//! Every row is `t` (s), the inputs held over [t, t + h), then the state at
//! t: `u,v,r` (m/s, m/s, rad/s, over ground in the body frame) and
//! `x,y,psi` (m, m, rad in NED, ψ wrapped to (−π, π]), each with optional
//! Gaussian measurement noise ([`Noise`]). Inputs are either the
//! generalized forces [`FORCES_HEADER`] (τ_X, τ_Y in N, τ_N in N·m) or,
//! for the Otter, its two propeller commands [`COMMANDS_HEADER`] (thrust
//! [`OTTER_THRUST_N`]·thr_i, τ = [`OTTER_T`]·thrust). Each run starts
//! drifting with the current (ν_r = 0) at the origin with a random heading,
//! and draws its own current realisation ([`Effects::current`]), which it
//! returns with the log. The inputs, the current, the heading and the noise
//! come from separate seed streams, so switching an effect or the noise
//! changes nothing else.
//!
//! - Otter ([`fly_usv_campaign`], 10 Hz): `surge-1…3` (family `dynamic`):
//!   both propellers on one command, a level (three speed levels) plus a
//!   PRBS; `turn-1…3` (`dynamic`): the same levels held in common with a
//!   differential PRBS — a yaw-moment PRBS at a mean forward thrust, since
//!   the Otter turns only with speed and sways only through yaw — at two
//!   amplitudes, the second half at [`UsvTrial::yaw_second_half`]; `VAL`
//!   (`validation`): common and differential commands at independent random
//!   held levels.
//! - Supply vessel ([`fly_supply_campaign`], 1 Hz): `SI1-r` (`dp_surge`):
//!   τ_X at held levels of alternating sign; `SI2-r` (`dp_sway_yaw`): τ_Y
//!   and τ_N at independent held levels; `VAL` (`validation`): all three.
//!   Forces slewed at 5 % of their maximum per second, zero for 10 s.

use nalgebra::Vector3;

use super::current::CurrentTrack;
use super::model::{Effects, Simulator, SurfaceVessel};
use super::signals::{held, prbs, slewed};
use super::vessels::{OTTER_T, OTTER_THRUST_N};
use crate::rng::{Rng, derive_seed};

/// Header of a log carrying generalized forces.
pub const FORCES_HEADER: &str = "t,tau_X,tau_Y,tau_N,u,v,r,x,y,psi";
/// Header of an Otter log carrying propeller commands.
pub const COMMANDS_HEADER: &str = "t,thr_1,thr_2,u,v,r,x,y,psi";
/// Otter log rate (Hz).
pub const USV_RATE_HZ: f64 = 10.0;
/// Supply vessel log rate (Hz).
pub const SUPPLY_RATE_HZ: f64 = 1.0;
/// RK4 steps per logged sample (0.01 s for the Otter, 0.1 s for the
/// supply vessel).
pub const SUBSTEPS: usize = 10;

/// Gaussian measurement noise (standard deviations).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Noise {
    /// u, v (m/s) and r (rad/s).
    pub velocity: [f64; 3],
    /// x and y (m).
    pub position_m: f64,
    /// ψ (rad).
    pub heading_rad: f64,
}

impl Noise {
    /// Exact measurements.
    pub const NONE: Noise = Noise {
        velocity: [0.0; 3],
        position_m: 0.0,
        heading_rad: 0.0,
    };
    /// A small USV's RTK GNSS and IMU: 0.01 m/s, 0.005 rad/s, 0.02 m,
    /// 0.005 rad.
    pub const OTTER: Noise = Noise {
        velocity: [0.01, 0.01, 0.005],
        position_m: 0.02,
        heading_rad: 0.005,
    };
    /// A DP vessel's DGNSS and gyro: 0.02 m/s, 2e-4 rad/s, 0.5 m, 0.2°.
    pub const SUPPLY: Noise = Noise {
        velocity: [0.02, 0.02, 2e-4],
        position_m: 0.5,
        heading_rad: 0.2 * std::f64::consts::PI / 180.0,
    };
}

/// What an Otter log carries as inputs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UsvLogged {
    /// `tau_X,tau_Y,tau_N` (τ_Y = 0).
    Forces,
    /// `thr_1,thr_2` (port, starboard), dimensionless.
    Commands,
}

/// How to fly and log the Otter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UsvTrial {
    /// The physics flown.
    pub effects: Effects,
    /// Measurement noise.
    pub noise: Noise,
    /// Forces or commands.
    pub logged: UsvLogged,
    /// Mean command per propeller of the three speed levels (both surge
    /// and turn runs); 0.10, 0.18, 0.26 make 0.31, 0.56, 0.80 m/s clean.
    pub levels: [f64; 3],
    /// PRBS amplitude on the common command in surge runs.
    pub surge_amplitude: f64,
    /// PRBS amplitude of the differential command in the turn runs' first
    /// half and the validation run's range (±0.1: τ_N = ±9.5 N·m, r up to
    /// ≈ 0.2 rad/s).
    pub yaw_amplitude: f64,
    /// The differential amplitude of each turn run's second half, as a
    /// fraction of [`UsvTrial::yaw_amplitude`] (1: one amplitude). Crews
    /// fly turns at two sizes (zig-zag 20/20 then 10/10): one amplitude
    /// makes a damping that grows with |r| indistinguishable from a
    /// linear one (|r|v ≈ a·v).
    pub yaw_second_half: f64,
    /// PRBS chip (s).
    pub chip_s: f64,
    /// Length of each surge and turn run (s).
    pub run_s: f64,
    /// Length of the validation run (s).
    pub validation_s: f64,
}

impl Default for UsvTrial {
    fn default() -> Self {
        UsvTrial {
            effects: Effects::CLEAN,
            noise: Noise::OTTER,
            logged: UsvLogged::Forces,
            levels: [0.10, 0.18, 0.26],
            surge_amplitude: 0.04,
            yaw_amplitude: 0.1,
            yaw_second_half: 0.5,
            chip_s: 1.5,
            run_s: 120.0,
            validation_s: 180.0,
        }
    }
}

/// How to fly and log the supply vessel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SupplyTrial {
    /// The physics flown.
    pub effects: Effects,
    /// Measurement noise.
    pub noise: Noise,
    /// Samples per run (1 Hz).
    pub samples: usize,
    /// Runs of SI1 and of SI2 each.
    pub repetitions: usize,
    /// Largest |τ_X| (N), |τ_Y| (N), |τ_N| (N·m).
    pub force_max: [f64; 3],
    /// Validation runs (`VAL`, `VAL-2`, …).
    pub validation_runs: usize,
}

impl Default for SupplyTrial {
    fn default() -> Self {
        SupplyTrial {
            effects: Effects::CLEAN,
            noise: Noise::SUPPLY,
            samples: 600,
            repetitions: 2,
            force_max: [1.0e5, 1.0e5, 1.5e6],
            validation_runs: 1,
        }
    }
}

/// One logged run.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceRun {
    /// Run name, e.g. `turn-2`, `SI1-1`, `VAL`.
    pub name: String,
    /// `dynamic` or `validation` (Otter); `dp_surge`, `dp_sway_yaw` or
    /// `validation` (supply vessel).
    pub family: &'static str,
    /// The CSV log.
    pub csv: String,
    /// The true current: β_c and V_c at each logged row.
    pub current: CurrentTrack,
}

/// A campaign and its truth.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceCampaign {
    /// The true parameters.
    pub vessel: SurfaceVessel,
    /// The physics flown.
    pub effects: Effects,
    /// Log rate (Hz).
    pub rate_hz: f64,
    /// The runs in flying order.
    pub runs: Vec<SurfaceRun>,
}

/// What a log carries between t and the state.
enum Inputs {
    Commands(Vec<[f64; 2]>),
    Forces(Vec<Vector3<f64>>),
}

/// τ = T · K · thr of the Otter's propellers.
fn otter_tau(c: &[f64; 2]) -> Vector3<f64> {
    Vector3::from_fn(|i, _| OTTER_THRUST_N * (OTTER_T[i][0] * c[0] + OTTER_T[i][1] * c[1]))
}

/// Seed-stream tags within a run.
const INPUTS: u64 = 1;
const CURRENT: u64 = 2;
const HEADING: u64 = 3;
const NOISE: u64 = 4;

/// ψ wrapped to (−π, π].
pub fn wrap_heading(psi: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    PI - (PI - psi).rem_euclid(TAU)
}

/// Flies `inputs` and writes the log of one run.
fn fly_run(
    sim: &Simulator,
    trial: (&Effects, &Noise),
    h: f64,
    inputs: Inputs,
    seed: u64,
    name: String,
    family: &'static str,
) -> SurfaceRun {
    let (effects, noise) = trial;
    let taus: Vec<Vector3<f64>> = match &inputs {
        Inputs::Commands(c) => c.iter().map(otter_tau).collect(),
        Inputs::Forces(t) => t.clone(),
    };
    let n = taus.len();
    let track = effects
        .current
        .realise(n, h, &mut Rng::new(derive_seed(seed, CURRENT)));
    let psi0 =
        Rng::new(derive_seed(seed, HEADING)).range(-std::f64::consts::PI, std::f64::consts::PI);
    let [u_c, v_c] = track.segment(0, h).body(psi0);
    let states = sim.fly([u_c, v_c, 0.0, 0.0, 0.0, psi0], &taus, &track, h, SUBSTEPS);
    let mut rng = Rng::new(derive_seed(seed, NOISE));
    let decimals = if h < 1.0 { 1 } else { 0 };
    let mut csv = String::from(match inputs {
        Inputs::Commands(_) => COMMANDS_HEADER,
        Inputs::Forces(_) => FORCES_HEADER,
    });
    csv.push('\n');
    for (k, s) in states.iter().enumerate() {
        csv.push_str(&format!("{:.*}", decimals, k as f64 * h));
        match &inputs {
            // + 0.0 writes −0 as 0.
            Inputs::Commands(c) => {
                csv.push_str(&format!(",{:.6},{:.6}", c[k][0] + 0.0, c[k][1] + 0.0))
            }
            Inputs::Forces(t) => {
                for f in t[k].iter() {
                    csv.push_str(&format!(",{:.12e}", f + 0.0));
                }
            }
        }
        let mut e = |sd: f64| if sd > 0.0 { sd * rng.normal() } else { 0.0 };
        let u = s[0] + e(noise.velocity[0]);
        let v = s[1] + e(noise.velocity[1]);
        let r = s[2] + e(noise.velocity[2]);
        let x = s[3] + e(noise.position_m);
        let y = s[4] + e(noise.position_m);
        let psi = wrap_heading(s[5] + e(noise.heading_rad));
        csv.push_str(&format!(
            ",{:.6},{:.6},{:.8},{:.4},{:.4},{:.6}\n",
            u + 0.0,
            v + 0.0,
            r + 0.0,
            x + 0.0,
            y + 0.0,
            psi + 0.0
        ));
    }
    SurfaceRun {
        name,
        family,
        csv,
        current: track,
    }
}

/// The Otter campaign of seed `seed` on `vessel` (the Otter or a draw of
/// it): `surge-1…3`, `turn-1…3`, `VAL` at [`USV_RATE_HZ`].
pub fn fly_usv_campaign(vessel: &SurfaceVessel, trial: &UsvTrial, seed: u64) -> SurfaceCampaign {
    let sim = Simulator::new(vessel, trial.effects);
    let h = 1.0 / USV_RATE_HZ;
    let n = (trial.run_s * USV_RATE_HZ).round() as usize;
    // Commands are flown as logged, to the 1e-6 of the log.
    let log = |c: Vec<[f64; 2]>| {
        let c: Vec<[f64; 2]> = c
            .iter()
            .map(|p| p.map(|x| (x * 1e6).round() / 1e6))
            .collect();
        match trial.logged {
            UsvLogged::Commands => Inputs::Commands(c),
            UsvLogged::Forces => Inputs::Forces(c.iter().map(otter_tau).collect()),
        }
    };
    let ctx = (&trial.effects, &trial.noise);
    let mut runs = Vec::new();
    for (i, &level) in trial.levels.iter().enumerate() {
        let run_seed = derive_seed(seed, 1 + i as u64);
        let p = prbs(
            &mut Rng::new(derive_seed(run_seed, INPUTS)),
            n,
            h,
            trial.chip_s,
        );
        let c = p
            .iter()
            .map(|&p| [level + trial.surge_amplitude * p; 2])
            .collect();
        runs.push(fly_run(
            &sim,
            ctx,
            h,
            log(c),
            run_seed,
            format!("surge-{}", i + 1),
            "dynamic",
        ));
    }
    for (i, &level) in trial.levels.iter().enumerate() {
        let run_seed = derive_seed(seed, 4 + i as u64);
        let p = prbs(
            &mut Rng::new(derive_seed(run_seed, INPUTS)),
            n,
            h,
            trial.chip_s,
        );
        let c = p
            .iter()
            .enumerate()
            .map(|(k, &p)| {
                let a = trial.yaw_amplitude
                    * if 2 * k < n {
                        1.0
                    } else {
                        trial.yaw_second_half
                    };
                [level + a * p, level - a * p]
            })
            .collect();
        runs.push(fly_run(
            &sim,
            ctx,
            h,
            log(c),
            run_seed,
            format!("turn-{}", i + 1),
            "dynamic",
        ));
    }
    let run_seed = derive_seed(seed, 999);
    let nv = (trial.validation_s * USV_RATE_HZ).round() as usize;
    let mut rng = Rng::new(derive_seed(run_seed, INPUTS));
    let lo = trial.levels.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = trial
        .levels
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max);
    let common = held(&mut rng, nv, 0, (3.0 / h, 8.0 / h), (lo, hi), false);
    let a = trial.yaw_amplitude;
    let diff = held(&mut rng, nv, 0, (1.0 / h, 4.0 / h), (-a, a), false);
    let c = common
        .iter()
        .zip(&diff)
        .map(|(&m, &d)| [m + d, m - d])
        .collect();
    runs.push(fly_run(
        &sim,
        ctx,
        h,
        log(c),
        run_seed,
        "VAL".into(),
        "validation",
    ));
    SurfaceCampaign {
        vessel: vessel.clone(),
        effects: trial.effects,
        rate_hz: USV_RATE_HZ,
        runs,
    }
}

/// The supply-vessel campaign of seed `seed` on `vessel` (the supply vessel
/// or a draw of it): `SI1-r`, `SI2-r` (r = 1 … repetitions), then `VAL`,
/// `VAL-2`, … at [`SUPPLY_RATE_HZ`].
pub fn fly_supply_campaign(
    vessel: &SurfaceVessel,
    trial: &SupplyTrial,
    seed: u64,
) -> SurfaceCampaign {
    const SURGE_HOLD: (f64, f64) = (60.0, 150.0);
    const SWAY_YAW_HOLD: (f64, f64) = (40.0, 120.0);
    let sim = Simulator::new(vessel, trial.effects);
    let h = 1.0 / SUPPLY_RATE_HZ;
    let n = trial.samples;
    let f = trial.force_max;
    let ctx = (&trial.effects, &trial.noise);
    // One force channel: held levels of alternating sign, |τ| in `band` × max, slewed.
    let channel = |rng: &mut Rng, i: usize, hold, band: (f64, f64)| -> Vec<f64> {
        let x = held(rng, n, 10, hold, (band.0 * f[i], band.1 * f[i]), true);
        slewed(&x, 0.05 * f[i] * h)
    };
    let forces = |x: Vec<f64>, y: Vec<f64>, z: Vec<f64>| -> Inputs {
        Inputs::Forces((0..n).map(|k| Vector3::new(x[k], y[k], z[k])).collect())
    };
    let mut runs = Vec::new();
    let mut tag = 0;
    for (code, family) in [("SI1", "dp_surge"), ("SI2", "dp_sway_yaw")] {
        for r in 1..=trial.repetitions {
            tag += 1;
            let run_seed = derive_seed(seed, tag);
            let mut rng = Rng::new(derive_seed(run_seed, INPUTS));
            let zero = vec![0.0; n];
            let inputs = if code == "SI1" {
                forces(
                    channel(&mut rng, 0, SURGE_HOLD, (0.4, 1.0)),
                    zero.clone(),
                    zero,
                )
            } else {
                let y = channel(&mut rng, 1, SWAY_YAW_HOLD, (0.4, 1.0));
                let z = channel(&mut rng, 2, SWAY_YAW_HOLD, (0.4, 1.0));
                forces(zero, y, z)
            };
            runs.push(fly_run(
                &sim,
                ctx,
                h,
                inputs,
                run_seed,
                format!("{code}-{r}"),
                family,
            ));
        }
    }
    for r in 1..=trial.validation_runs {
        let run_seed = derive_seed(seed, 999 + r as u64);
        let mut rng = Rng::new(derive_seed(run_seed, INPUTS));
        let x = channel(&mut rng, 0, SURGE_HOLD, (0.3, 0.8));
        let y = channel(&mut rng, 1, SWAY_YAW_HOLD, (0.3, 0.8));
        let z = channel(&mut rng, 2, SWAY_YAW_HOLD, (0.3, 0.8));
        let name = if r == 1 {
            "VAL".to_string()
        } else {
            format!("VAL-{r}")
        };
        runs.push(fly_run(
            &sim,
            ctx,
            h,
            forces(x, y, z),
            run_seed,
            name,
            "validation",
        ));
    }
    SurfaceCampaign {
        vessel: vessel.clone(),
        effects: trial.effects,
        rate_hz: SUPPLY_RATE_HZ,
        runs,
    }
}
