//! Weights of an LPV model's sub-models at a forward speed u.
//!
//! Inside the grid (thesis eq. 2.17/2.18): the nearest sub-model, or the
//! linear blend of the two bracketing ones.
//!
//! Beyond the grid the thesis holds the end sub-model. A model may instead
//! *extend* over a stated range beyond each end ([`Extension`]), with the
//! weights that are exact for the usual hull forces: linearized about
//! ν₀ = (u₀, 0, …), quadratic damping d|u|u gives D̄(u₀) = 2d|u₀| and
//! C(ν)ν's Munk terms give entries ∝ u₀ — D̄ is affine in u₀ — while the
//! constant load of the tangent, b(u₀) = d(u₀) − D̄(u₀)u₀ = −d u₀², is
//! quadratic. So D̄ is extrapolated linearly from the two end grid points
//! and the load quadratically through the three end points (Lagrange); M,
//! which does not change with speed, stays the end point's (extrapolating
//! the points' estimates of it would amplify their scatter). Extrapolating the load linearly, as a plain blend would,
//! gets the steady force wrong by d·w(w − 1)(Δx)² (at u = 0.3 m/s from a
//! 0.5/1.0 m/s grid, 0.14 d against a true 0.09 d).

/// Which grid points a speed uses, and with which weight: the sub-model of
/// `lower` gets `w_lower`, the one of `upper` gets 1 − `w_lower` (the
/// thesis's w(k)). `lower == upper` and `w_lower = 1` for a single model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScheduleWeights {
    /// Index of the lower (or only) grid point.
    pub lower: usize,
    /// Index of the upper (or only) grid point.
    pub upper: usize,
    /// Weight of the lower grid point's model, in [0, 1].
    pub w_lower: f64,
}

/// How the sub-model at a forward speed is chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Scheduling {
    /// Nearest grid point (thesis eq. 2.17).
    Nearest,
    /// Linear blend of the two neighbouring grid points (thesis eq. 2.18);
    /// the scheme behind the thesis's reported predictions.
    #[default]
    Interpolate,
}

/// The speeds (m/s) an interpolated model extends to beyond its grid:
/// down to `from_mps` ≤ the lowest grid speed and up to `to_mps` ≥ the
/// highest. Beyond those it holds the sub-model extrapolated to them.
/// Takes effect with [`Scheduling::Interpolate`] on a grid of three or more
/// points (the load's extrapolation needs three).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Extension {
    /// Lowest speed modelled (m/s).
    pub from_mps: f64,
    /// Highest speed modelled (m/s).
    pub to_mps: f64,
}

/// Weights of the sub-models at one speed: the dynamics (M, D̄; Φ, Γ) are
/// Σ `dynamics` wᵢ·(model i), the load Σ `load` vⱼ·(load j). Inside the
/// grid both are the thesis's blend; entries with weight 0 are unused.
/// Beyond it (`extrapolated`) the first dynamics entry is the end grid
/// point, whose M the model keeps ([`super::LpvModel::at`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Blend {
    /// (grid index, weight) of the dynamics; the weights sum to 1.
    pub dynamics: [(usize, f64); 2],
    /// (grid index, weight) of the load; the weights sum to 1.
    pub load: [(usize, f64); 3],
    /// Whether the load has weights of its own (the speed lies beyond the
    /// grid, in an extension).
    pub extrapolated: bool,
}

impl Blend {
    /// The blend of plain schedule weights (no extrapolation).
    pub fn of(w: ScheduleWeights) -> Self {
        let dynamics = [(w.lower, w.w_lower), (w.upper, 1.0 - w.w_lower)];
        Blend {
            dynamics,
            load: [dynamics[0], dynamics[1], (w.lower, 0.0)],
            extrapolated: false,
        }
    }
}

/// The weights of `speed` on a strictly increasing, non-empty, finite `grid`.
pub(crate) fn schedule(grid: &[f64], speed: f64, scheduling: Scheduling) -> ScheduleWeights {
    let only = |i| ScheduleWeights {
        lower: i,
        upper: i,
        w_lower: 1.0,
    };
    let last = grid.len() - 1;
    match scheduling {
        Scheduling::Nearest => {
            let mut best = 0;
            for (i, x) in grid.iter().enumerate() {
                // Strict < keeps the lower point on a tie.
                if (speed - x).abs() < (speed - grid[best]).abs() {
                    best = i;
                }
            }
            only(best)
        }
        Scheduling::Interpolate => {
            if speed <= grid[0] {
                return only(0);
            }
            if speed >= grid[last] {
                return only(last);
            }
            // grid[i] ≤ speed < grid[i + 1].
            let i = grid.partition_point(|x| *x <= speed) - 1;
            if speed == grid[i] {
                return only(i);
            }
            ScheduleWeights {
                lower: i,
                upper: i + 1,
                w_lower: (grid[i + 1] - speed) / (grid[i + 1] - grid[i]),
            }
        }
    }
}

