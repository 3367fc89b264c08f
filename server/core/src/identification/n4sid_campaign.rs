//! Black-box comparison model by N4SID (the thesis's comparison, sec. 4):
//! one LTI model about the campaign's mean operating point, from the
//! estimation runs as a multi-experiment set; validated on held-out runs.

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::RunInput;
use super::dataset::{Segment, segments};
use super::document::{Method, ModelDocument, ModelKind, ParameterRow, StateSpaceDoc, to_rows};
use super::error::IdentifyError;
use super::outcome::{Identified, RunValidation};
use super::roles::assign_roles;
use super::state_space::StateSpacePredictor;
use crate::estimation::n4sid::{N4sidError, N4sidSettings, Weighting, n4sid};
use crate::estimation::{Progress, SubProgress};
use crate::planning::Dof;
use crate::planning::vessel::VesselProfile;
use crate::validation::{ValidationRecord, ValidationSettings, validate};

/// Weighting of the oblique projection.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum WeightingChoice {
    /// W₁ = W₂ = I.
    N4sid,
    /// MOESP (default).
    #[default]
    Moesp,
    /// Canonical variate analysis.
    Cva,
}

/// Settings of an N4SID identification (JSON `settings` of the job).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct N4sidCampaignSettings {
    /// Model order n; default: chosen from the singular values.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub order: Option<usize>,
    /// Block rows i of the Hankel matrices (≥ 2).
    #[serde(default = "default_horizon")]
    pub horizon: usize,
    /// Largest order considered when choosing.
    #[serde(default = "default_max_order")]
    pub max_order: usize,
    /// Weighting.
    #[serde(default)]
    pub weighting: WeightingChoice,
    /// Held-out runs; default: the plan's validation runs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub validation_run_ids: Option<Vec<String>>,
    /// Horizon of the k-step predictions of validation.
    #[serde(default = "default_k")]
    pub k: usize,
}

fn default_horizon() -> usize {
    10
}
fn default_max_order() -> usize {
    12
}
fn default_k() -> usize {
    10
}

impl Default for N4sidCampaignSettings {
    fn default() -> Self {
        N4sidCampaignSettings {
            order: None,
            horizon: default_horizon(),
            max_order: default_max_order(),
            weighting: WeightingChoice::Moesp,
            validation_run_ids: None,
            k: default_k(),
        }
    }
}

fn column_means(segs: &[Segment], pick: impl Fn(&Segment) -> &DMatrix<f64>) -> Vec<f64> {
    let cols = segs.first().map_or(0, |s| pick(s).ncols());
    let n: usize = segs.iter().map(|s| pick(s).nrows()).sum();
    (0..cols)
        .map(|j| segs.iter().map(|s| pick(s).column(j).sum()).sum::<f64>() / n.max(1) as f64)
        .collect()
}

fn centered(m: &DMatrix<f64>, mean: &[f64]) -> DMatrix<f64> {
    DMatrix::from_fn(m.nrows(), m.ncols(), |i, j| m[(i, j)] - mean[j])
}

