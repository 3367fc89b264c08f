//! The thesis's linear vessel model M ν̇ + D̄ ν = γ, γ = τ − g(η)
//! (thesis eq. 2.7–2.9), where D̄ lumps damping and Coriolis, in state-space
//! form ν̇ = A ν + B γ with A = −M⁻¹D̄, B = M⁻¹ (eq. 2.10–2.12).

use nalgebra::{DMatrix, DVector};

use super::error::{ModelError, check_finite, check_sample_time};
use super::predict::{check_record, free_run, k_step, no_prediction};
use super::state_space::{DiscreteStateSpace, StateSpace};
use super::structure::{StructureReport, check_structure};
use crate::planning::dof::Dof;
use crate::validation::{Predictor, ValidationRecord};

/// Reciprocal condition number below which M (or B) counts as singular.
const RCOND_MIN: f64 = 1e-13;

/// M ν̇ + D̄ ν + b = γ over the modelled `dofs` (rows and columns of M and
/// D̄ in that order). Inputs are γ = τ − g(η) per DOF, outputs the measured
/// ν. The constant load b (zero unless set) holds what is constant at the
/// operating point: a tether's pull, the heave part of W − B, and the offset
/// of the linearization of the damping about the forward speed.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearVesselModel {
    dofs: Vec<Dof>,
    m: DMatrix<f64>,
    d_bar: DMatrix<f64>,
    a: DMatrix<f64>,
    b: DMatrix<f64>,
    load: DVector<f64>,
}

/// Rejects an empty DOF list or a repeated DOF.
pub(crate) fn check_dofs(dofs: &[Dof]) -> Result<(), ModelError> {
    if dofs.is_empty() {
        return Err(ModelError::Dofs {
            reason: "at least one DOF must be modelled".into(),
        });
    }
    for (i, d) in dofs.iter().enumerate() {
        if dofs[..i].contains(d) {
            return Err(ModelError::Dofs {
                reason: format!("{} appears twice", d.name()),
            });
        }
    }
    Ok(())
}

fn check_square(name: &str, mat: &DMatrix<f64>, n: usize) -> Result<(), ModelError> {
    if mat.shape() != (n, n) {
        return Err(ModelError::Shape {
            name: name.into(),
            expected: format!("{n}×{n} (one row and column per modelled DOF)"),
            found: mat.shape(),
        });
    }
    check_finite(name, mat.iter())
}

/// The inverse of a well-conditioned square matrix, or `None`.
fn robust_inverse(mat: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let sv = mat.clone().svd(false, false).singular_values;
    let (lo, hi) = (sv.min(), sv.max());
    if hi == 0.0 || lo / hi < RCOND_MIN {
        return None;
    }
    mat.clone().try_inverse()
}

impl LinearVesselModel {
    /// A model from M and D̄ (n × n, n = number of `dofs`). M must be
    /// invertible; it need not be symmetric, since identified M often is not
    /// — [`check_structure`](Self::check_structure) reports that.
    pub fn new(dofs: Vec<Dof>, m: DMatrix<f64>, d_bar: DMatrix<f64>) -> Result<Self, ModelError> {
        check_dofs(&dofs)?;
        let n = dofs.len();
        check_square("M", &m, n)?;
        check_square("D̄", &d_bar, n)?;
        let b = robust_inverse(&m).ok_or(ModelError::Singular {
            name: "M".into(),
            why: "B = M⁻¹ (thesis eq. 2.12) does not exist",
        })?;
        let a = -&b * &d_bar;
        check_finite("A = −M⁻¹D̄", a.iter())?;
        Ok(LinearVesselModel {
            load: DVector::zeros(n),
            dofs,
            m,
            d_bar,
            a,
            b,
        })
    }

