//! A stored model back as a predictor, and a run as that model's validation
//! record — so any model can be validated on any run later (side-by-side
//! comparison of two models on the same run).

use nalgebra::{DMatrix, DVector, Matrix3};

use super::attitude_loop::AttitudeLoop;
use super::augmented::{AugmentedLpv, is_augmented};
use super::bis::{BisScale, SiDpShip, unwrap_heading};
use super::dataset::{RunInput, level_attitude, segments};
use super::document::{ModelDocument, ModelKind, from_rows};
use super::error::IdentifyError;
use super::heading_loop::HeadingLoop;
use super::intersample::logged_equivalent;
use super::state_space::StateSpacePredictor;
use crate::estimation::ekf::IdentifiedDpShip;
use crate::estimation::n4sid::{N4sidModel, NoiseCovariances, Weighting};
use crate::estimation::restoring::RestoringParams;
use crate::logs::schema::pose_column;
use crate::models::{LinearVesselModel, LpvModel};
use crate::planning::dof::Dof;
use crate::simulation::dp_ship::{DpShip, N_GROUPS, ThrustLayout};
use crate::validation::{
    Predictor, ValidationRecord, ValidationReport, ValidationSettings, validate,
};

fn matrix(rows: &super::document::Matrix, what: &str) -> Result<DMatrix<f64>, IdentifyError> {
    from_rows(rows).ok_or_else(|| IdentifyError::invalid("document", format!("{what} is ragged")))
}

/// g(η) when a stored model simulates its own attitude ([`AttitudeLoop`]):
/// a 6-DOF LPV model with estimated restoring and no discovered terms.
fn attitude_in_loop(doc: &ModelDocument) -> Option<RestoringParams> {
    let eligible = doc.kind == ModelKind::Lpv && !is_augmented(doc) && doc.dofs == Dof::ALL;
    doc.restoring
        .as_ref()
        .filter(|_| eligible)
        .map(|r| r.params)
}

/// V = [V_N, V_E] (m/s) when a stored LPV model carries a current fixed
/// in NED (and no discovered terms): validated with ψ in the loop.
fn current_in_loop(doc: &ModelDocument) -> Option<nalgebra::Vector2<f64>> {
    let lpv = doc.lpv.as_ref()?;
    if doc.kind != ModelKind::Lpv || is_augmented(doc) {
        return None;
    }
    let v = lpv.current.as_ref()?.ned_mps;
    Some(nalgebra::Vector2::new(v[0], v[1]))
}

/// The predictor of a stored model.
pub fn predictor(doc: &ModelDocument) -> Result<Box<dyn Predictor>, IdentifyError> {
    match doc.kind {
        ModelKind::Lpv if is_augmented(doc) => Ok(Box::new(AugmentedLpv::from_doc(doc)?)),
        ModelKind::Lpv => {
            let model = baseline_lpv(doc)?;
            if let (Some(g), Some(v)) = (attitude_in_loop(doc), current_in_loop(doc)) {
                return AttitudeLoop::with_current(model, g, v)
                    .map(|m| Box::new(m) as Box<dyn Predictor>)
                    .ok_or_else(|| {
                        IdentifyError::invalid(
                            "document.lpv.current",
                            "a current needs the six DOFs with g(η)",
                        )
                    });
            }
            if let Some(v) = current_in_loop(doc) {
                return HeadingLoop::new(model, v)
                    .map(|m| Box::new(m) as Box<dyn Predictor>)
                    .ok_or_else(|| {
                        IdentifyError::invalid(
                            "document.lpv.current",
                            "a current needs surge and yaw",
                        )
                    });
            }
            match attitude_in_loop(doc) {
                Some(g) => Ok(Box::new(
                    AttitudeLoop::new(model, g).expect("attitude_in_loop checked the DOFs"),
                )),
                None => Ok(Box::new(model)),
            }
        }
        ModelKind::StateSpace => {
            let s = doc
                .state_space
                .as_ref()
                .ok_or_else(|| IdentifyError::invalid("document.state_space", "missing"))?;
            let (a, c) = (matrix(&s.phi, "Φ")?, matrix(&s.c, "C")?);
            let (n, l) = (a.nrows(), c.nrows());
            Ok(Box::new(StateSpacePredictor(N4sidModel {
                a,
                b: matrix(&s.gamma, "Γ")?,
                c,
                d: matrix(&s.d, "D")?,
                k: matrix(&s.k, "K")?,
                h: s.h,
                order: s.order,
                horizon: 0,
                weighting: Weighting::default(),
                singular_values: s.singular_values.clone(),
                noise: NoiseCovariances {
                    q: DMatrix::zeros(n, n),
                    s: DMatrix::zeros(n, l),
                    r: DMatrix::zeros(l, l),
                },
                innovation_covariance: DMatrix::zeros(l, l),
                state_covariance: DMatrix::zeros(n, n),
                hankel_columns: 0,
                output_names: doc.outputs.clone(),
            })))
        }
        ModelKind::DpShip => Ok(Box::new(dp_ship(doc)?)),
    }
}

