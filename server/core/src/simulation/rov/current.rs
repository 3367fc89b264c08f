//! Ocean current V_c, constant in NED or a seeded first-order Gauss–Markov
//! process V̇_c + μ V_c = w (μ = 0: random walk), bounded in speed (Fossen
//! 2011, sec. 8.3). In the body frame ν_c = [Rᵀ(Θ) V_c; 0₃], so the current
//! the vehicle feels turns with its heading.

use nalgebra::Vector3;

use super::error::{SimError, finite, non_negative};
use crate::rng::SplitMix64;

/// The current in the water the vehicle moves through.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Current {
    /// Still water.
    #[default]
    None,
    /// Constant V_c = [north, east, down] (m/s) in NED.
    Constant {
        /// V_c in NED (m/s).
        ned: [f64; 3],
    },
    /// Gauss–Markov / random walk in NED.
    RandomWalk(RandomWalkCurrent),
}

/// V̇_c + μ V_c = w with white w of intensity σ² per NED axis, |V_c| ≤
/// `max_speed`; the draw is held over each internal integration step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RandomWalkCurrent {
    /// V_c(0) in NED (m/s).
    pub initial_ned: [f64; 3],
    /// σ per NED axis (m/s per √s): the standard deviation of the change
    /// over 1 s when μ = 0.
    pub sigma: [f64; 3],
    /// μ (1/s), ≥ 0; 0 is a pure random walk.
    pub mu: f64,
    /// Upper bound on |V_c| (m/s); +∞ for none.
    pub max_speed: f64,
    /// Seed of the draws.
    pub seed: u64,
}

impl Current {
    /// Checks finiteness and ranges.
    pub fn validate(&self) -> Result<(), SimError> {
        match self {
            Current::None => Ok(()),
            Current::Constant { ned } => finite("current.ned", ned.iter()),
            Current::RandomWalk(rw) => {
                finite("current.initial_ned", rw.initial_ned.iter())?;
                for (axis, s) in ["north", "east", "down"].iter().zip(rw.sigma) {
                    non_negative(format!("current.sigma[{axis}]"), s, false)?;
                }
                non_negative("current.mu".into(), rw.mu, false)?;
                if rw.max_speed.is_nan() || rw.max_speed <= 0.0 {
                    return Err(SimError::InvalidParameter {
                        name: "current.max_speed".into(),
                        value: rw.max_speed,
                        requirement: "> 0 (or +∞ for no bound)",
                    });
                }
                Ok(())
            }
        }
    }
}

/// The current's state during one run.
#[derive(Debug, Clone)]
pub(crate) struct CurrentProcess {
    v: Vector3<f64>,
    walk: Option<(RandomWalkCurrent, SplitMix64)>,
}

fn bounded(v: Vector3<f64>, max: f64) -> Vector3<f64> {
    let n = v.norm();
    if n > max { v * (max / n) } else { v }
}

impl CurrentProcess {
    pub(crate) fn new(c: &Current) -> Self {
        match c {
            Current::None => CurrentProcess {
                v: Vector3::zeros(),
                walk: None,
            },
            Current::Constant { ned } => CurrentProcess {
                v: Vector3::from(*ned),
                walk: None,
            },
            Current::RandomWalk(rw) => CurrentProcess {
                v: bounded(Vector3::from(rw.initial_ned), rw.max_speed),
                walk: Some((*rw, SplitMix64::new(rw.seed))),
            },
        }
    }

    /// V_c now (NED, m/s).
    pub(crate) fn ned(&self) -> Vector3<f64> {
        self.v
    }

    /// Advances by `dt` with the exact discretization of the Gauss–Markov
    /// process: V ← e^{−μ dt} V + σ √((1 − e^{−2μ dt}) / 2μ) N(0, 1)
    /// (σ √dt for μ = 0).
    pub(crate) fn advance(&mut self, dt: f64) {
        let Some((rw, rng)) = &mut self.walk else {
            return;
        };
        let decay = (-rw.mu * dt).exp();
        let spread = if rw.mu > 0.0 {
            ((1.0 - decay * decay) / (2.0 * rw.mu)).sqrt()
        } else {
            dt.sqrt()
        };
        for i in 0..3 {
            self.v[i] = decay * self.v[i] + rw.sigma[i] * spread * rng.normal();
        }
        self.v = bounded(self.v, rw.max_speed);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn random_walk_increments_have_the_set_spread() {
        let rw = RandomWalkCurrent {
            initial_ned: [0.2, 0.0, 0.0],
            sigma: [0.02, 0.01, 0.0],
            mu: 0.0,
            max_speed: f64::INFINITY,
            seed: 11,
        };
        let mut p = CurrentProcess::new(&Current::RandomWalk(rw));
        let dt = 0.1;
        let n = 20_000;
        let mut inc = [
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
        ];
        for _ in 0..n {
            let before = p.ned();
            p.advance(dt);
            for (i, v) in inc.iter_mut().enumerate() {
                v.push(p.ned()[i] - before[i]);
            }
        }
        // std of the increment is σ√dt; standard error of the estimate is
        // 0.5% for n = 20 000, so 3% is a loose but failing-capable bound.
        for (i, axis) in inc.iter().take(2).enumerate() {
            let s = (axis.iter().map(|x| x * x).sum::<f64>() / n as f64).sqrt();
            let want = rw.sigma[i] * dt.sqrt();
            assert!((s / want - 1.0).abs() < 0.03, "axis {i}: {s} vs {want}");
        }
        assert!(inc[2].iter().all(|x| *x == 0.0));
        // Same seed, same path; the bound holds.
        let mut a = CurrentProcess::new(&Current::RandomWalk(RandomWalkCurrent {
            max_speed: 0.25,
            ..rw
        }));
        let mut b = a.clone();
        for _ in 0..5000 {
            a.advance(dt);
            b.advance(dt);
            assert!(a.ned().norm() <= 0.25 + 1e-15);
        }
        assert_eq!(a.ned(), b.ned());
    }

    #[test]
    fn gauss_markov_settles_to_its_stationary_spread() {
        // Stationary variance σ²/(2μ).
        let rw = RandomWalkCurrent {
            initial_ned: [0.0; 3],
            sigma: [0.05, 0.0, 0.0],
            mu: 0.5,
            max_speed: f64::INFINITY,
            seed: 3,
        };
        let mut p = CurrentProcess::new(&Current::RandomWalk(rw));
        let mut acc = 0.0;
        let n = 200_000;
        for _ in 0..n {
            p.advance(0.5);
            acc += p.ned()[0] * p.ned()[0];
        }
        let var = acc / n as f64;
        let want = 0.05 * 0.05 / (2.0 * 0.5);
        assert!((var / want - 1.0).abs() < 0.05, "{var} vs {want}");
    }
}
