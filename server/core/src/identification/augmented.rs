//! An LPV model with discovered physics (thesis eq. 2.16–2.18 plus the terms
//! of [`crate::discrepancy`]): one [`AugmentedModel`] per grid speed, driven
//! by (τ, η) rather than γ because the added terms may act on τ before it is
//! applied (lag, delay, saturation) or depend on η (restoring, current).

use nalgebra::DMatrix;

use super::document::{LpvPoint, ModelDocument, from_rows};
use super::error::IdentifyError;
use crate::discrepancy::{AugmentedModel, Baseline, Restoring};
use crate::planning::dof::Dof;
use crate::validation::{Predictor, ValidationRecord};

/// True when any sub-model of `doc` carries discovered terms.
pub fn is_augmented(doc: &ModelDocument) -> bool {
    doc.lpv
        .as_ref()
        .is_some_and(|l| l.points.iter().any(|p| p.augmentation.is_some()))
}

/// g(η) of a stored model in the form discovery uses (zero when the
/// restoring forces were not estimated: then γ = τ).
pub fn restoring_of(doc: &ModelDocument) -> Restoring {
    doc.restoring
        .as_ref()
        .map(|r| Restoring {
            w_minus_b: r.params.weight_minus_buoyancy_n,
            zg_w_minus_zb_b: r.params.zg_weight_minus_zb_buoyancy_nm,
            tether_pitch_moment: r.params.tether_pitch_moment_nm,
        })
        .unwrap_or_default()
}

fn matrix(rows: &super::document::Matrix, what: &str) -> Result<DMatrix<f64>, IdentifyError> {
    from_rows(rows)
        .ok_or_else(|| IdentifyError::invalid("document.lpv", format!("{what} is ragged")))
}

/// The baseline M ν̇ + D̄ ν = τ − g(η) of one LPV sub-model.
pub fn baseline_at(doc: &ModelDocument, point: &LpvPoint) -> Result<Baseline, IdentifyError> {
    Ok(Baseline {
        dofs: doc.dofs.clone(),
        m: matrix(&point.m, "M")?,
        d_bar: matrix(&point.d_bar, "D̄")?,
        restoring: restoring_of(doc),
    })
}

/// The sub-model of one grid point with its terms (none: the baseline).
pub fn augmented_at(
    doc: &ModelDocument,
    point: &LpvPoint,
) -> Result<AugmentedModel, IdentifyError> {
    let b = baseline_at(doc, point)?;
    Ok(match &point.augmentation {
        None => AugmentedModel::from_baseline(&b),
        Some(a) => AugmentedModel::new(
            b.dofs,
            b.m,
            b.d_bar,
            b.restoring,
            matrix(&a.m_ref, "augmentation.m_ref")?,
            matrix(&a.d_ref, "augmentation.d_ref")?,
            a.terms.clone(),
        ),
    })
}

/// The augmented LPV model as a predictor with u = [τ | η]. A run is
/// predicted by the sub-model of the grid speed nearest its mean measured
/// forward speed (runs fly one grid speed; scheduling sample by sample
/// would switch the actuator states of lag and delay terms mid-run).
pub struct AugmentedLpv {
    speeds: Vec<f64>,
    models: Vec<AugmentedModel>,
    surge: Option<usize>,
}

impl AugmentedLpv {
    /// From a stored LPV document (augmented or not).
    pub fn from_doc(doc: &ModelDocument) -> Result<Self, IdentifyError> {
        let lpv = doc
            .lpv
            .as_ref()
            .ok_or_else(|| IdentifyError::invalid("document.lpv", "missing"))?;
        if lpv.points.is_empty() {
            return Err(IdentifyError::invalid("document.lpv.points", "empty"));
        }
        let models = lpv
            .points
            .iter()
            .map(|p| augmented_at(doc, p))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(AugmentedLpv {
            speeds: lpv.points.iter().map(|p| p.speed_mps).collect(),
            models,
            surge: doc.dofs.iter().position(|d| *d == Dof::Surge),
        })
    }

    fn pick(&self, rec: &ValidationRecord<'_>) -> &AugmentedModel {
        let speed = match self.surge {
            Some(j) if rec.y.nrows() > 0 => rec.y.column(j).mean(),
            _ => self.speeds[0],
        };
        &self.models[super::roles::nearest_grid_index(&self.speeds, speed)]
    }
}

impl Predictor for AugmentedLpv {
    fn output_names(&self) -> Vec<String> {
        self.models[0].output_names()
    }

    fn predict_k_step(&self, rec: &ValidationRecord<'_>, k: usize) -> DMatrix<f64> {
        Predictor::predict_k_step(self.pick(rec), rec, k)
    }

    fn simulate(&self, rec: &ValidationRecord<'_>) -> DMatrix<f64> {
        Predictor::simulate(self.pick(rec), rec)
    }
}