/// Runs N4SID over a campaign: inputs τ (or τ_T), outputs ν, deviations
/// from the mean operating point of the estimation data.
pub fn identify_n4sid_campaign(
    profile: &VesselProfile,
    inputs: &[String],
    runs: &[RunInput],
    settings: &N4sidCampaignSettings,
    progress: &mut dyn Progress,
) -> Result<Identified, IdentifyError> {
    if settings.k == 0 {
        return Err(IdentifyError::invalid(
            "settings.k",
            "the horizon k must be ≥ 1",
        ));
    }
    let roles = assign_roles(runs, settings.validation_run_ids.as_deref())?;
    let outputs: Vec<String> = Dof::velocity_symbols(&profile.dofs);
    let min_len = 4 * settings.horizon.max(2) + 20;
    let mut segs = Vec::new();
    // Static runs are estimation data too for a black box: they carry the
    // steady-state gain.
    for r in roles.estimation.iter().chain(&roles.statics) {
        segs.extend(
            segments(r, inputs, &outputs, min_len).map_err(|e| {
                IdentifyError::invalid(format!("runs[{}]", e.run_id), e.to_string())
            })?,
        );
    }
    let h = segs[0].h;
    if let Some(s) = segs.iter().find(|s| (s.h - h).abs() > 1e-9 * h) {
        return Err(IdentifyError::invalid(
            format!("runs[{}]", s.run_id),
            format!(
                "sample time {} s differs from {h} s of the other runs; resample them alike",
                s.h
            ),
        ));
    }
    let u_mean = column_means(&segs, |s| &s.u);
    let y_mean = column_means(&segs, |s| &s.y);
    let data: Vec<(DMatrix<f64>, DMatrix<f64>)> = segs
        .iter()
        .map(|s| (centered(&s.u, &u_mean), centered(&s.y, &y_mean)))
        .collect();
    let refs: Vec<(&DMatrix<f64>, &DMatrix<f64>)> = data.iter().map(|(u, y)| (u, y)).collect();
    let n4 = N4sidSettings {
        h,
        horizon: settings.horizon,
        order: settings.order,
        max_order: settings.max_order,
        weighting: match settings.weighting {
            WeightingChoice::N4sid => Weighting::N4sid,
            WeightingChoice::Moesp => Weighting::Moesp,
            WeightingChoice::Cva => Weighting::Cva,
        },
        ..N4sidSettings::new(h)
    };
    let mut model = {
        let mut sub = SubProgress::new(progress, 0.0, 0.8);
        n4sid(&refs, &n4, &mut sub).map_err(|e| match e {
            N4sidError::Cancelled => IdentifyError::Cancelled,
            e => IdentifyError::invalid("settings", e.to_string()),
        })?
    };
    // Validation reports name the channels as the logs do (u, v, …), not y0, y1, ….
    model.output_names = outputs.clone();
    progress.update(0.8, "validating on held-out runs")?;
    let vsettings = ValidationSettings {
        k: settings.k,
        input_names: inputs.to_vec(),
        ..ValidationSettings::default()
    };
    let predictor = StateSpacePredictor(model.clone());
    let mut validation = Vec::new();
    for r in &roles.validation {
        let vs = segments(r, inputs, &outputs, min_len)
            .map_err(|e| IdentifyError::invalid(format!("runs[{}]", e.run_id), e.to_string()))?;
        let longest = vs
            .iter()
            .max_by_key(|s| s.y.nrows())
            .expect("segments is non-empty");
        let (u, y) = (centered(&longest.u, &u_mean), centered(&longest.y, &y_mean));
        let report = validate(
            &predictor,
            &ValidationRecord { h, u: &u, y: &y },
            &vsettings,
        )
        .map_err(|e| IdentifyError::invalid(format!("runs[{}]", r.run_id), e.to_string()))?;
        validation.push(RunValidation {
            run_id: r.run_id.clone(),
            run_name: r.name.clone(),
            report,
        });
    }
    progress.update(1.0, "done")?;
    let mut notes = vec![format!(
        "LTI model of deviations about the mean operating point of the estimation data (u₀ = {:.3} m/s in surge where modelled); order {} from the singular values",
        profile
            .dofs
            .iter()
            .position(|d| *d == crate::planning::dof::Dof::Surge)
            .map_or(0.0, |j| y_mean[j]),
        model.order
    )];
    let (a_c, b_c) = match model.continuous() {
        Ok(c) => (Some(to_rows(&c.a)), Some(to_rows(&c.b))),
        Err(e) => {
            notes.push(format!("no continuous-time form: {e}"));
            (None, None)
        }
    };
    let parameters = model
        .eigenvalues()
        .iter()
        .enumerate()
        .map(|(i, z)| ParameterRow {
            group: "poles".into(),
            symbol: format!("|z{}| (discrete pole, arg {:.4} rad)", i + 1, z.arg()),
            grid_speed_mps: None,
            value: z.norm(),
            std: None,
            unit: "-".into(),
        })
        .collect();
    let document = ModelDocument {
        kind: ModelKind::StateSpace,
        method: Method::N4sid,
        dofs: profile.dofs.clone(),
        inputs: inputs.to_vec(),
        outputs,
        restoring: None,
        lpv: None,
        dp_ship: None,
        state_space: Some(StateSpaceDoc {
            h,
            order: model.order,
            phi: to_rows(&model.a),
            gamma: to_rows(&model.b),
            c: to_rows(&model.c),
            d: to_rows(&model.d),
            k: to_rows(&model.k),
            singular_values: model.singular_values.clone(),
            a_continuous: a_c,
            b_continuous: b_c,
            u_offset: u_mean.clone(),
            y_offset: y_mean.clone(),
        }),
        parameters,
        structure_findings: vec![],
        notes,
    };
    let mut used = settings.clone();
    used.order = Some(model.order);
    Ok(Identified {
        document,
        validation,
        estimation_run_ids: roles
            .estimation
            .iter()
            .chain(&roles.statics)
            .map(|r| r.run_id.clone())
            .collect(),
        validation_run_ids: roles.validation.iter().map(|r| r.run_id.clone()).collect(),
        settings_used: serde_json::to_value(&used).unwrap_or_default(),
    })
}