/// The LPV model of a stored LPV document's M, D̄ and loads (as the logs
/// see them behind a controller faster than the log), with its extension.
pub(crate) fn baseline_lpv(doc: &ModelDocument) -> Result<LpvModel, IdentifyError> {
    let lpv = doc
        .lpv
        .as_ref()
        .ok_or_else(|| IdentifyError::invalid("document.lpv", "missing"))?;
    let mut models = Vec::new();
    let mut vehicle_m = Vec::new();
    for p in &lpv.points {
        let (m, d_bar) = (matrix(&p.m, "M")?, matrix(&p.d_bar, "D̄")?);
        vehicle_m.push(m.clone());
        // Predictions on logs of a controller faster than the log add its
        // unlogged commands back.
        let (m, d_bar) = match &lpv.logged_controller {
            Some(lc) => logged_equivalent(&m, &d_bar, lc, &doc.dofs)
                .ok_or_else(super::intersample::malformed_controller)?,
            None => (m, d_bar),
        };
        models.push(
            LinearVesselModel::new(doc.dofs.clone(), m, d_bar)
                .and_then(|m| m.with_load(super::augmented::load_of(doc, p)))
                .map_err(|e| IdentifyError::invalid("document.lpv", e.to_string()))?,
        );
    }
    let speeds = lpv.points.iter().map(|p| p.speed_mps).collect();
    let model = LpvModel::new(speeds, models)
        .map_err(|e| IdentifyError::invalid("document.lpv", e.to_string()))?;
    let model = if lpv.coriolis_second_order {
        let vehicle_m = match super::lambda_coriolis::document_inertia(lpv) {
            Some(m) => vec![m; vehicle_m.len()],
            None => vehicle_m,
        };
        model.with_second_order_coriolis(vehicle_m).map_err(|e| {
            IdentifyError::invalid("document.lpv.coriolis_second_order", e.to_string())
        })?
    } else {
        model
    };
    let model = match quadratic_of(lpv, doc.dofs.len())? {
        Some(d_q) => model
            .with_quadratic_damping(vec![d_q; lpv.points.len()])
            .map_err(|e| IdentifyError::invalid("document.lpv.quadratic_damping", e.to_string()))?,
        None => model,
    };
    match lpv.extension {
        Some(e) => model
            .with_extension(e.into())
            .map_err(|e| IdentifyError::invalid("document.lpv.extension", e.to_string())),
        None => Ok(model),
    }
}