    /// The same model with the constant load b (one entry per DOF, N or
    /// N·m, finite).
    pub fn with_load(mut self, load: DVector<f64>) -> Result<Self, ModelError> {
        if load.len() != self.dofs.len() {
            return Err(ModelError::Shape {
                name: "b".into(),
                expected: format!("{}×1 (one entry per modelled DOF)", self.dofs.len()),
                found: (load.len(), 1),
            });
        }
        check_finite("b", load.iter())?;
        self.load = load;
        Ok(self)
    }

    /// Constant load b (N, N·m), zero unless set.
    pub fn load(&self) -> &DVector<f64> {
        &self.load
    }

    /// The model from identified A and B: M = B⁻¹, D̄ = −M A (inverting
    /// thesis eq. 2.11–2.12). B singular is an error naming `B`.
    pub fn from_a_b(dofs: Vec<Dof>, a: DMatrix<f64>, b: DMatrix<f64>) -> Result<Self, ModelError> {
        check_dofs(&dofs)?;
        let n = dofs.len();
        check_square("A", &a, n)?;
        check_square("B", &b, n)?;
        let m = robust_inverse(&b).ok_or(ModelError::Singular {
            name: "B".into(),
            why: "M = B⁻¹ (thesis eq. 2.12) does not exist",
        })?;
        let d_bar = -&m * &a;
        Self::new(dofs, m, d_bar)
    }

    /// Modelled DOFs, in row order.
    pub fn dofs(&self) -> &[Dof] {
        &self.dofs
    }
    /// Inertia M (rigid body + added mass), n × n.
    pub fn m(&self) -> &DMatrix<f64> {
        &self.m
    }
    /// Lumped damping and Coriolis D̄, n × n.
    pub fn d_bar(&self) -> &DMatrix<f64> {
        &self.d_bar
    }
    /// A = −M⁻¹D̄ (thesis eq. 2.11).
    pub fn a(&self) -> &DMatrix<f64> {
        &self.a
    }
    /// B = M⁻¹ (thesis eq. 2.12).
    pub fn b(&self) -> &DMatrix<f64> {
        &self.b
    }

    /// ν̇ = A ν + B γ, y = ν (C = I, D = 0).
    pub fn to_state_space(&self) -> StateSpace {
        let n = self.dofs.len();
        // Shapes and finiteness were checked at construction.
        StateSpace::new(
            self.a.clone(),
            self.b.clone(),
            DMatrix::identity(n, n),
            DMatrix::zeros(n, n),
        )
        .expect("shapes are consistent by construction")
    }

    /// ZOH discretization at sample time `h` (s); the load enters as the
    /// constant increment w = −Γ·b.
    pub fn discretize(&self, h: f64) -> Result<DiscreteStateSpace, ModelError> {
        check_sample_time(h)?;
        let d = self.to_state_space().discretize_zoh(h)?;
        let w = -(d.gamma() * &self.load);
        d.with_offset(w)
    }

    /// Physical plausibility: M symmetric positive definite, D̄ dissipative
    /// (see [`StructureReport`]). `tol` (≥ 0) is the relative tolerance for
    /// symmetry and for the sign of the smallest eigenvalue of ½(D̄ + D̄ᵀ).
    pub fn check_structure(&self, tol: f64) -> Result<StructureReport, ModelError> {
        if !(tol.is_finite() && tol >= 0.0) {
            return Err(ModelError::InvalidParameter {
                name: "tol",
                value: tol,
                requirement: "a finite number ≥ 0",
            });
        }
        Ok(check_structure(&self.dofs, &self.m, &self.d_bar, tol))
    }

    /// [`Predictor::predict_k_step`] with the reason when the record does not
    /// fit: u (γ) and y (ν) must be N × n and finite, h > 0, k ≥ 1.
    pub fn try_predict_k_step(
        &self,
        rec: &ValidationRecord<'_>,
        k: usize,
    ) -> Result<DMatrix<f64>, ModelError> {
        let n = self.dofs.len();
        check_record(rec, n, n)?;
        let dss = self.discretize(rec.h)?;
        k_step(rec, k, |x, u| dss.step(x, u))
    }

