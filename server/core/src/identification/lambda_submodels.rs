//! The λ identification's sub-models made physical and assembled into the
//! LPV model on forward speed: M, D̄ and b per grid point with their
//! parameter rows, the pooled M of C(δ)δ, D_q, and the extension beyond
//! the grid.

use nalgebra::{DVector, Vector2};

use super::document::{LoggedController, LpvPoint, ParameterRow, to_rows};
use super::error::IdentifyError;
use super::intersample::logged_equivalent;
use super::joint_restoring::load;
use super::lambda_coriolis::pooled_inertia;
use super::lambda_extension::{Sides, choose_extension};
use super::lambda_physical::{enforce, unresolved_mode};
use super::lambda_quadratic;
use super::ned_current;
use crate::estimation::lambda::{Experiment, LambdaEstimate};
use crate::estimation::restoring::RestoringParams;
use crate::models::{Extension, LinearVesselModel, LpvModel, Scheduling};
use crate::planning::dof::Dof;

/// Unit of an entry (i, j) of M (`per_s` false) or D̄ (true).
fn unit(dofs: &[Dof], i: usize, j: usize, per_s: bool) -> String {
    let base = match (dofs[i].is_angular(), dofs[j].is_angular()) {
        (false, false) => "kg",
        (true, true) => "kg·m²",
        _ => "kg·m",
    };
    if per_s {
        format!("{base}/s")
    } else {
        base.to_string()
    }
}

/// Unit of a force (N) or moment (N·m) in DOF `d`.
fn force_unit(d: Dof) -> &'static str {
    if d.is_angular() { "N·m" } else { "N" }
}

/// The constant load b and its std of an estimate (zero without loads).
fn joint_load(est: &LambdaEstimate, n: usize) -> (DVector<f64>, DVector<f64>) {
    load(est).unwrap_or_else(|| (DVector::zeros(n), DVector::zeros(n)))
}

/// What the sub-models are fitted on, per grid point of `grid`.
pub(crate) struct SubModelInputs<'a> {
    pub dofs: &'a [Dof],
    pub grid: &'a [f64],
    /// The experiments each sub-model was fitted on (index of `grid`).
    pub exps: &'a [Vec<Experiment>],
    /// The runs behind each grid point.
    pub run_ids: &'a [Vec<String>],
    /// With C(ν) of M in the sub-models.
    pub coriolis_from_m: bool,
    /// With a constant load b per sub-model.
    pub constant_loads: bool,
}

/// The physical sub-models of a campaign.
pub(crate) struct SubModels {
    /// As they predict the logs (the logged controller's commands added
    /// back when it ran faster than the log).
    pub for_logs: Vec<LinearVesselModel>,
    /// The vehicle's own M, D̄, b.
    pub vehicle: Vec<LinearVesselModel>,
    pub points: Vec<LpvPoint>,
    pub parameters: Vec<ParameterRow>,
    pub findings: Vec<String>,
}

/// Each estimate projected onto the physical set (M symmetric positive
/// definite, D̄ dissipative), with its parameter rows and document point;
/// with a known current V = [V_N, V_E] each point's force shapes F of its
/// own D̄ (D̄ ν_c = −F e(ψ), [`ned_current::force`]), so that a loop driving
/// the model in ground velocities gives the D̄ ν_r it was fitted on.
pub(crate) fn sub_models(
    at: &SubModelInputs,
    estimates: &[(f64, LambdaEstimate)],
    current: Option<&Vector2<f64>>,
    logged_controller: Option<&LoggedController>,
) -> Result<SubModels, IdentifyError> {
    let dofs = at.dofs;
    let n = dofs.len();
    let mut out = SubModels {
        for_logs: Vec::new(),
        vehicle: Vec::new(),
        points: Vec::new(),
        parameters: Vec::new(),
        findings: Vec::new(),
    };
    for (speed, est) in estimates {
        let idx = at.grid.iter().position(|g| g == speed).unwrap_or(0);
        let (load, load_std) = joint_load(est, n);
        let physical = enforce(dofs, est, &load, &at.exps[idx], *speed, at.coriolis_from_m)?;
        out.findings.extend(physical.findings);
        let model = physical.model;
        out.findings
            .extend(unresolved_mode(dofs, model.a(), est.h, *speed));
        for i in 0..n {
            for j in 0..n {
                for (group, value, std, per_s) in [
                    ("M", model.m()[(i, j)], est.std_m[(i, j)], false),
                    ("D̄", model.d_bar()[(i, j)], est.std_d_bar[(i, j)], true),
                ] {
                    if value != 0.0 || std > 0.0 {
                        out.parameters.push(ParameterRow {
                            group: group.into(),
                            symbol: format!("{group}[{},{}]", dofs[i].name(), dofs[j].name()),
                            grid_speed_mps: Some(*speed),
                            value,
                            std: Some(std),
                            unit: unit(dofs, i, j, per_s),
                        });
                    }
                }
            }
            if at.constant_loads {
                out.parameters.push(ParameterRow {
                    group: "b".into(),
                    symbol: format!("b[{}]", dofs[i].name()),
                    grid_speed_mps: Some(*speed),
                    value: load[i],
                    std: Some(load_std[i]),
                    unit: force_unit(dofs[i]).into(),
                });
            }
        }
        out.points.push(LpvPoint {
            speed_mps: *speed,
            m: to_rows(model.m()),
            m_std: to_rows(&est.std_m),
            d_bar: to_rows(model.d_bar()),
            d_bar_std: to_rows(&est.std_d_bar),
            a: to_rows(model.a()),
            a_std: to_rows(&est.std_a),
            b: to_rows(model.b()),
            b_std: to_rows(&est.std_b),
            load: at.constant_loads.then(|| load.iter().copied().collect()),
            load_std: at
                .constant_loads
                .then(|| load_std.iter().copied().collect()),
            n_samples: est.n_samples,
            run_ids: at.run_ids[idx].clone(),
            current_force: current.map(|v| to_rows(&ned_current::force(model.d_bar(), dofs, v))),
            augmentation: None,
        });
        out.vehicle.push(model.clone());
        let for_logs = match logged_controller {
            Some(lc) => logged_equivalent(model.m(), model.d_bar(), lc, dofs)
                .and_then(|(m, d)| {
                    LinearVesselModel::new(dofs.to_vec(), m, d)
                        .and_then(|x| x.with_load(model.load().clone()))
                        .ok()
                })
                .unwrap_or(model),
            None => model,
        };
        out.for_logs.push(for_logs);
    }
    Ok(out)
}

