//! The campaign's runs cut into discovery records: valid blocks split at
//! grid-point changes of the smoothed forward speed, slow enough for the
//! state-variable filter, long enough for its transient and the k-step
//! horizon.

use super::super::augmented::pieces_by_speed;
use super::super::dataset::{RunInput, level_attitude, segments};
use super::super::error::IdentifyError;
use super::super::roles::nearest_grid_index;
use crate::discrepancy::{DiscoverySettings, Record};
use crate::estimation::lambda::MIN_T_OVER_H;
use crate::logs::schema::pose_column;
use crate::numbers::sig3;
use crate::planning::dof::Dof;

/// The valid blocks of a run as discovery records (τ in DOF order, ν, η),
/// each with the grid point it belongs to. A run without a planned grid
/// speed (the plan's validation runs step through the whole grid) is cut
/// where its forward speed, smoothed over 10 s, moves to another grid
/// point: discovery compares each sub-model with the part of the run it
/// predicts.
pub(super) fn records(
    run: &RunInput,
    dofs: &[Dof],
    forces: &[String],
    grid: &[f64],
    min_len: usize,
) -> Result<Vec<(Record, usize)>, IdentifyError> {
    let n = dofs.len();
    let run = level_attitude(run, dofs);
    let run = &*run;
    let cols: Vec<String> = forces
        .iter()
        .cloned()
        .chain(Dof::ALL.iter().map(|d| pose_column(*d).to_string()))
        .collect();
    let outputs: Vec<String> = Dof::velocity_symbols(dofs);
    let segs = segments(run, &cols, &outputs, min_len)
        .map_err(|e| IdentifyError::invalid(format!("runs[{}]", e.run_id), e.to_string()))?;
    let surge = dofs.iter().position(|d| *d == Dof::Surge);
    let mut out = Vec::new();
    for (b, s) in segs.into_iter().enumerate() {
        let rec = Record {
            name: run.name.clone(),
            h: s.h,
            tau: s.u.columns(0, n).into_owned(),
            nu: s.y,
            eta: s.u.columns(n, 6).into_owned(),
        };
        let block = if b > 0 {
            format!(" #{}", b + 1)
        } else {
            String::new()
        };
        let pieces: Vec<(usize, usize, usize)> = match (run.grid_speed_mps, surge) {
            (Some(v), _) => vec![(0, rec.len(), nearest_grid_index(grid, v))],
            (None, None) => vec![(0, rec.len(), 0)],
            (None, Some(j)) => pieces_by_speed(rec.nu.column(j).as_slice(), rec.h, grid),
        };
        let whole = pieces.len() == 1;
        for (start, end, i) in pieces {
            if end - start < min_len {
                continue;
            }
            let name = if whole {
                format!("{}{block}", run.name)
            } else {
                format!(
                    "{}{block} @ {:.2} m/s ({:.0}–{:.0} s)",
                    run.name,
                    grid[i],
                    start as f64 * rec.h,
                    end as f64 * rec.h
                )
            };
            out.push((rec.slice(start, end, name), i));
        }
    }
    Ok(out)
}

/// The state-variable filter must span [`MIN_T_OVER_H`] samples of the
/// slowest log, as the λ identification's does: a DP vessel logged at 1 Hz
/// gets T ≥ 5 s (a 10 Hz ROV log keeps the default 0.5 s). Raises `s`'s T
/// when shorter and says so.
pub(super) fn slow_enough_filter(s: &mut DiscoverySettings, runs: &[RunInput]) -> Option<String> {
    let h = runs
        .iter()
        .map(|r| 1.0 / r.record.sample_rate_hz)
        .filter(|h| h.is_finite())
        .fold(0.0, f64::max);
    let floor = MIN_T_OVER_H * h;
    (s.svf_time_constant_s < floor).then(|| {
        let note = format!(
            "The state-variable filter's time constant was raised from {} s to {} s: it must span {MIN_T_OVER_H} samples of the slowest log ({} Hz).",
            sig3(s.svf_time_constant_s),
            sig3(floor),
            sig3(1.0 / h)
        );
        s.svf_time_constant_s = floor;
        note
    })
}

/// The shortest record discovery accepts: the filter transient and the
/// k-step horizon (as `discover` checks), plus room to fit.
pub(super) fn min_record_len(s: &DiscoverySettings, h: f64) -> usize {
    let skip = ((5.0 * s.svf_time_constant_s / h).ceil() as usize)
        .max((s.max_delay_s / h).ceil() as usize + 1)
        .max(s.k_step);
    skip + s.k_step + 64
}
