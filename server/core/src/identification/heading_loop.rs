//! A horizontal LPV model in a current fixed in NED, with the heading in the
//! loop: M ν̇_r + C(ν_r)ν_r + D̄ ν_r + b = τ, ψ̇ = r, ν_r = ν − ν_c(ψ)
//! (C only when the model carries C(δ)δ).
//!
//! The current turns with the vessel in the body frame, so a free run
//! integrates ψ from the model's own yaw rate; the measured ψ only starts a
//! prediction. One step holds τ (ZOH) and steps the velocity through the
//! water with the LPV model, scheduled on its forward component u_r; ν is
//! ν_r plus ν_c at the new heading (trapezoid on r). The model was fitted
//! on ν_r ([`super::ned_current::Relative::apply`]), so nothing in the loop
//! depends on M: a mass no run forced (a USV's sway) cannot turn the
//! current's rotation ν̇_c into a wrong force.

use nalgebra::{DMatrix, DVector, Vector2};

use super::ned_current::nu_c_tilted;
use crate::models::predict::no_prediction;
use crate::models::{DiscreteLpv, LpvModel};
use crate::planning::dof::Dof;
use crate::validation::{Predictor, ValidationRecord};

/// See the module docs.
#[derive(Debug, Clone)]
pub struct HeadingLoop {
    lpv: LpvModel,
    /// V = [V_N, V_E] (m/s).
    v: Vector2<f64>,
    surge: usize,
    yaw: usize,
}

impl HeadingLoop {
    /// `None` unless the model has surge and yaw.
    pub fn new(lpv: LpvModel, v: Vector2<f64>) -> Option<Self> {
        let dofs = lpv.dofs();
        let surge = dofs.iter().position(|d| *d == Dof::Surge)?;
        let yaw = dofs.iter().position(|d| *d == Dof::Yaw)?;
        Some(HeadingLoop { lpv, v, surge, yaw })
    }

    /// Names of the record's input columns: the force columns, then ψ.
    pub fn input_names(force_columns: &[String]) -> Vec<String> {
        let mut names = force_columns.to_vec();
        names.push("psi".into());
        names
    }

    fn n(&self) -> usize {
        self.lpv.dofs().len()
    }

    /// ν_c(ψ) in the model's DOF order.
    pub(crate) fn nu_c(&self, psi: f64) -> DVector<f64> {
        self.nu_c_tilted(0.0, 0.0, psi)
    }

    /// ν_c of a hull at roll φ, pitch θ and heading ψ (rad).
    pub(crate) fn nu_c_tilted(&self, phi: f64, theta: f64, psi: f64) -> DVector<f64> {
        nu_c_tilted(self.lpv.dofs(), [self.v[0], self.v[1]], phi, theta, psi)
    }

    /// ν(k+1) and ψ(k+1) from ν(k), ψ(k) and τ(k): the LPV model steps the
    /// velocity through the water ν_r = ν − ν_c(ψ) (the form it was fitted
    /// in, exact for a current constant in NED whatever M is), then
    /// ν(k+1) = ν_r(k+1) + ν_c(ψ(k+1)) with ψ by the trapezoid on r.
    fn step(
        &self,
        lpv: &DiscreteLpv,
        h: f64,
        nu: &DVector<f64>,
        psi: f64,
        tau: &DVector<f64>,
    ) -> (DVector<f64>, f64) {
        let nu_r = nu - self.nu_c(psi);
        let speed = Some(nu_r[self.surge]);
        let next_r = lpv.step_at(&nu_r, tau, self.lpv.scheduling(), speed);
        let psi_next = psi + 0.5 * h * (nu[self.yaw] + next_r[self.yaw]);
        let next = next_r + self.nu_c(psi_next);
        (next, psi_next)
    }

    /// The record's τ and measured ψ, or `None` when it does not fit.
    fn parts(&self, rec: &ValidationRecord<'_>) -> Option<(DMatrix<f64>, Vec<f64>)> {
        let (rows, n) = (rec.y.nrows(), self.n());
        if rec.y.ncols() != n || rec.u.shape() != (rows, n + 1) || rec.h.is_nan() || rec.h <= 0.0 {
            return None;
        }
        if rec.u.iter().chain(rec.y.iter()).any(|v| !v.is_finite()) {
            return None;
        }
        Some((
            rec.u.columns(0, n).into_owned(),
            rec.u.column(n).iter().copied().collect(),
        ))
    }
}

impl Predictor for HeadingLoop {
    fn output_names(&self) -> Vec<String> {
        self.lpv.output_names()
    }

    fn predict_k_step(&self, rec: &ValidationRecord<'_>, k: usize) -> DMatrix<f64> {
        let n = self.n();
        let (Some((tau, psi)), Ok(lpv)) = (self.parts(rec), self.lpv.discretize(rec.h)) else {
            return no_prediction(rec, n);
        };
        let mut out = no_prediction(rec, n);
        if k == 0 {
            return out;
        }
        for t in k..rec.y.nrows() {
            let mut nu = rec.y.row(t - k).transpose();
            let mut p = psi[t - k];
            for i in t - k..t {
                (nu, p) = self.step(&lpv, rec.h, &nu, p, &tau.row(i).transpose());
            }
            out.row_mut(t).copy_from(&nu.transpose());
        }
        out
    }

