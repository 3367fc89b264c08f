//! Identification of an LPV model on forward speed by the λ-filter Kalman
//! method (thesis sec. 2.5): one M ν̇ + D̄ ν + b = γ per grid point, with
//! γ = τ − g(η) and g(η) estimated jointly from the runs themselves;
//! physical structure enforced; validated on the held-out runs.

use nalgebra::DVector;
use serde::{Deserialize, Serialize};

use super::dataset::Segment;
use super::dataset::{RunInput, segments};
use super::document::{
    LpvDoc, LpvPoint, Method, ModelDocument, ModelKind, ParameterRow, RestoringDoc, SpeedExtension,
    to_rows,
};
use super::error::IdentifyError;
use super::intersample::{correct_estimates, inertia_offset, logged_equivalent, logged_gains};
use super::joint_restoring::{Functions, PooledRestoring, load, specification};
use super::lambda_consistency::{inflate_inertia_std, symmetry_note};
use super::lambda_coriolis::fit_points;
use super::lambda_data::{experiment, per_point, regression_columns, static_holds};
use super::lambda_extension::{BELOW, choose_extension, speed_coverage_notes};
use super::lambda_information::default_t_lambda;
use super::lambda_physical::enforce;
use super::lambda_structure::choose_structure;
use super::lambda_validation::{HeldOut, choose_second_order};
use super::outcome::Identified;
use super::roles::assign_roles;
use crate::estimation::lambda::{Experiment, LambdaEstimate, LambdaSettings, MIN_T_OVER_H, Prior};
use crate::estimation::restoring::{RestoringEstimate, RestoringParams};
use crate::estimation::{Progress, SubProgress};
use crate::models::{LinearVesselModel, LpvModel, Scheduling};
use crate::planning::dof::Dof;
use crate::planning::vessel::VesselProfile;
use crate::validation::ValidationSettings;

/// The coupling structure to identify.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum StructureChoice {
    /// Port–starboard symmetry (default for 6-DOF and 3-DOF vessels) plus
    /// any pair the partial coherence between DOFs proposes; for other DOF
    /// sets the coherence proposal alone.
    #[default]
    Auto,
    /// Port–starboard (xz-plane) symmetry: surge, heave and pitch couple
    /// among themselves, sway, roll and yaw among themselves (Fossen 2011,
    /// sec. 7.5: the longitudinal and lateral subsystems).
    Symmetric,
    /// Each DOF alone (the thesis's first, uncoupled LPV model).
    Diagonal,
    /// Every entry of A and B free.
    Coupled,
    /// The user's pattern in `settings.coupling` (rows: ν_i, columns: DOFs).
    Custom,
}

/// How predictions schedule between grid points.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum SchedulingChoice {
    /// Nearest grid point (thesis eq. 2.17).
    Nearest,
    /// Blend of the neighbouring sub-models (eq. 2.18).
    #[default]
    Interpolate,
}