    /// [`Predictor::simulate`] with the reason when the record does not fit.
    pub fn try_simulate(&self, rec: &ValidationRecord<'_>) -> Result<DMatrix<f64>, ModelError> {
        let n = self.dofs.len();
        check_record(rec, n, n)?;
        let dss = self.discretize(rec.h)?;
        Ok(free_run(rec, |x: &DVector<f64>, u: &DVector<f64>| {
            dss.step(x, u)
        }))
    }
}

/// ν is measured, so the model state at t−k is the recorded ν(t−k); the
/// ZOH-discretized model runs on the recorded γ. A record that does not fit
/// (shapes, NaN, h ≤ 0, k = 0) yields all-NaN predictions; use
/// [`LinearVesselModel::try_predict_k_step`] for the reason.
impl Predictor for LinearVesselModel {
    fn output_names(&self) -> Vec<String> {
        Dof::velocity_symbols(&self.dofs)
    }

    fn predict_k_step(&self, rec: &ValidationRecord<'_>, k: usize) -> DMatrix<f64> {
        self.try_predict_k_step(rec, k)
            .unwrap_or_else(|_| no_prediction(rec, self.dofs.len()))
    }

    fn simulate(&self, rec: &ValidationRecord<'_>) -> DMatrix<f64> {
        self.try_simulate(rec)
            .unwrap_or_else(|_| no_prediction(rec, self.dofs.len()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simulation::integrate::simulate as rk4_simulate;
    use crate::validation::nrmse_fit_columns;

    const DOFS: [Dof; 3] = [Dof::Surge, Dof::Sway, Dof::Yaw];

    /// A coupled, physical 3-DOF model (surge, sway, yaw).
    fn model() -> LinearVesselModel {
        let m = DMatrix::from_row_slice(
            3,
            3,
            &[5000.0, 0.0, 0.0, 0.0, 7000.0, 400.0, 0.0, 400.0, 3000.0],
        );
        let d = DMatrix::from_row_slice(
            3,
            3,
            &[800.0, 0.0, 0.0, 0.0, 1500.0, -200.0, 0.0, 100.0, 900.0],
        );
        LinearVesselModel::new(DOFS.to_vec(), m, d).unwrap()
    }

    /// γ: a different square wave per DOF, and ν from fine RK4 of
    /// M ν̇ + D̄ ν = γ, sampled at h.
    fn record(model: &LinearVesselModel, n: usize, h: f64) -> (DMatrix<f64>, DMatrix<f64>) {
        let u = DMatrix::from_fn(n, 3, |k, j| {
            let period = [37, 23, 51][j];
            let amp = [400.0, 300.0, 150.0][j];
            if (k / period) % 2 == 0 {
                amp
            } else {
                -0.5 * amp
            }
        });
        let sub = 50;
        let fine: Vec<Vec<f64>> = (0..(n - 1) * sub)
            .map(|i| u.row(i / sub).iter().copied().collect())
            .collect();
        let (a, b) = (model.a().clone(), model.b().clone());
        let xs = rk4_simulate(
            |x, g, dx| {
                let xv = DVector::from_column_slice(x);
                let gv = DVector::from_column_slice(g);
                dx.copy_from_slice((&a * xv + &b * gv).as_slice());
            },
            &[0.1, -0.05, 0.02],
            &fine,
            h / sub as f64,
        );
        let y = DMatrix::from_fn(n, 3, |k, j| xs[k * sub][j]);
        (u, y)
    }

    #[test]
    fn a_b_round_trip_and_state_space() {
        let mdl = model();
        let back =
            LinearVesselModel::from_a_b(DOFS.to_vec(), mdl.a().clone(), mdl.b().clone()).unwrap();
        assert!((back.m() - mdl.m()).amax() < 1e-9);
        assert!((back.d_bar() - mdl.d_bar()).amax() < 1e-9);
        // A = −M⁻¹D̄: surge entry −800/5000.
        assert!((mdl.a()[(0, 0)] + 0.16).abs() < 1e-15);
        let ss = mdl.to_state_space();
        assert_eq!(ss.c(), &DMatrix::<f64>::identity(3, 3));
        assert_eq!(ss.d(), &DMatrix::<f64>::zeros(3, 3));
        assert!(ss.eigenvalues().iter().all(|l| l.re < 0.0));
    }

    #[test]
    fn k_step_reproduces_a_noise_free_record() {
        let mdl = model();
        let h = 0.1;
        let (u, y) = record(&mdl, 600, h);
        let rec = ValidationRecord { h, u: &u, y: &y };
        for k in [1, 10, 50] {
            let yh = mdl.predict_k_step(&rec, k);
            assert!(yh.rows(0, k).iter().all(|v| v.is_nan()));
            let err = (yh.rows(k, 600 - k) - y.rows(k, 600 - k)).amax();
            assert!(err < 1e-9, "k = {k}: max error {err}");
            for fit in nrmse_fit_columns(&y, &yh) {
                assert!(fit.unwrap() > 1.0 - 1e-8, "k = {k}: fit {fit:?}");
            }
        }
        let sim = mdl.simulate(&rec);
        assert!((sim - &y).amax() < 1e-9);
    }

    #[test]
    fn a_wrong_model_fits_worse_with_the_horizon() {
        let truth = model();
        let h = 0.1;
        let (u, y) = record(&truth, 600, h);
        let rec = ValidationRecord { h, u: &u, y: &y };
        // Damping halved: one-step predictions still fit well, free run worse.
        let wrong =
            LinearVesselModel::new(DOFS.to_vec(), truth.m().clone(), truth.d_bar() * 0.5).unwrap();
        let fit = |yh: DMatrix<f64>| nrmse_fit_columns(&y, &yh)[0].unwrap();
        let (f1, f10, fsim) = (
            fit(wrong.predict_k_step(&rec, 1)),
            fit(wrong.predict_k_step(&rec, 10)),
            fit(wrong.simulate(&rec)),
        );
        assert!(f1 > 0.9 && f1 < 1.0 - 1e-4, "1-step fit {f1}");
        assert!(f10 < f1 - 0.1 && fsim < f10 - 0.5, "fits {f1} {f10} {fsim}");
    }

    #[test]
    fn bad_input_is_a_typed_error() {
        let m = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 4.0]);
        let err =
            LinearVesselModel::new(vec![Dof::Surge, Dof::Yaw], m.clone(), DMatrix::zeros(2, 2))
                .unwrap_err();
        assert!(err.to_string().starts_with("M is singular"), "{err}");
        let err = LinearVesselModel::from_a_b(vec![Dof::Surge, Dof::Yaw], DMatrix::zeros(2, 2), m)
            .unwrap_err();
        assert!(err.to_string().starts_with("B is singular"), "{err}");
        let err = LinearVesselModel::new(
            vec![Dof::Surge, Dof::Surge],
            DMatrix::identity(2, 2),
            DMatrix::zeros(2, 2),
        )
        .unwrap_err();
        assert_eq!(err.to_string(), "dofs: surge appears twice");
        let err = LinearVesselModel::new(
            vec![Dof::Surge],
            DMatrix::identity(2, 2),
            DMatrix::zeros(2, 2),
        )
        .unwrap_err();
        assert!(
            err.to_string().starts_with("M is 2×2 but must be 1×1"),
            "{err}"
        );

        let mdl = model();
        let (u, y) = record(&mdl, 20, 0.1);
        let rec = ValidationRecord {
            h: 0.1,
            u: &u,
            y: &y,
        };
        assert!(matches!(
            mdl.try_predict_k_step(&rec, 0),
            Err(ModelError::InvalidHorizon { k: 0 })
        ));
        assert!(mdl.predict_k_step(&rec, 0).iter().all(|v| v.is_nan()));
        let short = u.rows(0, 10).into_owned();
        let bad = ValidationRecord {
            h: 0.1,
            u: &short,
            y: &y,
        };
        let err = mdl.try_simulate(&bad).unwrap_err();
        assert!(
            err.to_string().starts_with("u is 10×3 but must be 20×3"),
            "{err}"
        );
        let zero_h = ValidationRecord {
            h: 0.0,
            u: &u,
            y: &y,
        };
        assert!(matches!(
            mdl.try_simulate(&zero_h),
            Err(ModelError::InvalidSampleTime { .. })
        ));
        assert!(
            mdl.check_structure(f64::NAN)
                .unwrap_err()
                .to_string()
                .starts_with("tol = NaN")
        );
    }

    #[test]
    fn structure_of_a_physical_model_is_clean() {
        let report = model().check_structure(1e-9).unwrap();
        assert!(report.is_physical(), "{:?}", report.violations);
        assert!(report.m_symmetric && report.m_positive_definite && report.d_dissipative);
        // D̄[sway,yaw] = −200 vs D̄[yaw,sway] = 100 is noted, not a violation.
        assert_eq!(report.notes.len(), 1);
        assert!(
            report.notes[0].contains("D̄[sway,yaw]"),
            "{}",
            report.notes[0]
        );
    }

    #[test]
    fn structure_flags_the_thesis_coupled_estimate() {
        // Thesis sec. 4.5, coupled Kalman-filter estimate at u = 3.0 kn.
        let m = DMatrix::from_row_slice(
            6,
            6,
            &[
                0.3437, 0.0, -0.4223, 0.0, 0.1433, 0.0, 0.0, 0.2183, 0.0, -0.0014, 0.0, -0.0386,
                0.1496, 0.0, -0.6774, 0.0, 0.0186, 0.0, 0.0, -0.0514, 0.0, -0.0301, 0.0, 0.0091,
                -0.3544, 0.0, 1.0199, 0.0, 0.0111, 0.0, 0.0, -0.0074, 0.0, 0.0, 0.0, 0.2979,
            ],
        ) * 1e5;
        let d = DMatrix::from_row_slice(
            6,
            6,
            &[
                0.4239, 0.0, -1.1815, 0.0, 0.9776, 0.0, 0.0, 0.6001, 0.0, -0.0064, 0.0, -0.0154,
                -0.0303, 0.0, -1.9059, 0.0, 0.3370, 0.0, 0.0, -0.3641, 0.0, -0.0275, 0.0, 0.0036,
                -0.5384, 0.0, 2.877, 0.0, -0.705, 0.0, 0.0, -0.0465, 0.0, 0.0002, 0.0, 0.4986,
            ],
        ) * 1e4;
        let mdl = LinearVesselModel::new(Dof::ALL.to_vec(), m, d).unwrap();
        let r = mdl.check_structure(1e-6).unwrap();
        assert!(!r.m_symmetric && !r.m_positive_definite && !r.d_dissipative);
        assert_eq!(r.violations.len(), 3, "{:#?}", r.violations);
        // Largest |m_ij − m_ji|: pitch/heave, 1.0199e5 vs 0.0186e5.
        assert!(
            r.violations[0].contains("M[heave,pitch]"),
            "{}",
            r.violations[0]
        );
        assert!(
            r.violations[1].contains("M[heave,heave] = -6.7740e4"),
            "{}",
            r.violations[1]
        );
        assert!(
            r.violations[1].contains("M[roll,roll] = -3.0100e3"),
            "{}",
            r.violations[1]
        );
        assert!(
            r.violations[2].contains("D̄[heave,heave] = -1.9059e4"),
            "{}",
            r.violations[2]
        );
        assert!(r.m_min_eigenvalue < 0.0 && r.d_min_eigenvalue < 0.0);
    }
}
