//! A subspace (N4SID) model as validation sees it: its state is not
//! measured, so each restarted free run starts from the innovation-form
//! Kalman predictor's x̂(s | s−1) — the state the model itself holds at s
//! from the record up to s − 1 — rather than from a fit to the window's own
//! samples.

use nalgebra::{DMatrix, DVector};

use crate::estimation::n4sid::N4sidModel;
use crate::validation::{Predictor, ValidationRecord, restart_windows};

/// An N4SID model whose restarted free runs start from its Kalman predictor.
#[derive(Debug, Clone)]
pub struct StateSpacePredictor(pub N4sidModel);

impl Predictor for StateSpacePredictor {
    fn output_names(&self) -> Vec<String> {
        self.0.output_names()
    }

    fn predict_k_step(&self, rec: &ValidationRecord<'_>, k: usize) -> DMatrix<f64> {
        self.0.predict_k_step(rec, k)
    }

    fn simulate(&self, rec: &ValidationRecord<'_>) -> DMatrix<f64> {
        self.0.simulate(rec)
    }

    /// x̂(0 | −1) is the least-squares initial state of the record (as for
    /// the k-step predictions); x̂(t+1 | t) = Φx̂ + Γu + K(y − Cx̂ − Du).
    fn simulate_restarted(&self, rec: &ValidationRecord<'_>, every: usize) -> DMatrix<f64> {
        let m = &self.0;
        let (n, l) = (rec.y.nrows(), m.outputs());
        let mut out = DMatrix::from_element(n, l, f64::NAN);
        if rec.u.ncols() != m.inputs() || rec.y.ncols() != l || rec.u.nrows() != n {
            return out;
        }
        let mut filtered = m.estimate_initial_state(rec.u, rec.y);
        let mut start = 0;
        for (s, e) in restart_windows(n, every) {
            // The predictor's state at s from the samples before s.
            for t in start..s {
                let u = rec.u.row(t).transpose();
                let innovation = rec.y.row(t).transpose() - &m.c * &filtered - &m.d * &u;
                filtered = &m.a * &filtered + &m.b * &u + &m.k * innovation;
            }
            start = s;
            let mut x: DVector<f64> = filtered.clone();
            for t in s..e {
                let u = rec.u.row(t).transpose();
                let yt = &m.c * &x + &m.d * &u;
                out.row_mut(t).copy_from(&yt.transpose());
                x = &m.a * x + &m.b * u;
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::estimation::n4sid::{NoiseCovariances, Weighting};

    /// x⁺ = 0.9x + u, y = x, K = 0.9 (a predictor that copies the last
    /// measurement: x̂(t+1|t) = 0.9·y(t) + u(t)).
    fn first_order() -> N4sidModel {
        let one = |v: f64| DMatrix::from_element(1, 1, v);
        N4sidModel {
            a: one(0.9),
            b: one(1.0),
            c: one(1.0),
            d: one(0.0),
            k: one(0.9),
            h: 0.1,
            order: 1,
            horizon: 0,
            weighting: Weighting::default(),
            singular_values: vec![1.0],
            noise: NoiseCovariances {
                q: one(0.0),
                s: one(0.0),
                r: one(0.0),
            },
            innovation_covariance: one(0.0),
            state_covariance: one(0.0),
            hankel_columns: 0,
            output_names: vec!["u".into()],
        }
    }

    #[test]
    fn each_window_starts_from_the_predictor_state_then_runs_open_loop() {
        let n = 30;
        let u = DMatrix::from_fn(n, 1, |t, _| ((t * 7) % 5) as f64 - 2.0);
        // A measurement the model does not explain: y = t.
        let y = DMatrix::from_fn(n, 1, |t, _| t as f64);
        let rec = ValidationRecord {
            h: 0.1,
            u: &u,
            y: &y,
        };
        let out = StateSpacePredictor(first_order()).simulate_restarted(&rec, 10);
        // With K = Φ the predictor state at s is 0.9·y(s−1) + u(s−1).
        for s in [10, 20] {
            let mut x = 0.9 * y[(s - 1, 0)] + u[(s - 1, 0)];
            for t in s..s + 10 {
                assert!((out[(t, 0)] - x).abs() < 1e-12, "row {t}");
                x = 0.9 * x + u[(t, 0)];
            }
        }
    }
}
