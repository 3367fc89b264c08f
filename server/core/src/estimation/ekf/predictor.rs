//! The identified DP ship as a validation [`Predictor`]: outputs x, y, ψ.
//!
//! - k-step prediction: the unmeasured momentum h = M·ν and the bias b_h are
//!   not in the record, so a Kalman pass of the same momentum model with θ″
//!   frozen (the EKF of [`super::filter`] with no parameters) estimates
//!   x̂(t−k | t−k) = [ĥ; η̂; b̂_h] from the measured η up to t−k; the model is
//!   then run k steps on the recorded u with b̂_h held.
//! - free run: from the record's first pose η(0) at rest (h = 0, as the sea
//!   trials start) with zero bias, on the inputs alone.
//!
//! Units are the model's (Bis for the supply vessel): `rec.h` is the sample
//! time in Bis time, η in ship lengths and radians.

use nalgebra::{DMatrix, Vector3};

use super::dp_model::{DP_STATES, DpMomentumModel};
use super::filter::{EkfSettings, RunData, parallel_ekf};
use super::model::Rk4;
use crate::estimation::NoProgress;
use crate::simulation::dp_ship::model::{DpShip, rotation};
use crate::simulation::integrate::rk4_step;
use crate::validation::{Predictor, ValidationRecord};

/// An identified DP ship with the noise model of its state estimator.
#[derive(Debug, Clone, PartialEq)]
pub struct IdentifiedDpShip {
    /// M, T and the identified A_h, K.
    pub ship: DpShip,
    /// Measurement variances of x, y, ψ.
    pub r: [f64; 3],
    /// Initial momentum variance.
    pub p0_h: [f64; 3],
    /// Initial bias variance.
    pub p0_b: [f64; 3],
    /// Process noise on h per sample.
    pub q_h: [f64; 3],
    /// Bias random walk per sample.
    pub q_b: [f64; 3],
}

impl IdentifiedDpShip {
    /// Filtered states x̂(t|t) = [ĥ, η̂, b̂_h] (N × 9) of a record, θ″ frozen;
    /// `None` if the record is unusable (shapes, NaN).
    pub fn estimate_states(&self, rec: &ValidationRecord<'_>) -> Option<DMatrix<f64>> {
        let model = Rk4 {
            model: DpMomentumModel::new(
                self.ship.m,
                self.ship.thrust.clone(),
                self.ship.theta(),
                Vec::new(),
            ),
            h: rec.h,
        };
        if rec.y.ncols() != 3 || rec.y.nrows() == 0 {
            return None;
        }
        let mut x0 = vec![0.0; DP_STATES];
        for j in 0..3 {
            x0[3 + j] = rec.y[(0, j)];
        }
        let cat = |a: &[f64; 3], b: &[f64; 3], c: &[f64; 3]| [a.as_slice(), b, c].concat();
        let settings = EkfSettings {
            x0: vec![x0],
            theta0: Vec::new(),
            p0_x: cat(&self.p0_h, &self.r, &self.p0_b),
            p0_theta: Vec::new(),
            q_x: cat(&self.q_h, &[0.0; 3], &self.q_b),
            q_theta: Vec::new(),
            r: self.r.to_vec(),
        };
        let run = RunData { u: rec.u, z: rec.y };
        parallel_ekf(
            &model,
            &[run],
            &settings,
            "state estimation",
            &mut NoProgress,
        )
        .ok()
        .map(|out| out.states.into_iter().next().expect("one run"))
    }

    /// Runs the model from state [h; η] with bias `b` over inputs rows
    /// `from..to` of `u`; returns η at `to`.
    fn run(
        &self,
        state: [f64; 6],
        b: Vector3<f64>,
        u: &DMatrix<f64>,
        from: usize,
        to: usize,
        h: f64,
    ) -> [f64; 3] {
        let m_inv = self.ship.m_inv();
        let mut x = state;
        let mut f = |s: &[f64], w: &[f64], dx: &mut [f64]| {
            let hm = Vector3::new(s[0], s[1], s[2]);
            let hd = self.ship.h_dot(&m_inv, &hm, w, &b);
            let eta_dot = rotation(s[5]) * (m_inv * hm);
            dx[..3].copy_from_slice(hd.as_slice());
            dx[3..].copy_from_slice(eta_dot.as_slice());
        };
        let mut w = vec![0.0; self.ship.k.len()];
        for k in from..to {
            for (j, v) in w.iter_mut().enumerate() {
                *v = u[(k, j)];
            }
            rk4_step(&mut f, &mut x, &w, h);
        }
        [x[3], x[4], x[5]]
    }
}

impl Predictor for IdentifiedDpShip {
    fn output_names(&self) -> Vec<String> {
        vec!["x".into(), "y".into(), "psi".into()]
    }

    fn predict_k_step(&self, rec: &ValidationRecord<'_>, k: usize) -> DMatrix<f64> {
        let n = rec.y.nrows();
        let mut out = DMatrix::from_element(n, 3, f64::NAN);
        let Some(states) = self.estimate_states(rec) else {
            return out;
        };
        let k = k.max(1);
        for t in k..n {
            let s = states.row(t - k);
            let start = [s[0], s[1], s[2], s[3], s[4], s[5]];
            let b = Vector3::new(s[6], s[7], s[8]);
            let eta = self.run(start, b, rec.u, t - k, t, rec.h);
            for j in 0..3 {
                out[(t, j)] = eta[j];
            }
        }
        out
    }

    fn simulate(&self, rec: &ValidationRecord<'_>) -> DMatrix<f64> {
        let n = rec.y.nrows();
        let mut out = DMatrix::from_element(n, 3, f64::NAN);
        let r = self.ship.k.len();
        if n == 0 || rec.y.ncols() != 3 || rec.u.ncols() != r || rec.u.nrows() != n {
            return out;
        }
        let m_inv = self.ship.m_inv();
        let zero = Vector3::zeros();
        let mut x = [0.0, 0.0, 0.0, rec.y[(0, 0)], rec.y[(0, 1)], rec.y[(0, 2)]];
        let mut f = |s: &[f64], w: &[f64], dx: &mut [f64]| {
            let hm = Vector3::new(s[0], s[1], s[2]);
            let hd = self.ship.h_dot(&m_inv, &hm, w, &zero);
            let eta_dot = rotation(s[5]) * (m_inv * hm);
            dx[..3].copy_from_slice(hd.as_slice());
            dx[3..].copy_from_slice(eta_dot.as_slice());
        };
        let mut w = vec![0.0; r];
        for t in 0..n {
            for j in 0..3 {
                out[(t, j)] = x[3 + j];
            }
            for (j, v) in w.iter_mut().enumerate() {
                *v = rec.u[(t, j)];
            }
            rk4_step(&mut f, &mut x, &w, rec.h);
        }
        out
    }
}
