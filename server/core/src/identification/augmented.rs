//! An LPV model with discovered physics (thesis eq. 2.16–2.18 plus the terms
//! of [`crate::discrepancy`]): one [`AugmentedModel`] per grid speed, driven
//! by (τ, η) rather than γ because the added terms may act on τ before it is
//! applied (lag, delay, saturation) or depend on η (restoring, current).

use nalgebra::DMatrix;

use super::document::{LpvPoint, ModelDocument, from_rows};
use super::error::IdentifyError;
use super::intersample::logged_equivalent;
use super::lambda_coriolis::document_inertia;
use super::ned_current::surge_component;
use crate::discrepancy::model::{Drive, State, free_run, k_step};
use crate::discrepancy::{AugmentedModel, Baseline, Effect, Record, Restoring};
use crate::models::predict::no_prediction;
use crate::models::quadratic_damping::QuadraticDamping;
use crate::models::{LpvModel, Scheduling};
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
    let vehicle_m = matrix(&point.m, "M")?;
    let coriolis = doc
        .lpv
        .as_ref()
        .filter(|l| l.coriolis_second_order)
        .map(|l| document_inertia(l).unwrap_or_else(|| vehicle_m.clone()));
    let (m, d_bar) = logged_view(doc, vehicle_m, matrix(&point.d_bar, "D̄")?)?;
    let quadratic = match doc.lpv.as_ref() {
        Some(l) => super::predictor::quadratic_of(l, doc.dofs.len())?.map(|d_q| QuadraticDamping {
            d_q,
            u0: point.speed_mps,
        }),
        None => None,
    };
    Ok(Baseline {
        dofs: doc.dofs.clone(),
        m,
        d_bar,
        restoring,
        coriolis,
        quadratic,
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
        )
        .with_coriolis(b.coriolis)
        .with_quadratic(b.quadratic),
    })
}

/// The augmented LPV model as a predictor with u = [τ | η], scheduled as
/// the baseline's LPV model is (thesis eq. 2.16–2.18): on the model's own
/// forward speed (measured at the start of a prediction, predicted after),
/// each step the blend of the two bracketing sub-models' one-step
/// predictions, beyond the grid within the model's extension the blend of
/// the extension's models at tabulated speeds (D̄ and the load
/// extrapolated, M and the discovered terms of the end grid point). With
/// six DOFs, φ and θ are the model's own. Without its terms it predicts
/// as the baseline does, so the two compare number for number.
pub struct AugmentedLpv {
    /// Ascending speeds (m/s) of `models`: the grid with the extension's
    /// tabulated speeds beyond it.
    speeds: Vec<f64>,
    models: Vec<AugmentedModel>,
    surge: Option<usize>,
    /// Index in `models` of the first grid point (where the model is
    /// scheduled without a surge DOF).
    first_grid: usize,
    /// V = [V_N, V_E] (m/s) of a current the model carries (its first grid
    /// point's term): the model is then scheduled on the forward speed
    /// through the water u − u_c(ψ), as the identification's heading loop.
    current: Option<[f64; 2]>,
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
        let grid: Vec<AugmentedModel> = lpv
            .points
            .iter()
            .map(|p| augmented_at(doc, p))
            .collect::<Result<_, _>>()?;
        let grid_speeds: Vec<f64> = lpv.points.iter().map(|p| p.speed_mps).collect();
        let mut below = Vec::new();
        let mut above = Vec::new();
        if let (Some(ext), true) = (lpv.extension, grid.len() >= 3) {
            let base = super::predictor::baseline_lpv(doc)?;
            let last = grid.len() - 1;
            for (end, edge, out) in [
                (0, ext.from_mps, &mut below),
                (last, ext.to_mps, &mut above),
            ] {
                let g = grid_speeds[end];
                if edge == g {
                    continue;
                }
                for k in 1..=crate::models::lpv::BEYOND_STEPS {
                    let s = g + (edge - g) * k as f64 / crate::models::lpv::BEYOND_STEPS as f64;
                    out.push((s, beyond(&base, &grid[end], s)?));
                }
            }
        }
        let current = grid.iter().find_map(|m| {
            m.terms
                .iter()
                .find(|t| t.effect == Effect::Current && t.coefficients.len() == 2)
                .map(|t| [t.coefficients[0], t.coefficients[1]])
        });
        below.reverse();
        let first_grid = below.len();
        let (speeds, models) = below
            .into_iter()
            .chain(grid_speeds.into_iter().zip(grid))
            .chain(above)
            .unzip();
        Ok(AugmentedLpv {
            speeds,
            models,
            surge: doc.dofs.iter().position(|d| *d == Dof::Surge),
            first_grid,
            current,
        })
    }

    fn n(&self) -> usize {
        self.models[0].dofs.len()
    }

    /// (model index, weight) pairs at forward speed `u`: the bracketing
    /// pair blended linearly, the end model held beyond the table.
    fn weights(&self, u: f64) -> [(usize, f64); 2] {
        let s = &self.speeds;
        let last = s.len() - 1;
        if !u.is_finite() {
            return [(self.first_grid, 1.0), (self.first_grid, 0.0)];
        }
        if u <= s[0] {
            return [(0, 1.0), (0, 0.0)];
        }
        if u >= s[last] {
            return [(last, 1.0), (last, 0.0)];
        }
        let i = s.partition_point(|x| *x <= u) - 1;
        let w = (s[i + 1] - u) / (s[i + 1] - s[i]);
        [(i, w), (i + 1, 1.0 - w)]
    }

    /// One scheduled step k → k+1 from `x`.
    fn step(&self, rec: &Record, drives: &[Drive], k: usize, x: &State) -> State {
        let through_water = |u: f64| match (self.current, rec.eta.get((k, 5))) {
            (Some(v), Some(&psi)) => u - surge_component(v, psi),
            _ => u,
        };
        let pair = match self.surge {
            Some(j) if self.speeds.len() > 1 => self.weights(through_water(x.nu[j])),
            _ => [(self.first_grid, 1.0), (self.first_grid, 0.0)],
        };
        let parts: Vec<(f64, State)> = pair
            .iter()
            .filter(|(_, w)| *w > 0.0)
            .map(|&(i, w)| (w, self.models[i].step(rec, &drives[i], k, x)))
            .collect();
        State::blend(&parts)
    }
}