/// Settings of a λ-filter identification (JSON `settings` of the job).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct LambdaCampaignSettings {
    /// Coupling structure.
    #[serde(default)]
    pub structure: StructureChoice,
    /// Free entries for `custom`: n × n booleans in the order of the vessel's DOFs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coupling: Option<Vec<Vec<bool>>>,
    /// Partial-coherence threshold of the `auto` proposal (0–1).
    #[serde(default = "default_threshold")]
    pub coupling_threshold: f64,
    /// Time constant T of λ(s) = 1/(1+sT) (s); default: half the shortest
    /// expected time constant of the vessel, at least 5 samples.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub t_lambda_s: Option<f64>,
    /// Held-out runs; default: the plan's validation runs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub validation_run_ids: Option<Vec<String>>,
    /// Horizon of the k-step predictions of validation.
    #[serde(default = "default_k")]
    pub k: usize,
    /// Scheduling of predictions on forward speed.
    #[serde(default)]
    pub scheduling: SchedulingChoice,
    /// Estimate g(η) (W − B, z_G·W − z_B·B) jointly with M and D̄ from every
    /// run where the attitude moves, sharpened by static attitude holds when
    /// there are any (6-DOF vessels).
    #[serde(default = "default_true")]
    pub estimate_restoring: bool,
    /// Estimate a constant load b per DOF and grid point (tether, the heave
    /// part of W − B, the offset of the damping's linearization at speed).
    #[serde(default = "default_true")]
    pub constant_loads: bool,
    /// Take the couplings of C(ν)ν at the grid speed from the estimated M
    /// (Fossen 2011, eq. 6.43; 6-DOF and 3-DOF horizontal models), so the
    /// structure constrains the damping D and D̄ = D + J_C(M, u₀).
    #[serde(default = "default_true")]
    pub coriolis_from_m: bool,
    /// Rate of the vehicle's feedback controller (Hz); default: the vessel
    /// profile's `controller_rate_hz`. When it runs faster than the log
    /// (e.g. a 20 Hz loop logged at 10 Hz), M and D̄ are corrected for the
    /// commands the log does not show, with the controller's gains read
    /// from the log (see `intersample`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub controller_rate_hz: Option<f64>,
    /// Extend the model a short way below its lowest grid speed (up to 0.6
    /// of the first spacing, not below 0 m/s, as far as it stays physical
    /// and stable: damping extrapolated linearly in speed, the load
    /// quadratically) instead of holding the lowest sub-model there
    /// (thesis). Interpolated scheduling on three or more grid speeds;
    /// above the grid the highest sub-model is held.
    #[serde(default = "default_true")]
    pub extend_below_grid: bool,
    /// Fit M symmetric: the rows of each sub-model re-estimated under
    /// M = Mᵀ by least squares over their joint uncertainty, with σ scaled
    /// by how far the unconstrained rows were from it. Off by default (the
    /// rows fitted freely, the nearest symmetric M stored with D̄ unchanged)
    /// until discovery's refit of touched rows works from such a model.
    #[serde(default)]
    pub symmetric_inertia: bool,
    /// Carry the second-order Coriolis–centripetal force C(δ)δ of the
    /// estimated M in the model (δ = ν about straight-ahead motion at the
    /// scheduled speed): the centripetal forces of turning, heaving and
    /// rolling that no linear sub-model holds, with no parameter added
    /// (models with a surge DOF).
    #[serde(default = "default_true")]
    pub coriolis_second_order: bool,
}

fn default_threshold() -> f64 {
    0.2
}
fn default_k() -> usize {
    10
}
fn default_true() -> bool {
    true
}

impl Default for LambdaCampaignSettings {
    fn default() -> Self {
        LambdaCampaignSettings {
            structure: StructureChoice::Auto,
            coupling: None,
            coupling_threshold: default_threshold(),
            t_lambda_s: None,
            validation_run_ids: None,
            k: default_k(),
            scheduling: SchedulingChoice::Interpolate,
            estimate_restoring: true,
            constant_loads: true,
            coriolis_from_m: true,
            controller_rate_hz: None,
            extend_below_grid: true,
            symmetric_inertia: false,
            coriolis_second_order: true,
        }
    }
}

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

fn lambda_error(e: crate::estimation::lambda::LambdaError) -> IdentifyError {
    match e {
        crate::estimation::lambda::LambdaError::Cancelled => IdentifyError::Cancelled,
        e => IdentifyError::invalid(e.field().to_string(), e.to_string()),
    }
}

