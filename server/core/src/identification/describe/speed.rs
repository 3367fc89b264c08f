//! The forward speed of a run: the grid point nearest its mean, and whether
//! it wanders across the grid (the validation run steps through it).

use super::{blocks, mean_std};
use crate::identification::description::speed_words;
use crate::identification::roles::nearest_grid_index;
use crate::planning::vessel::VesselProfile;
use crate::planning::{Dof, KNOT};
use crate::timeseries::UniformRecord;

/// Moving-average window of the forward speed, in surge time constants
/// (≥ 30 s): long enough to average out a dynamic surge excitation (a square
/// wave of period 10·T), short enough to see the validation run's steps.
pub const SPEED_WINDOW_TIME_CONSTANTS: f64 = 10.0;

/// Smallest share of the run the smoothed speed must spend in a second grid
/// bin for the speed to count as wandering across the grid.
pub const MIN_BIN_SHARE: f64 = 0.15;

/// Spacing assumed about a one-point grid (m/s), to call a mean speed off
/// the grid: the thesis's grid spacing 0.5 kn.
const SINGLE_POINT_SPACING_MPS: f64 = 0.5 * KNOT;

/// Forward speed: mean, and the shares of the run the smoothed speed spends
/// in each grid bin (grid index → share), largest first.
fn speed_bins(
    rec: &UniformRecord,
    u: &[f64],
    grid: &[f64],
    window_s: f64,
) -> (f64, Vec<(usize, f64)>) {
    let (mean, _) = mean_std(rec, u);
    let w = ((window_s * rec.sample_rate_hz).round() as usize).max(1);
    let mut counts = std::collections::BTreeMap::<usize, usize>::new();
    let mut total = 0usize;
    for b in blocks(rec, u) {
        let half = w.min(b.len()) / 2;
        let mut prefix = vec![0.0; b.len() + 1];
        for (k, x) in b.iter().enumerate() {
            prefix[k + 1] = prefix[k] + x;
        }
        for k in 0..b.len() {
            let lo = k.saturating_sub(half);
            let hi = (k + half + 1).min(b.len());
            let avg = (prefix[hi] - prefix[lo]) / (hi - lo) as f64;
            *counts.entry(nearest_grid_index(grid, avg)).or_default() += 1;
            total += 1;
        }
    }
    let mut shares: Vec<(usize, f64)> = counts
        .into_iter()
        .map(|(i, c)| (i, c as f64 / total.max(1) as f64))
        .collect();
    shares.sort_by(|a, b| b.1.total_cmp(&a.1));
    (mean, shares)
}

/// What the speed says: (grid speed, its reason, mean, wandering reason).
pub(super) fn grid_speed(
    rec: &UniformRecord,
    profile: &VesselProfile,
    grid: &[f64],
) -> (Option<f64>, String, Option<f64>, Option<String>) {
    let Some(u) = rec.column(Dof::Surge.velocity_symbol()) else {
        return (None, "the log has no forward speed u".into(), None, None);
    };
    if grid.is_empty() {
        let (m, _) = mean_std(rec, u);
        return (
            None,
            "the campaign has no grid speeds".into(),
            Some(m),
            None,
        );
    }
    let window =
        (SPEED_WINDOW_TIME_CONSTANTS * profile.limit(Dof::Surge).time_constant_s).max(30.0);
    // With one grid point (a DP campaign at rest) there is no grid to move
    // across: a surge manoeuvre's speed changes are its excitation.
    let (mean, shares) = speed_bins(rec, u, grid, window);
    let visited: Vec<&(usize, f64)> = shares.iter().filter(|s| s.1 >= MIN_BIN_SHARE).collect();
    if visited.len() >= 2 {
        let mut v: Vec<&(usize, f64)> = visited.clone();
        v.sort_by_key(|s| s.0);
        let list = v
            .iter()
            .map(|(i, s)| format!("{:.2} kn ({:.0} %)", grid[*i] / KNOT, 100.0 * s))
            .collect::<Vec<_>>()
            .join(", ");
        let why = format!(
            "the forward speed ({window:.0} s moving average) moves across the grid: near {list} of the run"
        );
        return (
            None,
            format!("{why}; no single grid speed (mean {})", speed_words(mean)),
            Some(mean),
            Some(why),
        );
    }
    let i = nearest_grid_index(grid, mean);
    let g = grid[i];
    let spacing = if grid.len() > 1 {
        grid.windows(2)
            .map(|w| (w[1] - w[0]).abs())
            .fold(f64::INFINITY, f64::min)
    } else {
        SINGLE_POINT_SPACING_MPS
    };
    let off = mean - g;
    let mut reason = format!(
        "mean forward speed {} is {:.3} m/s {} the grid point {}",
        speed_words(mean),
        off.abs(),
        if off >= 0.0 { "above" } else { "below" },
        speed_words(g)
    );
    if off.abs() > 0.5 * spacing {
        reason.push_str(" — outside the grid: check the campaign's grid");
    }
    (Some(g), reason, Some(mean), None)
}
