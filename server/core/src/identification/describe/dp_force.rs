//! The DP manoeuvre of a run of a vessel outside the paper's six-thruster
//! layout (any thruster set, or logged forces τ), from which inputs move:
//! surge inputs alone are SI1, lateral inputs alone SI2, both together the
//! validation run (Fossen et al. 1995, sec. 4.2).

use super::mean_std;
use crate::identification::description::{RunRole, dof_words};
use crate::planning::Dof;
use crate::planning::campaign::ExperimentFamily;
use crate::planning::vessel::{InputChannels, VesselProfile};
use crate::timeseries::UniformRecord;

/// Share of a column's force in surge above which it counts as a surge
/// input (a main, an azimuth near the bow direction, τ_X).
const SURGE_COLUMN: f64 = 0.5;
/// A column moves when its force's std is at least this share of the
/// largest column's.
const MOVING_COLUMN: f64 = 0.1;

/// What the commanded force of a DP run does: the share of each DOF
/// (surge, sway, yaw) in its variance (T″·u of a thruster vessel in Bis, τ
/// over the DOF's force limit of one that logs forces), and whether surge
/// inputs and lateral inputs move; None without a moving command.
fn force_shares(rec: &UniformRecord, profile: &VesselProfile) -> Option<([f64; 3], bool, bool)> {
    let cols = crate::logs::commanded_columns(profile);
    // Each column's T and its thruster (a turning azimuth's two components
    // are judged together).
    let (t, owner): (Vec<[f64; 3]>, Vec<usize>) = match &profile.inputs {
        InputChannels::Thrusters { .. } => crate::logs::commanded_inputs(profile)
            .iter()
            .map(|c| (std::array::from_fn(|i| c.t[i]), c.thruster))
            .collect(),
        InputChannels::GeneralizedForces => Dof::HORIZONTAL
            .iter()
            .enumerate()
            .map(|(i, &d)| {
                let mut c = [0.0; 3];
                c[i] = 1.0 / profile.limit(d).max_force;
                (c, i)
            })
            .collect(),
    };
    let data: Vec<&[f64]> = cols.iter().filter_map(|c| rec.column(c)).collect();
    if data.len() != t.len() || data.is_empty() {
        return None;
    }
    let n = data[0].len();
    let (mut sum, mut sq, mut count) = ([0.0f64; 3], [0.0f64; 3], 0usize);
    for k in 0..n {
        let mut f = [0.0; 3];
        for (col, tj) in data.iter().zip(&t) {
            for i in 0..3 {
                f[i] += tj[i] * col[k];
            }
        }
        if f.iter().all(|v| v.is_finite()) {
            count += 1;
            for i in 0..3 {
                sum[i] += f[i];
                sq[i] += f[i] * f[i];
            }
        }
    }
    if count < 2 {
        return None;
    }
    let var: [f64; 3] =
        std::array::from_fn(|i| (sq[i] / count as f64 - (sum[i] / count as f64).powi(2)).max(0.0));
    let total: f64 = var.iter().sum();
    if total <= 0.0 {
        return None;
    }
    // Each thruster's force std (over its columns), and whether it pushes
    // mostly in surge: one column pushes along its T column, a turning
    // azimuth mostly along the component that moves more.
    let norm = |tj: &[f64; 3]| tj.iter().map(|v| v * v).sum::<f64>().sqrt();
    let n_owners = owner.iter().max().map_or(0, |m| m + 1);
    let (mut level_sq, mut surge_sq) = (vec![0.0; n_owners], vec![0.0; n_owners]);
    for ((col, tj), &o) in data.iter().zip(&t).zip(&owner) {
        let s = mean_std(rec, col).1;
        level_sq[o] += (s * norm(tj)).powi(2);
        surge_sq[o] += (s * tj[0]).powi(2);
    }
    let levels: Vec<f64> = level_sq.iter().map(|v| v.sqrt()).collect();
    let top = levels.iter().copied().fold(0.0, f64::max);
    let moving = |surge: bool| {
        levels.iter().zip(&surge_sq).any(|(&l, &sx)| {
            l > 0.0 && l >= MOVING_COLUMN * top && (sx.sqrt() >= SURGE_COLUMN * l) == surge
        })
    };
    Some((var.map(|v| v / total), moving(true), moving(false)))
}

/// The DP manoeuvre of a run of a vessel that is not the paper's layout,
/// by which inputs move: surge inputs alone (SI1), lateral inputs alone
/// (SI2), or both (validation).
pub(super) fn dp_role_by_force(
    rec: &UniformRecord,
    profile: &VesselProfile,
    names: &[Dof],
) -> (RunRole, ExperimentFamily, String) {
    let Some((share, surge, lateral)) = force_shares(rec, profile) else {
        return (
            RunRole::Dynamic,
            ExperimentFamily::Dynamic,
            format!(
                "{} excited, but no commanded force moves clearly: the DP manoeuvre is unknown",
                dof_words(names)
            ),
        );
    };
    let pct = |v: f64| format!("{:.0} %", 100.0 * v);
    let split = format!(
        "surge {}, sway–yaw {} of the commanded force's variance",
        pct(share[0]),
        pct(share[1] + share[2])
    );
    match (surge, lateral) {
        (true, false) => (
            RunRole::Dynamic,
            ExperimentFamily::DpSurge,
            format!("only surge inputs move ({split}): manoeuvre SI1 (dp_surge)"),
        ),
        (false, true) => (
            RunRole::Dynamic,
            ExperimentFamily::DpSwayYaw,
            format!("only lateral inputs move ({split}): manoeuvre SI2 (dp_sway_yaw)"),
        ),
        _ => (
            RunRole::Validation,
            ExperimentFamily::Validation,
            format!("surge and lateral inputs move together ({split}): the DP validation run"),
        ),
    }
}
