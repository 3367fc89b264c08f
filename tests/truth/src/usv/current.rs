//! Ocean current (Fossen 2021, ch. 8, ocean current models; the 2-D current
//! used in MSS `otter.m` and `osv.m`): a current of speed V_c flowing
//! towards direction β_c in NED has the body-frame velocity
//!
//!   ν_c = R(ψ)ᵀ [V_c cos β_c, V_c sin β_c, 0]ᵀ
//!       = [V_c cos(β_c − ψ), V_c sin(β_c − ψ), 0]ᵀ,
//!
//! and, the current being irrotational, its body-frame rate is
//!
//!   ν̇_c = [r v_c + V̇_c cos(β_c − ψ), −r u_c + V̇_c sin(β_c − ψ), 0]ᵀ.
//!
//! A slowly varying speed is Fossen's first-order Gauss–Markov process
//! V̇_c + μ V_c = w (w white), written here about a mean V̄_c and held to
//! 0 ≤ V_c ≤ V_max: V_c(t) − V̄_c is an Ornstein–Uhlenbeck process with
//! μ = 1/T_c and stationary standard deviation σ, sampled exactly at the
//! log instants and linear between them (so V̇_c is constant over a sample).

use crate::rng::Rng;

/// The current a run flies in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Current {
    /// No current: ν_c = 0.
    None,
    /// Constant speed V_c (m/s) towards β_c (rad, NED, from north towards
    /// east).
    Constant {
        /// V_c (m/s).
        speed_mps: f64,
        /// β_c (rad).
        direction_rad: f64,
    },
    /// V_c(t): a first-order Gauss–Markov process about `mean_mps`, direction
    /// fixed. Each run draws its own realisation, starting from the
    /// stationary distribution.
    GaussMarkov {
        /// V̄_c (m/s).
        mean_mps: f64,
        /// Stationary standard deviation σ of V_c (m/s).
        std_mps: f64,
        /// Correlation time T_c = 1/μ (s).
        time_constant_s: f64,
        /// V_max (m/s); V_c is held to [0, V_max].
        max_mps: f64,
        /// β_c (rad).
        direction_rad: f64,
    },
}

impl Current {
    /// A constant current drawn from `seed`: V_c uniform in
    /// [`lo_mps`, `hi_mps`), β_c uniform in [−π, π).
    pub fn random_constant(seed: u64, lo_mps: f64, hi_mps: f64) -> Current {
        let mut rng = Rng::new(seed);
        Current::Constant {
            speed_mps: rng.range(lo_mps, hi_mps),
            direction_rad: rng.range(-std::f64::consts::PI, std::f64::consts::PI),
        }
    }

    /// V_c at the `n` instants k·h (k = 0 … n − 1), drawing the
    /// Gauss–Markov steps from `rng`.
    pub fn realise(&self, n: usize, h: f64, rng: &mut Rng) -> CurrentTrack {
        match *self {
            Current::None => CurrentTrack {
                direction_rad: 0.0,
                speed_mps: vec![0.0; n],
            },
            Current::Constant {
                speed_mps,
                direction_rad,
            } => CurrentTrack {
                direction_rad,
                speed_mps: vec![speed_mps; n],
            },
            Current::GaussMarkov {
                mean_mps,
                std_mps,
                time_constant_s,
                max_mps,
                direction_rad,
            } => {
                let a = (-h / time_constant_s).exp();
                let step_std = std_mps * (1.0 - a * a).sqrt();
                let mut v = (mean_mps + std_mps * rng.normal()).clamp(0.0, max_mps);
                let speed_mps = (0..n)
                    .map(|_| {
                        let now = v;
                        v = (mean_mps + a * (v - mean_mps) + step_std * rng.normal())
                            .clamp(0.0, max_mps);
                        now
                    })
                    .collect();
                CurrentTrack {
                    direction_rad,
                    speed_mps,
                }
            }
        }
    }
}

/// One realised current: β_c and V_c at the log instants.
#[derive(Debug, Clone, PartialEq)]
pub struct CurrentTrack {
    /// β_c (rad).
    pub direction_rad: f64,
    /// V_c (m/s) at t = k·h.
    pub speed_mps: Vec<f64>,
}