/// D_q of `lpv` (`n` entries), if it carries quadratic damping.
pub(crate) fn quadratic_of(
    lpv: &super::document::LpvDoc,
    n: usize,
) -> Result<Option<nalgebra::DVector<f64>>, IdentifyError> {
    match &lpv.quadratic_damping {
        None => Ok(None),
        Some(d) if d.len() == n => Ok(Some(nalgebra::DVector::from_column_slice(d))),
        Some(d) => Err(IdentifyError::invalid(
            "document.lpv.quadratic_damping",
            format!("{} entries for {n} DOFs", d.len()),
        )),
    }
}

/// The SI predictor of a stored DP-ship document.
pub fn dp_ship(doc: &ModelDocument) -> Result<SiDpShip, IdentifyError> {
    let s = doc
        .dp_ship
        .as_ref()
        .ok_or_else(|| IdentifyError::invalid("document.dp_ship", "missing"))?;
    let three = |v: &[f64], what: &str| -> Result<[f64; 3], IdentifyError> {
        v.try_into().map_err(|_| {
            IdentifyError::invalid("document.dp_ship.noise", format!("{what} needs 3 entries"))
        })
    };
    let (m, t, a_h) = (
        matrix(&s.m, "M")?,
        matrix(&s.t_config, "T")?,
        matrix(&s.a_h, "A_h")?,
    );
    if m.shape() != (3, 3) || a_h.shape() != (3, 3) || t.nrows() != 3 || s.k.len() != t.ncols() {
        return Err(IdentifyError::invalid(
            "document.dp_ship",
            "M and A_h must be 3 × 3, T 3 × r and K of length r",
        ));
    }
    let groups = groups_of(&s.k).ok_or_else(|| {
        IdentifyError::invalid(
            "document.dp_ship.k",
            format!("K takes more than {N_GROUPS} distinct values"),
        )
    })?;
    Ok(SiDpShip {
        model: IdentifiedDpShip {
            ship: DpShip {
                m: Matrix3::from_fn(|i, j| m[(i, j)]),
                thrust: ThrustLayout { t, groups },
                a_h: Matrix3::from_fn(|i, j| a_h[(i, j)]),
                k: DVector::from_column_slice(&s.k),
            },
            r: three(&s.noise.r, "r")?,
            p0_h: three(&s.noise.p0_h, "p0_h")?,
            p0_b: three(&s.noise.p0_b, "p0_b")?,
            q_h: three(&s.noise.q_h, "q_h")?,
            q_b: three(&s.noise.q_b, "q_b")?,
        },
        scale: BisScale {
            length_m: s.length_m,
            time_unit_s: s.time_unit_s,
        },
    })
}

/// The coefficient groups of a stored K (one per column): columns with the
/// same K″ share a group, which is how the identification wrote them.
fn groups_of(k: &[f64]) -> Option<Vec<usize>> {
    let mut values: Vec<f64> = Vec::new();
    k.iter()
        .map(|v| match values.iter().position(|w| w == v) {
            Some(g) => Some(g),
            None if values.len() < N_GROUPS => {
                values.push(*v);
                Some(values.len() - 1)
            }
            None => None,
        })
        .collect()
}