/// [`schedule`] with the model's extension: beyond the grid ends (and
/// within the extension, the speed clamped to it) D̄ extrapolated linearly
/// from the two end points, the load quadratically through the three end
/// points.
pub(crate) fn blend(
    grid: &[f64],
    extension: Option<Extension>,
    speed: f64,
    scheduling: Scheduling,
) -> Blend {
    let n = grid.len();
    let plain = || Blend::of(schedule(grid, speed, scheduling));
    let Some(ext) = extension else {
        return plain();
    };
    if n < 3 || scheduling != Scheduling::Interpolate || !speed.is_finite() {
        return plain();
    }
    let (ends, s) = if speed < grid[0] && ext.from_mps < grid[0] {
        ([0, 1, 2], speed.max(ext.from_mps))
    } else if speed > grid[n - 1] && ext.to_mps > grid[n - 1] {
        ([n - 1, n - 2, n - 3], speed.min(ext.to_mps))
    } else {
        return plain();
    };
    let [a, b, _] = ends;
    let w = (grid[b] - s) / (grid[b] - grid[a]);
    let lagrange = |j: usize| {
        ends.iter()
            .filter(|&&k| k != ends[j])
            .map(|&k| (s - grid[k]) / (grid[ends[j]] - grid[k]))
            .product::<f64>()
    };
    Blend {
        dynamics: [(a, w), (b, 1.0 - w)],
        load: [
            (ends[0], lagrange(0)),
            (ends[1], lagrange(1)),
            (ends[2], lagrange(2)),
        ],
        extrapolated: true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const GRID: [f64; 4] = [0.5, 1.0, 1.5, 2.0];

    fn ext() -> Option<Extension> {
        Some(Extension {
            from_mps: 0.25,
            to_mps: 2.5,
        })
    }

    /// Σ weights · f(grid) for the dynamics and the load.
    fn apply(b: &Blend, f: impl Fn(f64) -> f64) -> (f64, f64) {
        let dyn_: f64 = b.dynamics.iter().map(|&(i, w)| w * f(GRID[i])).sum();
        let load: f64 = b.load.iter().map(|&(i, w)| w * f(GRID[i])).sum();
        (dyn_, load)
    }

    #[test]
    fn extrapolation_is_exact_for_affine_damping_and_quadratic_load() {
        // Tangent of d·u|u| + c at u₀: D̄ = 2d u₀ (affine), b = c − d u₀².
        let (d, c) = (300.0, 40.0);
        for speed in [0.3, 0.25, 2.2, 2.5] {
            let bl = blend(&GRID, ext(), speed, Scheduling::Interpolate);
            assert!(bl.extrapolated);
            let (d_bar, _) = apply(&bl, |x| 2.0 * d * x);
            let (_, load) = apply(&bl, |x| c - d * x * x);
            assert!((d_bar - 2.0 * d * speed).abs() < 1e-9, "{speed}: {d_bar}");
            assert!(
                (load - (c - d * speed * speed)).abs() < 1e-9,
                "{speed}: {load}"
            );
            let sum: f64 = bl.load.iter().map(|l| l.1).sum();
            assert!((sum - 1.0).abs() < 1e-12);
        }
        // Beyond the extension: the model at its edge.
        let edge = blend(&GRID, ext(), 0.25, Scheduling::Interpolate);
        assert_eq!(blend(&GRID, ext(), 0.0, Scheduling::Interpolate), edge);
        let top = blend(&GRID, ext(), 2.5, Scheduling::Interpolate);
        assert_eq!(blend(&GRID, ext(), 3.7, Scheduling::Interpolate), top);
    }

    #[test]
    fn inside_the_grid_and_without_an_extension_it_is_the_thesis_blend() {
        for speed in [0.1, 0.5, 0.8, 1.25, 2.0, 2.4] {
            let plain = Blend::of(schedule(&GRID, speed, Scheduling::Interpolate));
            assert_eq!(blend(&GRID, None, speed, Scheduling::Interpolate), plain);
            if (0.5..=2.0).contains(&speed) {
                assert_eq!(blend(&GRID, ext(), speed, Scheduling::Interpolate), plain);
            }
        }
        // Nearest scheduling and short grids do not extrapolate.
        let near = blend(&GRID, ext(), 0.3, Scheduling::Nearest);
        assert!(!near.extrapolated);
        assert!(!blend(&GRID[..2], ext(), 0.3, Scheduling::Interpolate).extrapolated);
        // Continuous at the grid ends.
        let just_below = blend(&GRID, ext(), 0.5 - 1e-12, Scheduling::Interpolate);
        let (d0, l0) = apply(&just_below, |x| x * x * x + 1.0);
        assert!((d0 - 1.125).abs() < 1e-9 && (l0 - 1.125).abs() < 1e-9);
    }
}