impl CurrentTrack {
    /// Mean V_c (m/s).
    pub fn mean_mps(&self) -> f64 {
        if self.speed_mps.is_empty() {
            return 0.0;
        }
        self.speed_mps.iter().sum::<f64>() / self.speed_mps.len() as f64
    }

    /// The NED current velocity [V_c cos β_c, V_c sin β_c] (m/s) at sample k.
    pub fn ned_mps(&self, k: usize) -> [f64; 2] {
        let v = self.speed_mps[k];
        [v * self.direction_rad.cos(), v * self.direction_rad.sin()]
    }

    /// The current over the sample interval [k·h, (k+1)·h]: V_c linear from
    /// sample k to k + 1 (held after the last sample).
    pub fn segment(&self, k: usize, h: f64) -> CurrentNow {
        let v0 = self.speed_mps[k];
        let v1 = *self.speed_mps.get(k + 1).unwrap_or(&v0);
        CurrentNow {
            speed_mps: v0,
            rate_mps2: (v1 - v0) / h,
            direction_rad: self.direction_rad,
        }
    }
}

/// The current at one instant: V_c, V̇_c, β_c. `advanced(dt)` moves along a
/// sample interval at constant V̇_c.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurrentNow {
    /// V_c (m/s).
    pub speed_mps: f64,
    /// V̇_c (m/s²).
    pub rate_mps2: f64,
    /// β_c (rad).
    pub direction_rad: f64,
}

impl CurrentNow {
    /// No current.
    pub const NONE: CurrentNow = CurrentNow {
        speed_mps: 0.0,
        rate_mps2: 0.0,
        direction_rad: 0.0,
    };

    /// The current `dt` seconds later.
    pub fn advanced(&self, dt: f64) -> CurrentNow {
        CurrentNow {
            speed_mps: self.speed_mps + self.rate_mps2 * dt,
            ..*self
        }
    }

    /// ν_c = [u_c, v_c] (m/s) in the body frame at heading ψ.
    pub fn body(&self, psi: f64) -> [f64; 2] {
        let (s, c) = (self.direction_rad - psi).sin_cos();
        [self.speed_mps * c, self.speed_mps * s]
    }

    /// ν̇_c = [r v_c + V̇_c cos(β_c − ψ), −r u_c + V̇_c sin(β_c − ψ)] (m/s²).
    pub fn body_rate(&self, psi: f64, r: f64) -> [f64; 2] {
        let (s, c) = (self.direction_rad - psi).sin_cos();
        let (u_c, v_c) = (self.speed_mps * c, self.speed_mps * s);
        [r * v_c + self.rate_mps2 * c, -r * u_c + self.rate_mps2 * s]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ν̇_c is the time derivative of ν_c along ψ(t) = ψ₀ + r t, V_c(t) =
    /// V₀ + V̇ t.
    #[test]
    fn body_rate_is_the_derivative_of_the_body_current() {
        let c = CurrentNow {
            speed_mps: 0.4,
            rate_mps2: 0.01,
            direction_rad: 0.7,
        };
        let (psi, r, dt) = (-1.1, 0.05, 1e-6);
        let a = c.advanced(-dt).body(psi - r * dt);
        let b = c.advanced(dt).body(psi + r * dt);
        let rate = c.body_rate(psi, r);
        for i in 0..2 {
            assert!(((b[i] - a[i]) / (2.0 * dt) - rate[i]).abs() < 1e-8);
        }
    }

    #[test]
    fn gauss_markov_stays_in_bounds_near_its_mean_and_is_seeded() {
        let gm = Current::GaussMarkov {
            mean_mps: 0.3,
            std_mps: 0.05,
            time_constant_s: 100.0,
            max_mps: 0.5,
            direction_rad: 1.0,
        };
        let a = gm.realise(100_000, 1.0, &mut Rng::new(5));
        let b = gm.realise(100_000, 1.0, &mut Rng::new(5));
        assert_eq!(a, b);
        assert!(a.speed_mps.iter().all(|v| (0.0..=0.5).contains(v)));
        assert!((a.mean_mps() - 0.3).abs() < 0.01, "{}", a.mean_mps());
        let steps: f64 = a.speed_mps.windows(2).map(|w| (w[1] - w[0]).abs()).sum();
        // Slowly varying: the mean step is ~σ·√(2h/T_c)·√(2/π) ≈ 0.0056.
        assert!(steps / 1e5 < 0.01);
    }
}
