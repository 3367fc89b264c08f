//! Identification of an LPV model on forward speed by the λ-filter Kalman
//! method (thesis sec. 2.5): restoring forces from static runs, then one
//! M ν̇ + D̄ ν = γ per grid point from the dynamic and recursive runs, with
//! γ = τ − g(η); validated on the held-out runs.

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::dataset::{RunInput, Segment, segments};
use super::document::{
    LpvDoc, LpvPoint, Method, ModelDocument, ModelKind, ParameterRow, RestoringDoc, to_rows,
};
use super::error::IdentifyError;
use super::outcome::{Identified, RunValidation};
use super::roles::{assign_roles, nearest_grid_index};
use crate::estimation::lambda::{
    CouplingMask, Experiment, LambdaSettings, MIN_T_OVER_H, Prior, Structure, identify_lpv,
    propose_coupling,
};
use crate::estimation::restoring::{
    RestoringParams, RestoringSettings, StaticRecord, estimate_restoring,
};
use crate::estimation::{Progress, SubProgress};
use crate::logs::schema::pose_column;
use crate::models::{LinearVesselModel, LpvModel, Scheduling};
use crate::planning::dof::Dof;
use crate::planning::vessel::VesselProfile;
use crate::validation::{ValidationRecord, ValidationSettings, validate};

/// The coupling structure to identify.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum StructureChoice {
    /// Propose the coupling from partial coherence between DOFs (default).
    #[default]
    Auto,
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
    /// Estimate W − B, z_G·W − z_B·B and the tether moment from static runs
    /// (needs a 6-DOF vessel with static holds at several attitudes).
    #[serde(default = "default_true")]
    pub estimate_restoring: bool,
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

/// The segment's γ = τ − g(η) (or τ when no restoring model), and ν.
fn gamma_nu(
    seg: &Segment,
    n: usize,
    restoring: Option<&RestoringParams>,
) -> Result<(DMatrix<f64>, DMatrix<f64>), IdentifyError> {
    let tau = seg.u.columns(0, n).into_owned();
    let gamma = match restoring {
        Some(r) => {
            let eta = seg.u.columns(n, 6).into_owned();
            r.gamma(&tau, &eta).map_err(|e| {
                IdentifyError::invalid(format!("runs[{}]", seg.run_id), e.to_string())
            })?
        }
        None => tau,
    };
    Ok((gamma, seg.y.clone()))
}

