//! The augmented LPV model from the per-speed reports: a chosen set of grid
//! points take discovery's refitted M, D̄ and terms, the others stay as the
//! start model has them.

use std::collections::BTreeSet;

use nalgebra::DMatrix;

use super::super::augmented::load_of;
use super::super::dataset::RunInput;
use super::super::document::ModelDocument;
use super::super::document::{
    LoggedController, LpvDoc, Method, ParameterRow, PointAugmentation, to_rows,
};
use super::super::error::IdentifyError;
use super::super::intersample::vehicle_from_logged;
use super::super::outcome::{Identified, RunValidation};
use super::super::predictor::validate_on_run;
use super::{DiscoverCampaignSettings, PointDiscovery};
use crate::discrepancy::ModelTerm;
use crate::discrepancy::report::ModelReport;
use crate::logs::schema::pose_column;
use crate::planning::dof::Dof;

/// What every candidate model is built and validated from.
pub(super) struct Assembly<'a> {
    pub doc: &'a ModelDocument,
    pub points: &'a [PointDiscovery],
    pub forces: &'a [String],
    pub runs: &'a [RunInput],
    pub est_ids: &'a [String],
    pub val_ids: &'a [String],
    pub settings: &'a DiscoverCampaignSettings,
    pub k: usize,
    /// Grid speeds not examined, refitted with the campaign's shared
    /// force held (`shared::held_alone`): they enter with any augmentation.
    pub held_only: &'a [(f64, ModelReport)],
}

impl Assembly<'_> {
    /// The held-out validation of `doc` on the validation runs.
    pub fn validate(&self, doc: &ModelDocument) -> Result<Vec<RunValidation>, IdentifyError> {
        self.runs
            .iter()
            .filter(|r| self.val_ids.contains(&r.run_id))
            .map(|r| {
                Ok(RunValidation {
                    run_id: r.run_id.clone(),
                    run_name: r.name.clone(),
                    report: validate_on_run(doc, r, self.forces, self.k)?,
                })
            })
            .collect()
    }

    /// The augmented model with the grid points in `kept` (indices into
    /// `points`) as discovery fitted them — their refitted M, D̄ and every
    /// term, carried or new — and the others as the start model has them,
    /// validated on the held-out runs.
    pub fn model(&self, kept: &BTreeSet<usize>) -> Result<Identified, IdentifyError> {
        let at: Vec<(f64, &ModelReport)> = self
            .points
            .iter()
            .enumerate()
            .filter(|(i, p)| kept.contains(i) && !p.report.findings.is_empty())
            .map(|(_, p)| (p.grid_speed_mps, &p.report.model))
            .collect();
        self.model_from(&at, true)
    }

    /// The start model with the grid points at the speeds of `at` replaced
    /// by their refitted models (and, when `hold` and one was applied, the
    /// speeds not examined holding the campaign's shared force), validated
    /// on the held-out runs.
    pub fn model_from(
        &self,
        at: &[(f64, &ModelReport)],
        hold: bool,
    ) -> Result<Identified, IdentifyError> {
        let doc = self.doc;
        let mut out = doc.clone();
        out.method = Method::Discovery;
        // Driven by the commanded τ and the measured attitude (see `augmented`).
        out.inputs = self
            .forces
            .iter()
            .cloned()
            .chain(Dof::ALL.iter().map(|d| pose_column(*d).to_string()))
            .collect();
        let lpv = out.lpv.as_mut().expect("checked: LPV");
        let logged_controller = lpv.logged_controller.clone();
        let mut applied = false;
        for &(speed, model) in at {
            applied |= apply_at(
                doc,
                lpv,
                logged_controller.as_ref(),
                &mut out.parameters,
                speed,
                model,
            )?;
        }
        // The speeds not examined hold the campaign's shared force too.
        if applied && hold {
            for (speed, model) in self.held_only {
                apply_at(
                    doc,
                    lpv,
                    logged_controller.as_ref(),
                    &mut out.parameters,
                    *speed,
                    model,
                )?;
            }
        }
        out.notes.insert(
            0,
            "Augmented by missing-physics discovery; refitted rows of M, D̄ keep the baseline's standard deviations — the discovered terms carry their own.".into(),
        );
        let validation = self.validate(&out)?;
        Ok(Identified {
            document: out,
            validation,
            estimation_run_ids: self.est_ids.to_vec(),
            validation_run_ids: self.val_ids.to_vec(),
            settings_used: serde_json::to_value(self.settings).unwrap_or_default(),
        })
    }
}