/// The augmented model at speed `s` beyond the grid: the baseline LPV's
/// extension there (M, D̄, load) with the end grid point's terms.
fn beyond(base: &LpvModel, end: &AugmentedModel, s: f64) -> Result<AugmentedModel, IdentifyError> {
    let lin = base
        .at(s, Scheduling::Interpolate)
        .map_err(|e| IdentifyError::invalid("document.lpv.extension", e.to_string()))?;
    let mut restoring = end.restoring;
    for (i, d) in end.dofs.iter().enumerate() {
        restoring.constant[d.index()] = lin.load()[i];
    }
    Ok(AugmentedModel::new(
        end.dofs.clone(),
        lin.m().clone(),
        lin.d_bar().clone(),
        restoring,
        end.m_ref.clone(),
        end.d_ref.clone(),
        end.terms.clone(),
    )
    .with_coriolis(end.coriolis.clone())
    .with_quadratic(
        end.quadratic
            .clone()
            .map(|q| QuadraticDamping { u0: s, ..q }),
    ))
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
        let Some(r) = Record::from_validation(self.n(), rec) else {
            return no_prediction(rec, self.n());
        };
        let drives: Vec<Drive> = self.models.iter().map(|m| m.drive(&r)).collect();
        let first = &self.models[0];
        k_step(
            &r,
            self.n(),
            k,
            |r, t| first.measured_state(r, t),
            |s, x| self.step(&r, &drives, s, x),
        )
    }

    fn simulate(&self, rec: &ValidationRecord<'_>) -> DMatrix<f64> {
        let Some(r) = Record::from_validation(self.n(), rec) else {
            return no_prediction(rec, self.n());
        };
        let drives: Vec<Drive> = self.models.iter().map(|m| m.drive(&r)).collect();
        let first = &self.models[0];
        free_run(
            &r,
            self.n(),
            |r, t| first.measured_state(r, t),
            |k, x| self.step(&r, &drives, k, x),
        )
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

    /// Damping 50 at 0.5 m/s and 80 at 1.5 m/s, scheduled on the model's own
    /// speed: a steady surge command X = 75 settles where u·d(u) = X with
    /// d(u) = 50 + 30(u − 0.5) blended between the grid points, i.e.
    /// 30u² + 35u − 75 = 0, u = 1.1020 m/s (the nearest point alone would
    /// give 0.9375). Blending the two one-step predictions (thesis eq. 2.18)
    /// rather than the coefficients moves it by O(h·d/m): 1e-3 here.
    #[test]
    fn the_free_run_blends_the_grid_points_on_its_own_speed() {
        let lpv = AugmentedLpv::from_doc(&doc(80.0)).unwrap();
        let (mut u, y) = run();
        for k in 0..u.nrows() {
            u[(k, 0)] = 75.0;
        }
        let rec = ValidationRecord {
            h: 0.1,
            u: &u,
            y: &y,
        };
        let sim = Predictor::simulate(&lpv, &rec);
        let tail = sim.view((1600, 0), (400, 1)).mean();
        let want = (-35.0 + (35.0f64.powi(2) + 4.0 * 30.0 * 75.0).sqrt()) / 60.0;
        assert!((tail - want).abs() < 3e-3, "{tail} vs {want}");
    }

    /// A 6-DOF model with g(η), constant loads, quadratic damping (surge's
    /// as the remainder about each sub-model's speed), three grid points
    /// and an extension below the grid, on a run whose speed ramps through the
    /// extension and the grid: with no terms, the augmented predictor
    /// (attitude in the loop, scheduled on its own speed) predicts as the
    /// baseline's LPV predictor does, so a gate comparing the two measures
    /// the terms and nothing else.
    #[test]
    fn without_terms_it_predicts_as_the_baseline_does() {
        use super::super::document::{PointAugmentation, RestoringDoc, SpeedExtension};
        use crate::estimation::restoring::RestoringParams;
        let diag = |v: [f64; 6]| -> Vec<Vec<f64>> {
            (0..6)
                .map(|i| (0..6).map(|j| if i == j { v[i] } else { 0.0 }).collect())
                .collect()
        };
        let m = diag([1200.0, 1500.0, 1600.0, 300.0, 350.0, 250.0]);
        let d = |s: f64| {
            diag([
                200.0 + 300.0 * s,
                400.0,
                500.0,
                150.0,
                180.0,
                120.0 + 40.0 * s,
            ])
        };
        let mut base = lpv_doc(
            Dof::ALL.to_vec(),
            vec![
                (0.5, m.clone(), d(0.5)),
                (1.0, m.clone(), d(1.0)),
                (1.5, m, d(1.5)),
            ],
        );
        for (i, p) in base.lpv.as_mut().unwrap().points.iter_mut().enumerate() {
            p.load = Some(vec![-20.0 * i as f64, 5.0, 30.0, 0.0, -4.0, 1.0]);
        }
        base.lpv.as_mut().unwrap().extension = Some(SpeedExtension {
            from_mps: 0.1,
            to_mps: 1.5,
        });
        base.lpv.as_mut().unwrap().quadratic_damping =
            Some(vec![150.0, 300.0, 250.0, 40.0, 50.0, 30.0]);
        base.restoring = Some(RestoringDoc {
            parameters: vec![],
            evidence: vec![],
            params: RestoringParams {
                weight_minus_buoyancy_n: 40.0,
                zg_weight_minus_zb_buoyancy_nm: 600.0,
                tether_pitch_moment_nm: 0.0,
            },
        });
        base.inputs = (0..6).map(|i| format!("tau{i}")).collect();
        base.outputs = Dof::velocity_symbols(&Dof::ALL);
        let mut aug = base.clone();
        aug.inputs
            .extend(["x", "y", "z", "phi", "theta", "psi"].map(String::from));
        for p in &mut aug.lpv.as_mut().unwrap().points {
            p.augmentation = Some(PointAugmentation {
                m_ref: p.m.clone(),
                d_ref: p.d_bar.clone(),
                terms: vec![],
            });
        }
        // Surge thrust ramping the speed from ≈ 0.15 to ≈ 1.4 m/s, the
        // other DOFs excited by sines; ν and η as logged (roughly).
        let n = 3000;
        let h = 0.1;
        let tau = DMatrix::from_fn(n, 6, |k, j| {
            let t = k as f64 * h;
            match j {
                0 => 60.0 + 1000.0 * t / 300.0 + 40.0 * (0.3 * t).sin(),
                _ => 50.0 * ((0.2 + 0.07 * j as f64) * t).sin(),
            }
        });
        let y = DMatrix::from_fn(n, 6, |k, j| {
            let t = k as f64 * h;
            if j == 0 {
                0.15 + 1.25 * t / 300.0
            } else {
                0.02 * (0.25 * t).sin()
            }
        });
        let eta = DMatrix::from_fn(n, 6, |k, j| {
            let t = k as f64 * h;
            match j {
                3 | 4 => 0.03 * (0.21 * t + j as f64).sin(),
                5 => 0.1 * t,
                _ => 0.0,
            }
        });
        let mut u = DMatrix::zeros(n, 12);
        u.columns_mut(0, 6).copy_from(&tau);
        u.columns_mut(6, 6).copy_from(&eta);
        let rec = ValidationRecord { h, u: &u, y: &y };
        let want = crate::identification::predictor::predictor(&base).unwrap();
        let got = AugmentedLpv::from_doc(&aug).unwrap();
        assert_eq!(got.speeds.len(), 3 + crate::models::lpv::BEYOND_STEPS);
        let (sw, sg) = (want.simulate(&rec), Predictor::simulate(&got, &rec));
        let (kw, kg) = (
            want.predict_k_step(&rec, 10),
            Predictor::predict_k_step(&got, &rec, 10),
        );
        assert!(
            sw.column(0).min() < 0.45 && sw.column(0).max() > 1.2,
            "ramp: {}",
            sw.column(0).max()
        );
        for j in 0..6 {
            let scale = sw.column(j).amax();
            let ds = (sw.column(j) - sg.column(j)).amax();
            let dk = (kw.column(j).rows(10, n - 10) - kg.column(j).rows(10, n - 10)).amax();
            assert!(
                ds < 0.01 * scale && dk < 0.01 * scale,
                "DOF {j}: free run {ds}, 10-step {dk}, scale {scale}"
            );
        }
    }
}