/// Runs the λ-filter identification of a campaign.
///
/// `inputs` are the generalized-force columns in the order of
/// `profile.dofs` (τ, or τ_T = T·u for a thruster-actuated vessel); `grid`
/// is the campaign's LPV grid (m/s).
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
    progress.update(0.0, "restoring forces from static runs")?;

    // Restoring forces g(η) from the static runs (6-DOF vessels only: g(η)
    // couples heave, roll and pitch through the attitude).
    let mut restoring: Option<(RestoringParams, RestoringDoc)> = None;
    let with_pose: Vec<String> = inputs
        .iter()
        .cloned()
        .chain(Dof::ALL.iter().map(|d| pose_column(*d).to_string()))
        .collect();
    if settings.estimate_restoring && six_dof && !roles.statics.is_empty() {
        let mut segs = Vec::new();
        for r in &roles.statics {
            segs.extend(segments(r, &with_pose, &outputs, 20).map_err(|e| {
                IdentifyError::invalid(format!("runs[{}]", e.run_id), e.to_string())
            })?);
        }
        let taus: Vec<DMatrix<f64>> = segs
            .iter()
            .map(|s| s.u.columns(0, 6).into_owned())
            .collect();
        let etas: Vec<DMatrix<f64>> = segs
            .iter()
            .map(|s| s.u.columns(6, 6).into_owned())
            .collect();
        let records: Vec<StaticRecord<'_>> = segs
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
            Ok(est) => {
                let p = &est.params;
                let s = &est.std;
                let row = |symbol: &str, value: f64, std: f64, unit: &str| ParameterRow {
                    group: "g(η)".into(),
                    symbol: symbol.into(),
                    grid_speed_mps: None,
                    value,
                    std: Some(std),
                    unit: unit.into(),
                };
                let doc = RestoringDoc {
                    parameters: vec![
                        row("W−B", p.weight_minus_buoyancy_n, s.weight_minus_buoyancy_n, "N"),
                        row(
                            "z_G·W − z_B·B",
                            p.zg_weight_minus_zb_buoyancy_nm,
                            s.zg_weight_minus_zb_buoyancy_nm,
                            "N·m",
                        ),
                        row("τ_θ (tether)", p.tether_pitch_moment_nm, s.tether_pitch_moment_nm, "N·m"),
                    ],
                    evidence: vec![format!(
                        "{} steady segments from {} static runs; moment-term correlation {:.2}",
                        est.segments.len(),
                        roles.statics.len(),
                        est.moment_correlation
                    )],
                    params: *p,
                };
                restoring = Some((*p, doc));
            }
            Err(e) => notes.push(format!(
                "restoring forces not estimated ({e}); γ = τ, so W − B and the tether moment end up in the fit"
            )),
        }
    } else if !six_dof {
        notes.push("restoring forces need all six DOFs and the attitude; γ = τ".into());
    } else if roles.statics.is_empty() && settings.estimate_restoring {
        notes.push("no static runs: restoring forces not estimated; γ = τ".into());
    }
    let g = restoring.as_ref().map(|(p, _)| p);
    let cols_in: &[String] = if g.is_some() { &with_pose } else { inputs };
    let to_experiments = |run: &RunInput| -> Result<Vec<Experiment>, IdentifyError> {
        segments(run, cols_in, &outputs, 50)
            .map_err(|e| IdentifyError::invalid(format!("runs[{}]", e.run_id), e.to_string()))?
            .iter()
            .map(|s| {
                let (gamma, nu) = gamma_nu(s, n, g)?;
                Ok(Experiment::new(s.h, nu, gamma))
            })
            .collect()
    };

    // Estimation data per grid point; a run without a planned grid speed
    // goes to the grid point nearest its mean forward speed.
    let surge = dofs.iter().position(|d| *d == Dof::Surge);
    let mut per_point: Vec<Vec<Experiment>> = vec![Vec::new(); grid.len()];
    let mut runs_per_point: Vec<Vec<String>> = vec![Vec::new(); grid.len()];
    for r in &roles.estimation {
        for e in to_experiments(r)? {
            let speed = r
                .grid_speed_mps
                .unwrap_or_else(|| surge.map_or(grid[0], |j| e.nu.column(j).mean()));
            let i = nearest_grid_index(grid, speed);
            if !runs_per_point[i].contains(&r.run_id) {
                runs_per_point[i].push(r.run_id.clone());
            }
            per_point[i].push(e);
        }
    }
    let h = per_point
        .iter()
        .flatten()
        .map(|e| e.h)
        .next()
        .ok_or_else(|| IdentifyError::invalid("run_ids", "no usable estimation data"))?;
    for (speed, exps) in grid.iter().zip(&per_point) {
        if exps.is_empty() {
            notes.push(format!(
                "no estimation data at {speed:.2} m/s: the LPV model has no sub-model there"
            ));
        }
    }

    // λ filter time constant: well below the vessel's dynamics, ≥ 5 samples.
    let t_min = dofs
        .iter()
        .map(|d| profile.limit(*d).time_constant_s)
        .fold(f64::INFINITY, f64::min);
    let t_lambda = settings
        .t_lambda_s
        .unwrap_or_else(|| (0.5 * t_min).max(MIN_T_OVER_H * h));
    if !(t_lambda.is_finite() && t_lambda >= MIN_T_OVER_H * h) {
        return Err(IdentifyError::invalid(
            "settings.t_lambda_s",
            format!(
                "T = {t_lambda} s must be at least {MIN_T_OVER_H} samples ({} s)",
                MIN_T_OVER_H * h
            ),
        ));
    }

    // Coupling structure.
    let all: Vec<Experiment> = per_point.iter().flatten().cloned().collect();
    let (structure, mask_rows, structure_name) = match settings.structure {
        StructureChoice::Diagonal => (Structure::Diagonal, CouplingMask::diagonal(n), "diagonal"),
        StructureChoice::Coupled => (
            Structure::Coupled(CouplingMask::full(n)),
            CouplingMask::full(n),
            "coupled",
        ),
        StructureChoice::Custom => {
            let rows = settings.coupling.as_ref().ok_or_else(|| {
                IdentifyError::invalid(
                    "settings.coupling",
                    "structure 'custom' needs the coupling pattern",
                )
            })?;
            if rows.len() != n || rows.iter().any(|r| r.len() != n) {
                return Err(IdentifyError::invalid(
                    "settings.coupling",
                    format!("must be {n} × {n} booleans in the order {dofs:?}"),
                ));
            }
            let mut p = DMatrix::from_fn(n, n, |i, j| rows[i][j]);
            for i in 0..n {
                p[(i, i)] = true;
            }
            let mask = CouplingMask::from_pattern(&p);
            (Structure::Coupled(mask.clone()), mask, "coupled")
        }
        StructureChoice::Auto => {
            progress.update(0.08, "proposing coupling from partial coherence")?;
            let proposal = propose_coupling(&all, settings.coupling_threshold).map_err(|e| {
                IdentifyError::invalid(format!("settings.{}", e.field()), e.to_string())
            })?;
            let coupled: Vec<String> = proposal
                .evidence
                .iter()
                .filter(|p| proposal.mask.a[(p.output, p.input)])
                .map(|p| {
                    format!(
                        "{}←{} (partial coherence {:.2})",
                        dofs[p.output].name(),
                        dofs[p.input].name(),
                        p.median_partial_coherence
                    )
                })
                .collect();
            notes.push(if coupled.is_empty() {
                "coupling proposal: no DOF pair is coupled above the threshold; diagonal model"
                    .into()
            } else {
                format!("coupling proposed from the data: {}", coupled.join(", "))
            });
            let mask = proposal.mask.clone();
            (Structure::Coupled(mask.clone()), mask, "coupled")
        }
    };

    // Weak rigid-body prior from the profile: D ≈ F_max/v_max, M ≈ T·D.
    let lambda_settings = LambdaSettings::new(
        dofs.clone(),
        t_lambda,
        structure,
        Prior::from_profile(profile, &dofs),
    );
    let points: Vec<(f64, Vec<Experiment>)> = grid
        .iter()
        .zip(per_point)
        .filter(|(_, e)| !e.is_empty())
        .map(|(s, e)| (*s, e))
        .collect();
    let estimates = {
        let mut sub = SubProgress::new(progress, 0.1, 0.75);
        identify_lpv(&points, &lambda_settings, &mut sub).map_err(|e| match e {
            crate::estimation::lambda::LambdaError::Cancelled => IdentifyError::Cancelled,
            e => IdentifyError::invalid(e.field().to_string(), e.to_string()),
        })?
    };

    // Sub-models, their physical checks, parameters.
    let mut models = Vec::new();
    let mut lpv_points = Vec::new();
    let mut parameters = Vec::new();
    let mut findings = Vec::new();
    for (speed, est) in &estimates {
        let model = LinearVesselModel::new(dofs.clone(), est.m.clone(), est.d_bar.clone())
            .map_err(|e| IdentifyError::invalid("model", format!("at {speed:.2} m/s: {e}")))?;
        if let Ok(rep) = model.check_structure(1e-3) {
            findings.extend(
                rep.violations
                    .iter()
                    .map(|v| format!("at {speed:.2} m/s: {v}")),
            );
        }
        for i in 0..n {
            for j in 0..n {
                for (group, value, std, per_s) in [
                    ("M", est.m[(i, j)], est.std_m[(i, j)], false),
                    ("D̄", est.d_bar[(i, j)], est.std_d_bar[(i, j)], true),
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
        }
        let idx = grid.iter().position(|g| g == speed).unwrap_or(0);
        lpv_points.push(LpvPoint {
            speed_mps: *speed,
            m: to_rows(&est.m),
            m_std: to_rows(&est.std_m),
            d_bar: to_rows(&est.d_bar),
            d_bar_std: to_rows(&est.std_d_bar),
            a: to_rows(&est.a),
            a_std: to_rows(&est.std_a),
            b: to_rows(&est.b),
            b_std: to_rows(&est.std_b),
            n_samples: est.n_samples,
            run_ids: runs_per_point[idx].clone(),
            augmentation: None,
        });
        models.push(model);
    }
    if let Some((_, doc)) = &restoring {
        parameters.extend(doc.parameters.iter().cloned());
    }
    let scheduling = match settings.scheduling {
        SchedulingChoice::Nearest => Scheduling::Nearest,
        SchedulingChoice::Interpolate => Scheduling::Interpolate,
    };
    let lpv = LpvModel::new(estimates.iter().map(|(s, _)| *s).collect(), models)
        .map_err(|e| IdentifyError::invalid("model", e.to_string()))?
        .with_scheduling(scheduling);

    // Validation on the held-out runs.
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
    let mut validation = Vec::new();
    for r in &roles.validation {
        let segs = segments(r, cols_in, &outputs, 50)
            .map_err(|e| IdentifyError::invalid(format!("runs[{}]", e.run_id), e.to_string()))?;
        let longest = segs
            .iter()
            .max_by_key(|s| s.y.nrows())
            .expect("segments is non-empty");
        let (gamma, nu) = gamma_nu(longest, n, g)?;
        let rec = ValidationRecord {
            h: longest.h,
            u: &gamma,
            y: &nu,
        };
        let report = validate(&lpv, &rec, &vsettings)
            .map_err(|e| IdentifyError::invalid(format!("runs[{}]", r.run_id), e.to_string()))?;
        validation.push(RunValidation {
            run_id: r.run_id.clone(),
            run_name: r.name.clone(),
            report,
        });
    }
    progress.update(1.0, "done")?;

    let coupling = (0..n)
        .map(|i| (0..n).map(|j| mask_rows.a[(i, j)]).collect())
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
            structure: structure_name.into(),
            coupling,
            points: lpv_points,
        }),
        dp_ship: None,
        state_space: None,
        parameters,
        structure_findings: findings,
        notes,
    };
    let mut used = settings.clone();
    used.t_lambda_s = Some(t_lambda);
    Ok(Identified {
        document,
        validation,
        estimation_run_ids: roles.estimation.iter().map(|r| r.run_id.clone()).collect(),
        validation_run_ids: roles.validation.iter().map(|r| r.run_id.clone()).collect(),
        settings_used: serde_json::to_value(&used).unwrap_or_default(),
    })
}