/// Grid point `speed` of `lpv` takes discovery's refitted `model`: its M,
/// D̄, constant loads and terms, and the terms' parameter rows. `false`
/// when the model has no such grid point.
fn apply_at(
    doc: &ModelDocument,
    lpv: &mut LpvDoc,
    logged_controller: Option<&LoggedController>,
    parameters: &mut Vec<ParameterRow>,
    speed: f64,
    model: &ModelReport,
) -> Result<bool, IdentifyError> {
    let Some(pt) = lpv
        .points
        .iter_mut()
        .find(|q| (q.speed_mps - speed).abs() < 1e-9)
    else {
        return Ok(false);
    };
    let terms = &model.terms;
    let m = DMatrix::from_fn(model.m.len(), model.m.len(), |i, j| model.m[i][j]);
    let d = DMatrix::from_fn(model.d_bar.len(), model.d_bar.len(), |i, j| {
        model.d_bar[i][j]
    });
    // Discovery fitted the model the logs see; the document keeps the
    // vehicle's M and D̄ (the logged view is rebuilt when predicting).
    let (m, d) = match logged_controller {
        Some(lc) => vehicle_from_logged(&m, &d, lc, &doc.dofs)
            .ok_or_else(super::super::intersample::malformed_controller)?,
        None => (m, d),
    };
    let m_inv = m.clone().try_inverse().ok_or_else(|| {
        IdentifyError::invalid(
            "document.lpv",
            format!("augmented M at {speed} m/s is singular"),
        )
    })?;
    // A force fixed in NED is refitted with the constant loads it had been
    // absorbed into.
    let load: Vec<f64> = doc
        .dofs
        .iter()
        .map(|d| model.restoring.constant[d.index()])
        .collect();
    if load != load_of(doc, pt).as_slice() {
        pt.load = Some(load);
    }
    pt.augmentation = Some(PointAugmentation {
        m_ref: model.m_ref.clone(),
        d_ref: model.d_ref.clone(),
        terms: terms.clone(),
    });
    pt.a = to_rows(&(-&m_inv * &d));
    pt.b = to_rows(&m_inv);
    pt.m = to_rows(&m);
    pt.d_bar = to_rows(&d);
    // Every term's estimates as refitted here (carried terms' earlier rows
    // at this speed are replaced).
    parameters.retain(|r| {
        !(r.group.starts_with("discovered: ")
            && r.grid_speed_mps.is_some_and(|s| (s - speed).abs() < 1e-9))
    });
    for term in terms {
        parameters.extend(term_rows(term, speed));
    }
    Ok(true)
}

/// The parameter-table rows of one discovered term at `speed`: its
/// coefficients, then its shape (lag, delay, level), each with its std.
pub(super) fn term_rows(term: &ModelTerm, speed: f64) -> Vec<ParameterRow> {
    let group = format!("discovered: {}", term.effect.label());
    let row = |symbol: String, value: f64, std: Option<f64>| ParameterRow {
        group: group.clone(),
        symbol,
        grid_speed_mps: Some(speed),
        value,
        std,
        unit: String::new(),
    };
    let mut rows: Vec<ParameterRow> = term
        .coefficients
        .iter()
        .zip(term.effect.coefficient_names())
        .enumerate()
        .map(|(j, (v, name))| row(name, *v, term.coefficient_std(j)))
        .collect();
    if let (Some(v), Some(kind)) = (term.shape, term.effect.shape()) {
        rows.push(row(kind.name().to_owned(), v, term.shape_std));
    }
    rows
}
