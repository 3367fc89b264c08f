//! What a campaign flies: grid, durations, amplitudes, noise, clocks.

use crate::controller::Envelope;

use super::Dof;

/// Standard deviations of Gaussian measurement noise (white, per sample).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NoiseSpec {
    /// u, v, w (m/s).
    pub velocity_linear: f64,
    /// p, q, r (rad/s).
    pub velocity_angular: f64,
    /// x, y (m).
    pub position_xy: f64,
    /// z (m).
    pub depth: f64,
    /// φ, θ (rad).
    pub roll_pitch: f64,
    /// ψ (rad).
    pub heading: f64,
}

impl Default for NoiseSpec {
    /// An INS-grade set: 5 mm/s, 2 mrad/s, 5 cm, 2 cm, 2 mrad, 5 mrad.
    fn default() -> Self {
        NoiseSpec {
            velocity_linear: 0.005,
            velocity_angular: 0.002,
            position_xy: 0.05,
            depth: 0.02,
            roll_pitch: 0.002,
            heading: 0.005,
        }
    }
}

impl NoiseSpec {
    /// No noise at all.
    pub fn none() -> Self {
        NoiseSpec {
            velocity_linear: 0.0,
            velocity_angular: 0.0,
            position_xy: 0.0,
            depth: 0.0,
            roll_pitch: 0.0,
            heading: 0.0,
        }
    }

    /// σ of ν component i.
    pub fn nu_std(&self, i: usize) -> f64 {
        if i < 3 {
            self.velocity_linear
        } else {
            self.velocity_angular
        }
    }

    /// σ of η component i.
    pub fn eta_std(&self, i: usize) -> f64 {
        [
            self.position_xy,
            self.position_xy,
            self.depth,
            self.roll_pitch,
            self.roll_pitch,
            self.heading,
        ][i]
    }
}

/// The campaign to fly. `Default` is the brief's campaign.
#[derive(Debug, Clone, PartialEq)]
pub struct CampaignSpec {
    /// Grid of forward speeds u₀ (m/s), each with a static and dynamic runs.
    pub grid_speeds: Vec<f64>,
    /// Validation staircase speeds; None: below, between and beyond the
    /// grid (see [`CampaignSpec::validation_speeds`]).
    pub validation_speeds: Option<Vec<f64>>,
    /// DOFs with a dynamic run at each grid speed.
    pub dynamic_dofs: Vec<Dof>,
    /// Static run duration range (s).
    pub static_duration_s: (f64, f64),
    /// Dynamic run duration range (s).
    pub dynamic_duration_s: (f64, f64),
    /// Validation run duration (s).
    pub validation_duration_s: f64,
    /// Excitation amplitudes: u, v, w (m/s), φ, θ (rad), r (rad/s); each
    /// run draws ×[0.8, 1.2] of it, surge at most 0.6 u₀.
    pub amplitude: [f64; 6],
    /// Noise on the controller's measurements and the single/control logs.
    pub noise: NoiseSpec,
    /// Noise of the nav computer's file.
    pub nav_noise: NoiseSpec,
    /// Nav file rate (Hz).
    pub nav_rate_hz: f64,
    /// Range of the campaign-wide clock offset (s).
    pub clock_offset_range_s: (f64, f64),
    /// Internal RK4 rate (Hz), a multiple of 20.
    pub integration_rate_hz: f64,
    /// Unlogged flight before each run, for the loops to settle (s).
    pub preroll_s: f64,
}

impl Default for CampaignSpec {
    fn default() -> Self {
        CampaignSpec {
            grid_speeds: vec![0.5, 1.0, 1.5, 2.0],
            validation_speeds: None,
            dynamic_dofs: Dof::ALL.to_vec(),
            static_duration_s: (60.0, 90.0),
            dynamic_duration_s: (120.0, 240.0),
            validation_duration_s: 600.0,
            amplitude: [0.25, 0.3, 0.25, 0.15, 0.15, 0.25],
            noise: NoiseSpec::default(),
            nav_noise: NoiseSpec::default(),
            nav_rate_hz: 25.0,
            clock_offset_range_s: (3.0, 15.0),
            integration_rate_hz: 200.0,
            preroll_s: 20.0,
        }
    }
}

impl CampaignSpec {
    /// The validation staircase: the given speeds, or 0.6·(lowest grid
    /// speed), every midpoint of the grid, and the highest grid speed plus
    /// half the last spacing (default grid: 0.3, 0.75, 1.25, 1.75, 2.25).
    pub fn validation_speeds(&self) -> Vec<f64> {
        if let Some(v) = &self.validation_speeds {
            return v.clone();
        }
        let mut g = self.grid_speeds.clone();
        g.sort_by(f64::total_cmp);
        let mut out = vec![0.6 * g[0]];
        out.extend(g.windows(2).map(|w| 0.5 * (w[0] + w[1])));
        let step = if g.len() > 1 {
            g[g.len() - 1] - g[g.len() - 2]
        } else {
            0.6
        };
        out.push(g[g.len() - 1] + 0.5 * step);
        out
    }

    /// Highest speeds the campaign asks for, for thrust limits.
    pub fn envelope(&self) -> Envelope {
        let top = self
            .grid_speeds
            .iter()
            .chain(self.validation_speeds().iter())
            .fold(0.0f64, |a, b| a.max(*b));
        Envelope {
            u_max: top + 1.2 * self.amplitude[0],
            amplitude: self.amplitude,
        }
    }
}
