//! The data of a λ-filter campaign identification: every estimation run's
//! segments at its grid point (static runs flown at a grid speed among
//! them: steady flight is data at that operating point), the dedicated
//! station-keeping attitude holds for g(η) (thesis eq. 2.1–2.4), and the
//! runs as [`Experiment`]s with γ = τ − g(η) and the exogenous functions.

use nalgebra::DMatrix;

use super::dataset::{RunInput, Segment, segments};
use super::error::IdentifyError;
use super::joint_restoring::{Functions, functions_of};
use super::roles::{Roles, nearest_grid_index};
use crate::estimation::lambda::Experiment;
use crate::estimation::restoring::{
    RestoringEstimate, RestoringParams, RestoringSettings, StaticRecord, estimate_restoring,
};
use crate::logs::schema::pose_column;
use crate::planning::dof::Dof;

/// The columns a segment carries: τ, then η when g(η) is part of the model.
pub(crate) fn regression_columns(inputs: &[String], with_attitude: bool) -> Vec<String> {
    let mut cols = inputs.to_vec();
    if with_attitude {
        cols.extend(Dof::ALL.iter().map(|d| pose_column(*d).to_string()));
    }
    cols
}

/// A static run whose mean forward speed is below this (m/s) is a
/// station-keeping attitude hold; above, steady flight at a grid speed.
const HOLD_SPEED: f64 = 0.1;

/// Segments per grid point and the runs they came from.
pub(crate) struct PointData {
    pub segments: Vec<Vec<Segment>>,
    pub run_ids: Vec<Vec<String>>,
}

impl PointData {
    /// The runs behind any grid point, each once, in grid order.
    pub fn distinct_run_ids(&self) -> Vec<String> {
        let mut ids: Vec<String> = Vec::new();
        for id in self.run_ids.iter().flatten() {
            if !ids.contains(id) {
                ids.push(id.clone());
            }
        }
        ids
    }
}

fn segs(
    run: &RunInput,
    cols: &[String],
    outputs: &[String],
    min: usize,
) -> Result<Vec<Segment>, IdentifyError> {
    segments(run, cols, outputs, min)
        .map_err(|e| IdentifyError::invalid(format!("runs[{}]", e.run_id), e.to_string()))
}

/// Half the smallest spacing of the grid (0.25 m/s for a single point): how
/// far a static run's mean speed may lie from a grid point to count there.
fn tolerance(grid: &[f64]) -> f64 {
    let mut s: Vec<f64> = grid.to_vec();
    s.sort_by(f64::total_cmp);
    s.windows(2)
        .map(|w| 0.5 * (w[1] - w[0]))
        .filter(|d| *d > 0.0)
        .fold(0.25, f64::min)
}

/// Each estimation run (and each static run flown at a grid speed) at the
/// grid point of its grid speed, or the one nearest its mean forward speed.
pub(crate) fn per_point(
    roles: &Roles<'_>,
    grid: &[f64],
    dofs: &[Dof],
    cols: &[String],
    outputs: &[String],
    notes: &mut Vec<String>,
) -> Result<PointData, IdentifyError> {
    let surge = dofs.iter().position(|d| *d == Dof::Surge);
    let mut data = PointData {
        segments: vec![Vec::new(); grid.len()],
        run_ids: vec![Vec::new(); grid.len()],
    };
    let mean_u = |s: &Segment| surge.map(|j| s.y.column(j).mean());
    let mut add = |r: &RunInput, s: Segment, i: usize| {
        if !data.run_ids[i].contains(&r.run_id) {
            data.run_ids[i].push(r.run_id.clone());
        }
        data.segments[i].push(s);
    };
    for r in &roles.estimation {
        for s in segs(r, cols, outputs, 50)? {
            let speed = r.grid_speed_mps.or(mean_u(&s)).unwrap_or(grid[0]);
            add(r, s, nearest_grid_index(grid, speed));
        }
    }
    let tol = tolerance(grid);
    let mut at_speed = 0;
    for r in &roles.statics {
        for s in segs(r, cols, outputs, 50)? {
            let Some(u) = mean_u(&s) else { continue };
            let i = nearest_grid_index(grid, r.grid_speed_mps.unwrap_or(u));
            if u.abs() > HOLD_SPEED && (u - grid[i]).abs() <= tol {
                add(r, s, i);
                at_speed += 1;
            }
        }
    }
    if at_speed > 0 {
        notes.push(format!(
            "{at_speed} segments of static runs flown at a grid speed are estimation data at that speed"
        ));
    }
    Ok(data)
}

/// g(η) from station-keeping attitude holds among the static runs (thesis
/// eq. 2.1–2.4), when there are any: `None` (with a note) otherwise.
pub(crate) fn static_holds(
    roles: &Roles<'_>,
    dofs: &[Dof],
    cols: &[String],
    outputs: &[String],
    notes: &mut Vec<String>,
) -> Result<Option<RestoringEstimate>, IdentifyError> {
    let Some(surge) = dofs.iter().position(|d| *d == Dof::Surge) else {
        return Ok(None);
    };
    let mut holds = Vec::new();
    for r in &roles.statics {
        for s in segs(r, cols, outputs, 20)? {
            if s.y.column(surge).mean().abs() <= HOLD_SPEED {
                holds.push(s);
            }
        }
    }
    if holds.is_empty() {
        return Ok(None);
    }
    let taus: Vec<DMatrix<f64>> = holds
        .iter()
        .map(|s| s.u.columns(0, 6).into_owned())
        .collect();
    let etas: Vec<DMatrix<f64>> = holds
        .iter()
        .map(|s| s.u.columns(6, 6).into_owned())
        .collect();
    let records: Vec<StaticRecord<'_>> = holds
        .iter()
        .zip(taus.iter().zip(&etas))
        .map(|(s, (tau, eta))| StaticRecord {
            h: s.h,
            nu: &s.y,
            eta,
            tau,
        })
        .collect();
    match estimate_restoring(&records, &RestoringSettings::default()) {
        Ok(est) => Ok(Some(est)),
        Err(e) => {
            notes.push(format!(
                "the station-keeping holds among the static runs did not determine g(η) on their own ({e}); it comes from the dynamic runs"
            ));
            Ok(None)
        }
    }
}

/// How a segment becomes an [`Experiment`]: γ = τ − g(η) with `restoring`
/// (τ without), and the exogenous functions `functions` of η (none when
/// `None`). Segments hold τ (n columns) and, when η is needed, η after it.
pub(crate) fn experiment(
    seg: &Segment,
    n: usize,
    restoring: Option<&RestoringParams>,
    functions: Option<Functions>,
) -> Result<Experiment, IdentifyError> {
    let tau = seg.u.columns(0, n).into_owned();
    let with_eta = seg.u.ncols() >= n + 6;
    let eta = with_eta.then(|| seg.u.columns(n, 6).into_owned());
    let gamma = match (restoring, &eta) {
        (Some(r), Some(eta)) => r
            .gamma(&tau, eta)
            .map_err(|e| IdentifyError::invalid(format!("runs[{}]", seg.run_id), e.to_string()))?,
        _ => tau,
    };
    let rows = seg.y.nrows();
    let exogenous = match (functions, &eta) {
        (None, _) => DMatrix::zeros(rows, 0),
        (Some(f), Some(eta)) => functions_of(eta, f),
        (Some(_), None) => DMatrix::from_element(rows, 1, 1.0),
    };
    Ok(Experiment {
        h: seg.h,
        nu: seg.y.clone(),
        gamma,
        exogenous,
    })
}
