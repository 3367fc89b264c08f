//! An LPV model with discovered physics (thesis eq. 2.16–2.18 plus the terms
//! of [`crate::discrepancy`]): one [`AugmentedModel`] per grid speed, driven
//! by (τ, η) rather than γ because the added terms may act on τ before it is
//! applied (lag, delay, saturation) or depend on η (restoring, current).

use nalgebra::DMatrix;

use super::document::{LpvPoint, ModelDocument, from_rows};
use super::error::IdentifyError;
use super::intersample::logged_equivalent;
use crate::discrepancy::{AugmentedModel, Baseline, Record, Restoring};
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
            constant: [0.0; 6],
        })
        .unwrap_or_default()
}

/// The constant load b of a sub-model, as a vector over the modelled DOFs
/// (zero when the model has none).
pub fn load_of(doc: &ModelDocument, point: &LpvPoint) -> nalgebra::DVector<f64> {
    let n = doc.dofs.len();
    match &point.load {
        Some(b) if b.len() == n => nalgebra::DVector::from_column_slice(b),
        _ => nalgebra::DVector::zeros(n),
    }
}

fn matrix(rows: &super::document::Matrix, what: &str) -> Result<DMatrix<f64>, IdentifyError> {
    from_rows(rows)
        .ok_or_else(|| IdentifyError::invalid("document.lpv", format!("{what} is ragged")))
}

/// M and D̄ as the logs see them: with the unlogged commands of a
/// controller faster than the log added back (see
/// [`super::intersample`]); the stored ones otherwise.
fn logged_view(
    doc: &ModelDocument,
    m: DMatrix<f64>,
    d_bar: DMatrix<f64>,
) -> Result<(DMatrix<f64>, DMatrix<f64>), IdentifyError> {
    match doc.lpv.as_ref().and_then(|l| l.logged_controller.as_ref()) {
        Some(lc) => logged_equivalent(&m, &d_bar, lc, &doc.dofs)
            .ok_or_else(super::intersample::malformed_controller),
        None => Ok((m, d_bar)),
    }
}

