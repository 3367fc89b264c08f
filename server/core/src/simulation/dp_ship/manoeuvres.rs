//! The decoupled sea-trial manoeuvres of sec. 4.2 (Fig. 5–7), two per stage:
//!
//! 1. surge (SI1): the main propellers u1 = u2 alone, constant heading;
//! 2. sway and yaw (SI2): the tunnel thrusters, stern u3 = u4 against the
//!    bow u5, so the heading changes by tens of degrees;
//! 3. azimuth (SI3): the bow azimuth u6 alone.
//!
//! Commands are u = |p|·p (eq. 5, p0 = 0) of pitch ratios p held at random
//! levels for random durations and slewed at a finite pitch rate, as the
//! P/D traces of Fig. 5–7.

use nalgebra::DMatrix;

use crate::rng::SplitMix64;

/// One of the three decoupled manoeuvres.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Manoeuvre {
    /// Uncoupled surge with the main propellers (Fig. 5, SI1).
    Surge,
    /// Coupled sway and yaw with the tunnel thrusters (Fig. 6, SI2).
    SwayYaw,
    /// The azimuth thruster alone (Fig. 7, SI3).
    Azimuth,
}

impl Manoeuvre {
    /// The stages in the order SI1 → SI2 → SI3 (Fig. 4).
    pub const ALL: [Manoeuvre; 3] = [Manoeuvre::Surge, Manoeuvre::SwayYaw, Manoeuvre::Azimuth];

    /// Stage name of Fig. 4.
    pub fn stage(self) -> &'static str {
        match self {
            Manoeuvre::Surge => "SI1",
            Manoeuvre::SwayYaw => "SI2",
            Manoeuvre::Azimuth => "SI3",
        }
    }

    /// Initial heading (rad) as in the figures: 133° (Fig. 5), 100° (Fig. 6),
    /// 0° (Fig. 7).
    pub fn initial_heading(self) -> f64 {
        match self {
            Manoeuvre::Surge => 133f64.to_radians(),
            Manoeuvre::SwayYaw => 100f64.to_radians(),
            Manoeuvre::Azimuth => 0.0,
        }
    }
}

/// Pitch-ratio rate limit per sample (full pitch in 20 samples).
const PITCH_RATE: f64 = 0.05;

/// Held pitch levels of magnitude in `level` = (min, max) and alternating
/// sign (ahead, astern, …, as the traces of Fig. 5–7), with holds of `hold`
/// samples, slewed at [`PITCH_RATE`]; starts from zero pitch.
fn pitch_sequence(
    rng: &mut SplitMix64,
    n: usize,
    hold: (usize, usize),
    level: (f64, f64),
) -> Vec<f64> {
    let mut target = vec![0.0; n];
    // A quiet start (the ship at rest, as the figures start) then random holds.
    let mut k = n.min(10);
    let mut sign = if rng.uniform() < 0.5 { -1.0 } else { 1.0 };
    while k < n {
        let len = hold.0 + (rng.uniform() * (hold.1 - hold.0 + 1) as f64) as usize;
        let level = sign * rng.uniform_in(level.0, level.1);
        sign = -sign;
        for t in target.iter_mut().skip(k).take(len) {
            *t = level;
        }
        k += len;
    }
    let mut p = 0.0_f64;
    target
        .iter()
        .map(|&goal| {
            p += (goal - p).clamp(-PITCH_RATE, PITCH_RATE);
            p
        })
        .collect()
}

/// u = |p|·p (eq. 5 with p0 = 0).
fn command(p: f64) -> f64 {
    p.abs() * p
}

/// Thruster commands u (n × 6, columns u1 … u6) of one manoeuvre.
pub fn manoeuvre_inputs(kind: Manoeuvre, n: usize, seed: u64) -> DMatrix<f64> {
    let mut rng = SplitMix64::new(seed);
    let mut u = DMatrix::zeros(n, 6);
    match kind {
        Manoeuvre::Surge => {
            // 30–60 % pitch held for about a surge time constant (≈ 100 s)
            // gives the 2–4 m/s of Fig. 5.
            let p = pitch_sequence(&mut rng, n, (80, 160), (0.3, 0.6));
            for (k, &pk) in p.iter().enumerate() {
                u[(k, 0)] = command(pk);
                u[(k, 1)] = command(pk);
            }
        }
        Manoeuvre::SwayYaw => {
            let stern = pitch_sequence(&mut rng, n, (40, 120), (0.4, 1.0));
            let bow = pitch_sequence(&mut rng, n, (40, 120), (0.4, 1.0));
            for k in 0..n {
                u[(k, 2)] = command(stern[k]);
                u[(k, 3)] = command(stern[k]);
                u[(k, 4)] = command(bow[k]);
            }
        }
        Manoeuvre::Azimuth => {
            let p = pitch_sequence(&mut rng, n, (60, 150), (0.4, 1.0));
            for (k, &pk) in p.iter().enumerate() {
                u[(k, 5)] = command(pk);
            }
        }
    }
    u
}