/// The longest valid block of `run` as the model's validation data:
/// γ = τ − g(η) and ν for an LPV model, [τ | η] and ν for one with
/// discovered terms, deviations from the operating point for a subspace
/// model, thruster commands and (x, y, ψ unwrapped) for a DP ship. `inputs`
/// are the force columns in DOF order (a DP ship uses its own `doc.inputs`,
/// the thruster commands).
pub fn validation_data(
    doc: &ModelDocument,
    run: &RunInput,
    inputs: &[String],
) -> Result<(f64, DMatrix<f64>, DMatrix<f64>), IdentifyError> {
    if doc.kind == ModelKind::DpShip {
        let segs = segments(run, &doc.inputs, &doc.outputs, 50)
            .map_err(|e| IdentifyError::invalid(format!("runs[{}]", e.run_id), e.to_string()))?;
        let seg = segs
            .into_iter()
            .max_by_key(|s| s.y.nrows())
            .expect("segments is non-empty");
        let mut y = seg.y;
        if y.ncols() == 3 {
            let mut psi: Vec<f64> = y.column(2).iter().copied().collect();
            unwrap_heading(&mut psi);
            y.set_column(2, &nalgebra::DVector::from_vec(psi));
        }
        return Ok((seg.h, seg.u, y));
    }
    let n = doc.dofs.len();
    let run = level_attitude(run, &doc.dofs);
    let run = &*run;
    let outputs: Vec<String> = Dof::velocity_symbols(&doc.dofs);
    let restoring = doc.restoring.as_ref().map(|r| r.params);
    let augmented = is_augmented(doc);
    let mut cols = inputs.to_vec();
    let current = current_in_loop(doc).is_some();
    if restoring.is_some() || augmented {
        cols.extend(Dof::ALL.iter().map(|d| pose_column(*d).to_string()));
    } else if current {
        cols.push(pose_column(Dof::Yaw).to_string());
    }
    let segs = segments(run, &cols, &outputs, 50)
        .map_err(|e| IdentifyError::invalid(format!("runs[{}]", e.run_id), e.to_string()))?;
    let seg = segs
        .iter()
        .max_by_key(|s| s.y.nrows())
        .expect("segments is non-empty");
    let tau = seg.u.columns(0, n).into_owned();
    if augmented || attitude_in_loop(doc).is_some() {
        return Ok((seg.h, seg.u.columns(0, n + 6).into_owned(), seg.y.clone()));
    }
    if current {
        return Ok((seg.h, seg.u.columns(0, n + 1).into_owned(), seg.y.clone()));
    }
    match doc.kind {
        ModelKind::StateSpace => {
            let s = doc.state_space.as_ref().expect("checked by predictor()");
            let shift = |m: &DMatrix<f64>, off: &[f64]| {
                DMatrix::from_fn(m.nrows(), m.ncols(), |i, j| {
                    m[(i, j)] - off.get(j).copied().unwrap_or(0.0)
                })
            };
            Ok((seg.h, shift(&tau, &s.u_offset), shift(&seg.y, &s.y_offset)))
        }
        _ => {
            let gamma = match restoring {
                Some(r) => r
                    .gamma(&tau, &seg.u.columns(n, 6).into_owned())
                    .map_err(|e| {
                        IdentifyError::invalid(format!("runs[{}]", run.run_id), e.to_string())
                    })?,
                None => tau,
            };
            Ok((seg.h, gamma, seg.y.clone()))
        }
    }
}

/// Validates a stored model on one run with horizon `k` (other settings
/// default).
pub fn validate_on_run(
    doc: &ModelDocument,
    run: &RunInput,
    inputs: &[String],
    k: usize,
) -> Result<ValidationReport, IdentifyError> {
    let settings = ValidationSettings {
        k,
        ..ValidationSettings::default()
    };
    validate_on_run_with(doc, run, inputs, settings)
}

/// Validates a stored model on one run with `settings` (the input names
/// are the model's own).
pub fn validate_on_run_with(
    doc: &ModelDocument,
    run: &RunInput,
    inputs: &[String],
    settings: ValidationSettings,
) -> Result<ValidationReport, IdentifyError> {
    let model = predictor(doc)?;
    let (h, u, y) = validation_data(doc, run, inputs)?;
    let input_names = match (attitude_in_loop(doc), current_in_loop(doc)) {
        (Some(_), _) => AttitudeLoop::input_names(inputs),
        (None, Some(_)) => HeadingLoop::input_names(&doc.inputs),
        (None, None) => doc.inputs.clone(),
    };
    let settings = ValidationSettings {
        input_names,
        ..settings
    };
    validate(
        model.as_ref(),
        &ValidationRecord { h, u: &u, y: &y },
        &settings,
    )
    .map_err(|e| IdentifyError::invalid(format!("runs[{}]", run.run_id), e.to_string()))
}