/// The baseline M ν̇ + D̄ ν = τ − g(η) of one LPV sub-model, as the logs
/// see it.
pub fn baseline_at(doc: &ModelDocument, point: &LpvPoint) -> Result<Baseline, IdentifyError> {
    let mut restoring = restoring_of(doc);
    for (i, d) in doc.dofs.iter().enumerate() {
        restoring.constant[d.index()] = load_of(doc, point)[i];
    }
    let (m, d_bar) = logged_view(doc, matrix(&point.m, "M")?, matrix(&point.d_bar, "D̄")?)?;
    Ok(Baseline {
        dofs: doc.dofs.clone(),
        m,
        d_bar,
        restoring,
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

/// The augmented LPV model as a predictor with u = [τ | η]. Scheduling is
/// by nearest grid point on the measured forward speed smoothed over 10 s
/// (see [`pieces_by_speed`]): each stretch of a run is predicted by its
/// sub-model; a free run carries its simulated state across the switch,
/// and k-step predictions start k samples before the stretch.
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

    fn n(&self) -> usize {
        self.models[0].dofs.len()
    }

    fn pieces(&self, rec: &ValidationRecord<'_>) -> Vec<(usize, usize, usize)> {
        let len = rec.y.nrows();
        match self.surge {
            Some(j) if self.speeds.len() > 1 && len > 0 => {
                let u: Vec<f64> = rec.y.column(j).iter().copied().collect();
                pieces_by_speed(&u, rec.h, &self.speeds)
            }
            _ => vec![(0, len, 0)],
        }
    }

    fn record(&self, rec: &ValidationRecord<'_>, start: usize, end: usize) -> Option<Record> {
        let n = self.n();
        if rec.u.ncols() != n + 6 || rec.y.ncols() != n || rec.u.nrows() != rec.y.nrows() {
            return None;
        }
        Some(Record {
            name: String::new(),
            h: rec.h,
            tau: rec.u.view((start, 0), (end - start, n)).into_owned(),
            nu: rec.y.rows(start, end - start).into_owned(),
            eta: rec.u.view((start, n), (end - start, 6)).into_owned(),
        })
    }
}

/// Maximal stretches [start, end) over which the forward speed `u`,
/// smoothed over 10 s, stays nearest one grid point (the grid index is the
/// third element).
pub fn pieces_by_speed(u: &[f64], h: f64, grid: &[f64]) -> Vec<(usize, usize, usize)> {
    let n = u.len();
    let half = ((5.0 / h).round() as usize).max(1);
    let mut prefix = vec![0.0; n + 1];
    for k in 0..n {
        prefix[k + 1] = prefix[k] + u[k];
    }
    let mut pieces: Vec<(usize, usize, usize)> = Vec::new();
    for k in 0..n {
        let (a, b) = (k.saturating_sub(half), (k + half + 1).min(n));
        let i = super::roles::nearest_grid_index(grid, (prefix[b] - prefix[a]) / (b - a) as f64);
        match pieces.last_mut() {
            Some(last) if last.2 == i => last.1 = k + 1,
            _ => pieces.push((k, k + 1, i)),
        }
    }
    pieces
}

impl Predictor for AugmentedLpv {
    fn output_names(&self) -> Vec<String> {
        self.models[0].output_names()
    }

    fn predict_k_step(&self, rec: &ValidationRecord<'_>, k: usize) -> DMatrix<f64> {
        let (len, n) = (rec.y.nrows(), self.n());
        let mut out = DMatrix::from_element(len, n, f64::NAN);
        for (start, end, i) in self.pieces(rec) {
            let from = start.saturating_sub(k);
            let Some(r) = self.record(rec, from, end) else {
                return out;
            };
            let p = self.models[i].predict_k_step(&r, k);
            for t in start..end {
                for c in 0..n {
                    out[(t, c)] = p[(t - from, c)];
                }
            }
        }
        out
    }

    fn simulate(&self, rec: &ValidationRecord<'_>) -> DMatrix<f64> {
        let (len, n) = (rec.y.nrows(), self.n());
        let mut out = DMatrix::from_element(len, n, f64::NAN);
        for (start, end, i) in self.pieces(rec) {
            // Start one sample early from the simulated state there.
            let from = start.saturating_sub(1);
            let Some(mut r) = self.record(rec, from, end) else {
                return out;
            };
            if start > 0 {
                for c in 0..n {
                    r.nu[(0, c)] = out[(from, c)];
                }
            }
            let s = self.models[i].simulate(&r);
            for t in start..end {
                for c in 0..n {
                    out[(t, c)] = s[(t - from, c)];
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identification::tests::lpv_doc;

    fn doc(d_fast: f64) -> ModelDocument {
        let m = vec![vec![100.0, 0.0], vec![0.0, 50.0]];
        let d = |d: f64| vec![vec![d, 0.0], vec![0.0, 25.0]];
        let mut doc = lpv_doc(
            vec![Dof::Surge, Dof::Yaw],
            vec![(0.5, m.clone(), d(50.0)), (1.5, m, d(d_fast))],
        );
        doc.outputs = vec!["u".into(), "r".into()];
        doc
    }

    /// A run that steps from 0.5 to 1.5 m/s half way: u = [τ | η], y = ν.
    fn run() -> (DMatrix<f64>, DMatrix<f64>) {
        let n = 2000;
        let y = DMatrix::from_fn(n, 2, |k, j| {
            if j == 0 {
                if k < n / 2 { 0.5 } else { 1.5 }
            } else {
                0.1 * (k as f64 * 0.05).sin()
            }
        });
        let u = DMatrix::from_fn(n, 8, |k, j| match j {
            0 => 50.0 * y[(k, 0)] + 20.0 * (k as f64 * 0.1).sin(),
            1 => 5.0 * (k as f64 * 0.07).cos(),
            _ => 0.0,
        });
        (u, y)
    }

    /// With identical sub-models the scheduled free run equals one model's
    /// free run over the whole record: the state is carried across the switch.
    #[test]
    fn free_run_carries_its_state_across_a_grid_switch() {
        let lpv = AugmentedLpv::from_doc(&doc(50.0)).unwrap();
        let (u, y) = run();
        let rec = ValidationRecord {
            h: 0.1,
            u: &u,
            y: &y,
        };
        assert_eq!(lpv.pieces(&rec).len(), 2);
        let scheduled = Predictor::simulate(&lpv, &rec);
        let single = Predictor::simulate(&lpv.models[0], &rec);
        assert!((scheduled - single).abs().max() < 1e-12);
        let k = Predictor::predict_k_step(&lpv, &rec, 10);
        let k1 = Predictor::predict_k_step(&lpv.models[0], &rec, 10);
        assert!((k.rows(10, 1990) - k1.rows(10, 1990)).abs().max() < 1e-12);
    }

    /// Behind a controller twice as fast as the log, discovery's baseline
    /// is the model the logs see, M − c K_ν (K_ν = ∂τ/∂ν < 0), not the
    /// vehicle's M the document stores.
    #[test]
    fn the_baseline_behind_a_faster_controller_is_the_logged_view() {
        use crate::identification::document::LoggedController;
        let mut d = doc(50.0);
        d.lpv.as_mut().unwrap().logged_controller = Some(LoggedController {
            rate_hz: 20.0,
            log_h_s: 0.1,
            c_s: 0.025,
            k_nu: vec![vec![-400.0, 0.0], vec![0.0, -60.0]],
            k_attitude: vec![vec![0.0; 2]; 2],
        });
        let point = d.lpv.as_ref().unwrap().points[0].clone();
        let b = baseline_at(&d, &point).unwrap();
        assert!((b.m[(0, 0)] - 110.0).abs() < 1e-9, "{}", b.m);
        assert!((b.m[(1, 1)] - 51.5).abs() < 1e-9, "{}", b.m);
        assert_eq!(b.d_bar[(0, 0)], 50.0);
        let plain = baseline_at(&doc(50.0), &point).unwrap();
        assert_eq!(plain.m[(0, 0)], 100.0);
        // A malformed controller is a typed error naming the field.
        d.lpv
            .as_mut()
            .unwrap()
            .logged_controller
            .as_mut()
            .unwrap()
            .k_nu = vec![vec![1.0]];
        let e = baseline_at(&d, &point).unwrap_err();
        assert_eq!(e.field(), "document.lpv.logged_controller");
    }

    /// Different damping at 1.5 m/s: the second half follows that sub-model
    /// (steady surge u = τ/d: 0.5 m/s → (50·1.5)/80 in the mean).
    #[test]
    fn each_stretch_is_predicted_by_its_grid_point() {
        let lpv = AugmentedLpv::from_doc(&doc(80.0)).unwrap();
        let (u, y) = run();
        let rec = ValidationRecord {
            h: 0.1,
            u: &u,
            y: &y,
        };
        let sim = Predictor::simulate(&lpv, &rec);
        let tail = sim.view((1600, 0), (400, 1)).mean();
        assert!((tail - 75.0 / 80.0).abs() < 0.02, "{tail}");
        let head = sim.view((600, 0), (400, 1)).mean();
        assert!((head - 0.5).abs() < 0.02, "{head}");
    }
}