/// Runs the λ-filter identification of a campaign.
///
/// `inputs` are the generalized-force columns in the order of
/// `profile.dofs` (τ, or τ_T = T·u for a thruster-actuated vessel); `grid`
/// is the campaign's LPV grid (m/s).
///
/// 1. g(η) (6-DOF): W − B and z_G W − z_B B estimated jointly with M, D̄
///    and constant loads at every grid point ([`super::joint_restoring`]),
///    pooled over the grid, sharpened by station-keeping holds if flown.
/// 2. Per grid point, M ν̇ + D̄ ν + b = τ − g(η) with the pooled g(η).
/// 3. A sub-model that is not physical (M not symmetric positive definite,
///    D̄ not dissipative) is projected onto the physical set and the cost in
///    1-step fit is reported ([`crate::models::project_physical`]).
/// 4. Validation on the held-out runs.
pub fn identify_lambda_campaign(
    profile: &VesselProfile,
    grid: &[f64],
    inputs: &[String],
    runs: &[RunInput],
    settings: &LambdaCampaignSettings,
    progress: &mut dyn Progress,
) -> Result<Identified, IdentifyError> {
    let dofs = profile.dofs.clone();
    let n = dofs.len();
    if inputs.len() != n {
        return Err(IdentifyError::invalid(
            "inputs",
            format!("{} input columns for {n} DOFs", inputs.len()),
        ));
    }
    if grid.is_empty() {
        return Err(IdentifyError::invalid(
            "campaign.grid",
            "the campaign has no grid speeds",
        ));
    }
    if !(settings.coupling_threshold > 0.0 && settings.coupling_threshold < 1.0) {
        return Err(IdentifyError::invalid(
            "settings.coupling_threshold",
            format!("must be in (0, 1), got {}", settings.coupling_threshold),
        ));
    }
    if let Some(rate) = settings.controller_rate_hz
        && !(rate.is_finite() && rate > 0.0)
    {
        return Err(IdentifyError::invalid(
            "settings.controller_rate_hz",
            format!("must be a positive rate in Hz, got {rate}"),
        ));
    }
    if settings.k == 0 {
        return Err(IdentifyError::invalid(
            "settings.k",
            "the horizon k must be ≥ 1",
        ));
    }
    let roles = assign_roles(runs, settings.validation_run_ids.as_deref())?;
    let outputs: Vec<String> = dofs
        .iter()
        .map(|d| d.velocity_symbol().to_string())
        .collect();
    let six_dof = n == 6;
    let mut notes = Vec::new();
    progress.update(0.0, "collecting estimation data")?;

    // Columns: τ, then η when g(η) is part of the model.
    let with_restoring = settings.estimate_restoring && six_dof;
    let cols = regression_columns(inputs, with_restoring);
    if !six_dof && settings.estimate_restoring {
        notes.push("g(η) needs all six DOFs and the attitude; γ = τ".into());
    }
    let data = per_point(&roles, grid, &dofs, &cols, &outputs, &mut notes)?;
    let h = data
        .segments
        .iter()
        .flatten()
        .map(|s| s.h)
        .next()
        .ok_or_else(|| IdentifyError::invalid("run_ids", "no usable estimation data"))?;
    for (speed, segs) in grid.iter().zip(&data.segments) {
        if segs.is_empty() {
            notes.push(format!(
                "no estimation data at {speed:.2} m/s: the LPV model has no sub-model there"
            ));
        }
    }

    // λ filter time constant: well below the vessel's dynamics, ≥ 5 samples.
    let t_lambda = settings
        .t_lambda_s
        .unwrap_or_else(|| default_t_lambda(profile, h));
    if !(t_lambda.is_finite() && t_lambda >= MIN_T_OVER_H * h) {
        return Err(IdentifyError::invalid(
            "settings.t_lambda_s",
            format!(
                "T = {t_lambda} s must be at least {MIN_T_OVER_H} samples ({} s)",
                MIN_T_OVER_H * h
            ),
        ));
    }

    let build = |restoring: Option<&RestoringParams>, f: Option<Functions>| {
        data.segments
            .iter()
            .map(|segs| {
                segs.iter()
                    .map(|s| experiment(s, n, restoring, f))
                    .collect::<Result<Vec<_>, _>>()
            })
            .collect::<Result<Vec<_>, _>>()
    };
    let points_of = |exps: Vec<Vec<Experiment>>| -> Vec<(f64, Vec<Experiment>)> {
        grid.iter()
            .zip(exps)
            .filter(|(_, e)| !e.is_empty())
            .map(|(s, e)| (*s, e))
            .collect()
    };
    let plain = build(None, None)?;
    let all: Vec<Experiment> = plain.iter().flatten().cloned().collect();
    let chosen = choose_structure(settings, &dofs, &all, progress, &mut notes)?;
    let mut lambda_settings = LambdaSettings::new(
        dofs.clone(),
        t_lambda,
        chosen.structure.clone(),
        Prior::from_profile(profile, &dofs),
    );
    lambda_settings.symmetric_inertia = settings.symmetric_inertia;
    // A controller faster than the log: the fit returns M − c K_ν, and
    // M itself is what must be symmetric.
    let logged: Vec<&Segment> = data.segments.iter().flatten().collect();
    let h_log = logged.first().map_or(0.0, |s| s.h);
    let rate_hz = settings
        .controller_rate_hz
        .unwrap_or(profile.controller_rate_hz);
    let gains = logged_gains(&logged, &dofs, with_restoring, rate_hz);
    lambda_settings.inertia_offset = gains
        .as_ref()
        .ok()
        .and_then(|g| g.as_ref())
        .map(|(g, c)| inertia_offset(g, *c));

    // 1. g(η) jointly with M, D̄ and constant loads, pooled over the grid.
    let mut restoring: Option<(RestoringParams, RestoringDoc)> = None;
    if with_restoring {
        let holds = static_holds(&roles, &dofs, &cols, &outputs, &mut notes)?;
        lambda_settings.exogenous = Some(specification(
            profile,
            &dofs,
            Functions::ConstantAndRestoring,
        ));
        let joint = {
            let mut sub = SubProgress::new(progress, 0.05, 0.4);
            fit_points(
                &points_of(build(None, Some(Functions::ConstantAndRestoring))?),
                &lambda_settings,
                settings.coriolis_from_m,
                &mut sub,
                &mut notes,
            )
            .map_err(lambda_error)?
        };
        match PooledRestoring::from_points(&joint) {
            Some(pooled) => {
                let pooled = match &holds {
                    Some(est) => pooled.with_static(&est.params, &est.std),
                    None => pooled,
                };
                restoring = Some((pooled.params(), restoring_doc(&pooled, &joint, holds.as_ref())));
            }
            None => notes.push(
                "g(η) could not be estimated (no attitude motion in roll or pitch): γ = τ, the constant loads absorb W − B"
                    .into(),
            ),
        }
    }
    let g = restoring.as_ref().map(|(p, _)| p);

    // 2. The sub-models with g(η) fixed at the pooled value.
    let loads = settings.constant_loads.then_some(Functions::Constant);
    lambda_settings.exogenous = loads.map(|f| specification(profile, &dofs, f));
    let exps = build(g, loads)?;
    let estimates = {
        let from = if with_restoring { 0.4 } else { 0.1 };
        let mut sub = SubProgress::new(progress, from, 0.8);
        fit_points(
            &points_of(exps.clone()),
            &lambda_settings,
            settings.coriolis_from_m,
            &mut sub,
            &mut notes,
        )
        .map_err(lambda_error)?
    };

    let (mut estimates, logged_controller) =
        correct_estimates(estimates, gains, h_log, rate_hz, &dofs, &mut notes);
    symmetry_note(&estimates, &mut notes);
    inflate_inertia_std(&mut estimates, &dofs, &mut notes);

    // 3. Sub-models, physical structure enforced, parameters.
    let mut models = Vec::new();
    let mut vehicle = Vec::new();
    let mut lpv_points = Vec::new();
    let mut parameters = Vec::new();
    let mut findings = Vec::new();
    for (speed, est) in &estimates {
        let idx = grid.iter().position(|g| g == speed).unwrap_or(0);
        let (load, load_std) = joint_load(est, n);
        let physical = enforce(
            &dofs,
            est,
            &load,
            &exps[idx],
            *speed,
            settings.coriolis_from_m,
        )?;
        findings.extend(physical.findings);
        let model = physical.model;
        for i in 0..n {
            for j in 0..n {
                for (group, value, std, per_s) in [
                    ("M", model.m()[(i, j)], est.std_m[(i, j)], false),
                    ("D̄", model.d_bar()[(i, j)], est.std_d_bar[(i, j)], true),
                ] {
                    if value != 0.0 || std > 0.0 {
                        parameters.push(ParameterRow {
                            group: group.into(),
                            symbol: format!("{group}[{},{}]", dofs[i].name(), dofs[j].name()),
                            grid_speed_mps: Some(*speed),
                            value,
                            std: Some(std),
                            unit: unit(&dofs, i, j, per_s),
                        });
                    }
                }
            }
            if settings.constant_loads {
                parameters.push(ParameterRow {
                    group: "b".into(),
                    symbol: format!("b[{}]", dofs[i].name()),
                    grid_speed_mps: Some(*speed),
                    value: load[i],
                    std: Some(load_std[i]),
                    unit: force_unit(dofs[i]).into(),
                });
            }
        }
        lpv_points.push(LpvPoint {
            speed_mps: *speed,
            m: to_rows(model.m()),
            m_std: to_rows(&est.std_m),
            d_bar: to_rows(model.d_bar()),
            d_bar_std: to_rows(&est.std_d_bar),
            a: to_rows(model.a()),
            a_std: to_rows(&est.std_a),
            b: to_rows(model.b()),
            b_std: to_rows(&est.std_b),
            load: settings
                .constant_loads
                .then(|| load.iter().copied().collect()),
            load_std: settings
                .constant_loads
                .then(|| load_std.iter().copied().collect()),
            n_samples: est.n_samples,
            run_ids: data.run_ids[idx].clone(),
            augmentation: None,
        });
        vehicle.push(model.clone());
        // Validation predicts the logs: with the controller's unlogged
        // commands added back when it ran faster than the log.
        let for_logs = match &logged_controller {
            Some(lc) => logged_equivalent(model.m(), model.d_bar(), lc, &dofs)
                .and_then(|(m, d)| {
                    LinearVesselModel::new(dofs.clone(), m, d)
                        .and_then(|x| x.with_load(model.load().clone()))
                        .ok()
                })
                .unwrap_or(model),
            None => model,
        };
        models.push(for_logs);
    }
    if let Some((_, doc)) = &restoring {
        parameters.extend(doc.parameters.iter().cloned());
    }
    let scheduling = match settings.scheduling {
        SchedulingChoice::Nearest => Scheduling::Nearest,
        SchedulingChoice::Interpolate => Scheduling::Interpolate,
    };
    let speeds: Vec<f64> = estimates.iter().map(|(s, _)| *s).collect();
    let second_order = settings.coriolis_second_order && dofs.contains(&Dof::Surge);
    let vehicle_m: Vec<_> = vehicle.iter().map(|v| v.m().clone()).collect();
    let lpv = LpvModel::new(speeds.clone(), models)
        .map_err(|e| IdentifyError::invalid("model", e.to_string()))?
        .with_scheduling(scheduling);
    let lpv = if second_order {
        lpv.with_second_order_coriolis(vehicle_m)
            .map_err(|e| IdentifyError::invalid("model", e.to_string()))?
    } else {
        lpv
    };
    // Beyond the grid: extended as far as the vehicle's model stays physical.
    let extension = (settings.extend_below_grid && scheduling == Scheduling::Interpolate)
        .then(|| LpvModel::new(speeds, vehicle).ok())
        .flatten()
        .and_then(|v| choose_extension(&v, settings.coriolis_from_m, g, BELOW));
    let lpv = match &extension {
        Some((ext, note)) => {
            notes.push(note.clone());
            lpv.with_extension(*ext)
                .map_err(|e| IdentifyError::invalid("model", e.to_string()))?
        }
        None => lpv,
    };

    // 4. Validation on the held-out runs.
    progress.update(0.85, "validating on held-out runs")?;
    let input_names: Vec<String> = dofs
        .iter()
        .map(|d| format!("γ_{}", &d.force_column()[4..]))
        .collect();
    let vsettings = ValidationSettings {
        k: settings.k,
        input_names: input_names.clone(),
        ..ValidationSettings::default()
    };
    let held_out = HeldOut {
        runs: &roles.validation,
        cols: &cols,
        outputs: &outputs,
        n,
        restoring: g,
        settings: &vsettings,
    };
    let validate_with = |lpv: &LpvModel| held_out.validate(lpv);
    let validation = validate_with(&lpv)?;
    let (lpv, validation, second_order) =
        choose_second_order(lpv, validation, second_order, &validate_with, &mut notes)?;
    if let Some(j) = dofs.iter().position(|d| *d == Dof::Surge) {
        for r in &roles.validation {
            if let Ok(segs) = segments(r, &cols, &outputs, 50)
                && let Some(longest) = segs.iter().max_by_key(|s| s.y.nrows())
            {
                let u: Vec<f64> = longest.y.column(j).iter().copied().collect();
                let grid: Vec<f64> = estimates.iter().map(|(s, _)| *s).collect();
                notes.extend(speed_coverage_notes(&r.name, &u, &grid, lpv.extension()));
            }
        }
    }
    progress.update(1.0, "done")?;

    let coupling = (0..n)
        .map(|i| (0..n).map(|j| chosen.mask.a[(i, j)]).collect())
        .collect();
    let document = ModelDocument {
        kind: ModelKind::Lpv,
        method: Method::LambdaKf,
        dofs: dofs.clone(),
        inputs: input_names,
        outputs,
        restoring: restoring.map(|(_, d)| d),
        lpv: Some(LpvDoc {
            t_lambda_s: t_lambda,
            structure: chosen.name.into(),
            coupling,
            points: lpv_points,
            logged_controller,
            extension: extension.map(|(e, _)| SpeedExtension::from(e)),
            coriolis_second_order: second_order,
        }),
        dp_ship: None,
        state_space: None,
        parameters,
        structure_findings: findings,
        notes,
    };
    let mut used = settings.clone();
    used.t_lambda_s = Some(t_lambda);
    let estimation_run_ids = {
        let mut ids: Vec<String> = Vec::new();
        for id in data.run_ids.iter().flatten() {
            if !ids.contains(id) {
                ids.push(id.clone());
            }
        }
        ids
    };
    Ok(Identified {
        document,
        validation,
        estimation_run_ids,
        validation_run_ids: roles.validation.iter().map(|r| r.run_id.clone()).collect(),
        settings_used: serde_json::to_value(&used).unwrap_or_default(),
    })
}

