//! The information a set of runs gives the λ-filter identification, per
//! grid point, before any of them is flown at sea: the same data path as
//! [`super::identify_lambda_campaign`] (estimation runs and static runs at
//! a grid speed, γ = τ, constant loads and g(η)'s shapes as exogenous
//! functions for a 6-DOF vehicle), ending in the regression's Gram matrix
//! Σφφᵀ instead of an estimate.

use nalgebra::DMatrix;

use super::dataset::RunInput;
use super::error::IdentifyError;
use super::joint_restoring::Functions;
use super::lambda_data::{experiment, per_point, regression_columns};
use super::lambda_structure::symmetric_pattern;
use super::roles::Roles;
use crate::estimation::lambda::{CouplingMask, MIN_T_OVER_H, regression_information};
use crate::planning::campaign::ExperimentFamily;
use crate::planning::dof::Dof;
use crate::planning::vessel::VesselProfile;

/// The λ regression's information at one grid point.
#[derive(Debug, Clone, PartialEq)]
pub struct PointInformation {
    /// Index of the grid point.
    pub grid_index: usize,
    /// Σφφᵀ over the runs' segments there (p × p, φ = [λν, λγ, λe]).
    pub gram: DMatrix<f64>,
    /// Samples it holds.
    pub samples: usize,
}

/// The regressors of each output row under the port–starboard structure
/// the identification assumes by default (its own ν and γ couplings within
/// the longitudinal or lateral subsystem, then every exogenous function):
/// indices into φ of `n` DOFs and `q` exogenous functions.
pub fn symmetric_rows(dofs: &[Dof], q: usize) -> Vec<Vec<usize>> {
    let n = dofs.len();
    let mask = CouplingMask::from_pattern(&symmetric_pattern(dofs));
    (0..n)
        .map(|i| {
            let mut free = mask.free_of_row(i);
            free.extend(2 * n..2 * n + q);
            free
        })
        .collect()
}

/// The λ filter's time constant the identification uses by default: half
/// the vessel's fastest time constant, at least [`MIN_T_OVER_H`] samples.
pub fn default_t_lambda(profile: &VesselProfile, h: f64) -> f64 {
    let t_min = profile
        .dofs
        .iter()
        .map(|d| profile.limit(*d).time_constant_s)
        .fold(f64::INFINITY, f64::min);
    (0.5 * t_min).max(MIN_T_OVER_H * h)
}

/// The number of exogenous functions the identification regresses on for
/// `profile`: [1, sin θ, cos θ sin φ] for a 6-DOF vehicle, [1] otherwise.
pub fn exogenous_count(profile: &VesselProfile) -> usize {
    if profile.dofs.len() == 6 { 3 } else { 1 }
}

/// Information per grid point of `grid` (m/s) from `runs`; validation runs
/// are left out (the identification holds them out). Grid points without
/// data are absent.
///
/// # Errors
/// A run whose columns or samples cannot be used, named by run.
pub fn lambda_information(
    profile: &VesselProfile,
    grid: &[f64],
    inputs: &[String],
    runs: &[RunInput],
) -> Result<Vec<PointInformation>, IdentifyError> {
    let dofs = profile.dofs.clone();
    let n = dofs.len();
    if inputs.len() != n {
        return Err(IdentifyError::invalid(
            "inputs",
            format!("{} input columns for {n} DOFs", inputs.len()),
        ));
    }
    let mut roles = Roles::default();
    for r in runs {
        match r.family {
            Some(ExperimentFamily::Validation) => roles.validation.push(r),
            Some(ExperimentFamily::Static) => roles.statics.push(r),
            _ => roles.estimation.push(r),
        }
    }
    let six_dof = n == 6;
    let cols = regression_columns(inputs, six_dof);
    let functions = if six_dof {
        Functions::ConstantAndRestoring
    } else {
        Functions::Constant
    };
    let outputs: Vec<String> = Dof::velocity_symbols(&dofs);
    let mut notes = Vec::new();
    let data = per_point(&roles, grid, &dofs, &cols, &outputs, &mut notes)?;
    let mut out = Vec::new();
    for (grid_index, segs) in data.segments.iter().enumerate() {
        if segs.is_empty() {
            continue;
        }
        let exps = segs
            .iter()
            .map(|s| experiment(s, n, None, Some(functions)))
            .collect::<Result<Vec<_>, _>>()?;
        let t_lambda = default_t_lambda(profile, exps[0].h);
        let (gram, samples) = regression_information(&exps, t_lambda)
            .map_err(|e| IdentifyError::invalid(e.field(), e.to_string()))?;
        out.push(PointInformation {
            grid_index,
            gram,
            samples,
        });
    }
    Ok(out)
}