/// How the sub-models are joined over speed.
pub(crate) struct Assembly<'a> {
    pub scheduling: Scheduling,
    /// C(δ)δ of the pooled vehicle M.
    pub second_order: bool,
    /// D_q and its std, shared by every grid speed.
    pub quadratic: Option<&'a (DVector<f64>, DVector<f64>)>,
    pub coriolis_from_m: bool,
    pub restoring: Option<&'a RestoringParams>,
    /// Extend below / above the grid as far as the vehicle stays physical.
    pub sides: Sides,
}

fn model_error(e: impl std::fmt::Display) -> IdentifyError {
    IdentifyError::invalid("model", e.to_string())
}

/// The LPV model of the sub-models at the speeds of `estimates`, with the
/// extension beyond the grid chosen (and its note); D_q's parameter rows
/// are appended to `parameters`.
pub(crate) fn assemble(
    dofs: &[Dof],
    subs: &SubModels,
    estimates: &[(f64, LambdaEstimate)],
    how: &Assembly,
    parameters: &mut Vec<ParameterRow>,
) -> Result<(LpvModel, Option<(Extension, String)>), IdentifyError> {
    let speeds: Vec<f64> = estimates.iter().map(|(s, _)| *s).collect();
    let vehicle_m: Vec<_> = subs.vehicle.iter().map(|v| v.m().clone()).collect();
    let m_std: Vec<_> = estimates.iter().map(|(_, e)| e.std_m.clone()).collect();
    let vehicle_m = match pooled_inertia(&vehicle_m, &m_std) {
        Some(m) => vec![m; vehicle_m.len()],
        None => vehicle_m,
    };
    let mut lpv = LpvModel::new(speeds.clone(), subs.for_logs.clone())
        .map_err(model_error)?
        .with_scheduling(how.scheduling);
    if how.second_order {
        lpv = lpv
            .with_second_order_coriolis(vehicle_m)
            .map_err(model_error)?;
    }
    if let Some((d_q, std)) = how.quadratic {
        lpv = lpv
            .with_quadratic_damping(vec![d_q.clone(); speeds.len()])
            .map_err(model_error)?;
        for i in (0..dofs.len()).filter(|&i| std[i] > 0.0) {
            parameters.push(ParameterRow {
                group: "D_q".into(),
                symbol: format!("D_q[{}]", dofs[i].name()),
                grid_speed_mps: None,
                value: d_q[i],
                std: Some(std[i]),
                unit: lambda_quadratic::unit(dofs[i]).into(),
            });
        }
    }
    let extension = ((how.sides.below || how.sides.above)
        && how.scheduling == Scheduling::Interpolate)
        .then(|| LpvModel::new(speeds, subs.vehicle.clone()).ok())
        .flatten()
        .and_then(|v| choose_extension(&v, how.coriolis_from_m, how.restoring, how.sides));
    if let Some((ext, _)) = &extension {
        lpv = lpv.with_extension(*ext).map_err(model_error)?;
    }
    Ok((lpv, extension))
}