    fn simulate(&self, rec: &ValidationRecord<'_>) -> DMatrix<f64> {
        let n = self.n();
        let (Some((tau, psi)), Ok(lpv)) = (self.parts(rec), self.lpv.discretize(rec.h)) else {
            return no_prediction(rec, n);
        };
        let rows = rec.y.nrows();
        let mut out = DMatrix::zeros(rows, n);
        if rows == 0 {
            return out;
        }
        let mut nu = rec.y.row(0).transpose();
        let mut p = psi[0];
        out.row_mut(0).copy_from(&nu.transpose());
        for t in 1..rows {
            (nu, p) = self.step(&lpv, rec.h, &nu, p, &tau.row(t - 1).transpose());
            out.row_mut(t).copy_from(&nu.transpose());
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::LinearVesselModel;
    use crate::simulation::integrate::rk4_step;

    const M: [f64; 3] = [100.0, 150.0, 40.0];
    const D: [f64; 3] = [50.0, 120.0, 30.0];

    /// A drifting vessel turning at a constant yaw moment in a current,
    /// integrated by RK4 at 1 ms on M ν̇_r = τ − D ν_r, ν_r = ν − ν_c(ψ),
    /// ψ̇ = r.
    fn drifting(n: usize, h: f64, v: Vector2<f64>, tau_n: f64) -> (Vec<[f64; 4]>, f64) {
        let mut f = |s: &[f64], _: &[f64], d: &mut [f64]| {
            let psi = s[3];
            let nu_c = [
                v[0] * psi.cos() + v[1] * psi.sin(),
                -v[0] * psi.sin() + v[1] * psi.cos(),
                0.0,
            ];
            let tau = [0.0, 0.0, tau_n];
            // ν̇_c = r·[v_c, −u_c, 0] for a current constant in NED.
            let nu_c_dot = [s[2] * nu_c[1], -s[2] * nu_c[0], 0.0];
            for i in 0..3 {
                d[i] = (tau[i] - D[i] * (s[i] - nu_c[i])) / M[i] + nu_c_dot[i];
            }
            d[3] = s[2];
        };
        let mut s = [0.0, 0.0, 0.0, 0.3];
        let fine = 1e-3;
        let per = (h / fine).round() as usize;
        let mut out = Vec::new();
        for _ in 0..n {
            out.push(s);
            for _ in 0..per {
                rk4_step(&mut f, &mut s, &[], fine);
            }
        }
        (out, tau_n)
    }

    #[test]
    fn a_vessel_turning_in_a_current_is_followed_by_its_own_heading() {
        let (h, v) = (0.1, Vector2::new(0.4, -0.3));
        let (states, tau_n) = drifting(600, h, v, 4.5);
        let dofs = Dof::HORIZONTAL.to_vec();
        let d = DMatrix::from_diagonal(&DVector::from_column_slice(&D));
        let point = LinearVesselModel::new(
            dofs.clone(),
            DMatrix::from_diagonal(&DVector::from_column_slice(&M)),
            d.clone(),
        )
        .unwrap();
        let lpv = LpvModel::new(vec![0.0], vec![point]).unwrap();
        let model = HeadingLoop::new(lpv, v).unwrap();
        let rows = states.len();
        let y = DMatrix::from_fn(rows, 3, |k, j| states[k][j]);
        let u = DMatrix::from_fn(rows, 4, |k, j| match j {
            2 => tau_n,
            3 => states[k][3],
            _ => 0.0,
        });
        let rec = ValidationRecord { h, u: &u, y: &y };
        let sim = model.simulate(&rec);
        // The vessel turns through more than a full circle; the current's
        // body-frame push follows it.
        assert!(states[rows - 1][3] - states[0][3] > 2.0 * std::f64::consts::PI);
        for j in 0..3 {
            let scale = states.iter().map(|s| s[j].abs()).fold(0.0, f64::max);
            let worst = (0..rows)
                .map(|k| (sim[(k, j)] - states[k][j]).abs())
                .fold(0.0, f64::max);
            assert!(worst < 0.01 * scale, "{j}: {worst} against {scale}");
        }
        // The measured heading only starts a prediction.
        let mut frozen = u.clone();
        for k in 0..rows {
            frozen[(k, 3)] = states[0][3];
        }
        let open = model.simulate(&ValidationRecord {
            h,
            u: &frozen,
            y: &y,
        });
        assert!((open - &sim).abs().max() < 1e-12);
        // Without the current the same model drifts off.
        let still = HeadingLoop::new(
            LpvModel::new(
                vec![0.0],
                vec![
                    LinearVesselModel::new(
                        dofs.clone(),
                        DMatrix::from_diagonal(&DVector::from_column_slice(&M)),
                        d.clone(),
                    )
                    .unwrap(),
                ],
            )
            .unwrap(),
            Vector2::zeros(),
        )
        .unwrap();
        let off = still.simulate(&rec);
        let worst = (0..rows)
            .map(|k| (off[(k, 0)] - states[k][0]).abs())
            .fold(0.0, f64::max);
        assert!(worst > 0.2, "a current of 0.5 m/s moves surge: {worst}");
    }

    #[test]
    fn records_that_do_not_fit_give_no_prediction() {
        let dofs = Dof::HORIZONTAL.to_vec();
        let point =
            LinearVesselModel::new(dofs, DMatrix::identity(3, 3), DMatrix::identity(3, 3)).unwrap();
        let lpv = LpvModel::new(vec![0.0], vec![point]).unwrap();
        let no_yaw = LinearVesselModel::new(
            vec![Dof::Surge, Dof::Sway],
            DMatrix::identity(2, 2),
            DMatrix::identity(2, 2),
        )
        .unwrap();
        let no_yaw = LpvModel::new(vec![0.0], vec![no_yaw]).unwrap();
        assert!(HeadingLoop::new(no_yaw, Vector2::zeros()).is_none());
        let model = HeadingLoop::new(lpv, Vector2::zeros()).unwrap();
        let y = DMatrix::zeros(10, 3);
        let u = DMatrix::zeros(10, 3);
        let sim = model.simulate(&ValidationRecord {
            h: 0.1,
            u: &u,
            y: &y,
        });
        assert!(sim.iter().all(|v| v.is_nan()));
    }
}