/// The constant load b and its std of an estimate (zero without loads).
fn joint_load(est: &LambdaEstimate, n: usize) -> (DVector<f64>, DVector<f64>) {
    load(est).unwrap_or_else(|| (DVector::zeros(n), DVector::zeros(n)))
}

/// The restoring document of the pooled estimate.
fn restoring_doc(
    pooled: &PooledRestoring,
    joint: &[(f64, LambdaEstimate)],
    holds: Option<&RestoringEstimate>,
) -> RestoringDoc {
    let row = |symbol: &str, p: &super::joint_restoring::Pooled, unit: &str| ParameterRow {
        group: "g(η)".into(),
        symbol: symbol.into(),
        grid_speed_mps: None,
        value: p.value,
        std: Some(p.std),
        unit: unit.into(),
    };
    let (wb, bg) = (&pooled.weight_minus_buoyancy, &pooled.metacentric);
    let mut evidence = vec![format!(
        "estimated with M, D̄ and the constant loads from every run where the attitude moves, at {} grid speeds; W − B from surge (sin θ) and sway (cos θ·sin φ): {} estimates, χ²/dof {:.2}; z_G·W − z_B·B from roll and pitch: {} estimates, χ²/dof {:.2}",
        joint.len(),
        wb.count,
        wb.birge_ratio_sq,
        bg.count,
        bg.birge_ratio_sq
    )];
    if let Some(h) = holds {
        evidence.push(format!(
            "sharpened by {} steady segments of station-keeping attitude holds (W − B {:.1} ± {:.1} N, z_G·W − z_B·B {:.2} ± {:.2} N·m on their own)",
            h.segments.len(),
            h.params.weight_minus_buoyancy_n,
            h.std.weight_minus_buoyancy_n,
            h.params.zg_weight_minus_zb_buoyancy_nm,
            h.std.zg_weight_minus_zb_buoyancy_nm
        ));
    }
    RestoringDoc {
        parameters: vec![row("W−B", wb, "N"), row("z_G·W − z_B·B", bg, "N·m")],
        evidence,
        params: pooled.params(),
    }
}
