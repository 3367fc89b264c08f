//! The one interface every identified model offers to validation.
//!
//! Convention: a record's signals are matrices with one row per sample and one
//! column per channel (N × m inputs, N × p outputs), column-major, so each
//! channel is a contiguous slice.

use nalgebra::DMatrix;

/// A recorded run on a uniform grid, as validation sees it.
#[derive(Debug, Clone, Copy)]
pub struct ValidationRecord<'a> {
    /// Sample time h (s).
    pub h: f64,
    /// Inputs, N × m (e.g. γ = τ − g(η), or thruster commands u).
    pub u: &'a DMatrix<f64>,
    /// Measured outputs, N × p (e.g. ν, or η for a DP ship).
    pub y: &'a DMatrix<f64>,
}

/// A model that predicts the outputs of a record from its inputs.
pub trait Predictor {
    /// Names of the output channels, in column order of `y`.
    fn output_names(&self) -> Vec<String>;

    /// k-step-ahead predictions ŷ(t | t−k) (k ≥ 1), N × p: the model is
    /// started from the measured (or estimated) state at t−k and run k steps on
    /// the recorded inputs. Rows t < k are NaN (no prediction exists).
    fn predict_k_step(&self, rec: &ValidationRecord<'_>, k: usize) -> DMatrix<f64>;

    /// Free-run simulation ŷ(t) from the record's initial condition on the
    /// recorded inputs alone (thesis eq. 2.20–2.21), N × p.
    fn simulate(&self, rec: &ValidationRecord<'_>) -> DMatrix<f64>;

    /// Free runs restarted from the measured (or estimated) state every
    /// `every` samples (≥ 1), N × p: rows of window [s, s + every) are the
    /// simulation started at s on the recorded inputs (see
    /// [`restart_windows`]).
    ///
    /// The default simulates each window as a record of its own, so a model
    /// whose [`Predictor::simulate`] starts from the measured state of the
    /// record's first sample needs nothing more; a model with an estimated
    /// state (Kalman filter, EKF) should restart from the state its filter
    /// holds at s, using no sample after s.
    fn simulate_restarted(&self, rec: &ValidationRecord<'_>, every: usize) -> DMatrix<f64> {
        let (n, p) = (rec.y.nrows(), self.output_names().len());
        let mut out = DMatrix::from_element(n, p, f64::NAN);
        for (start, end) in restart_windows(n, every) {
            let u = rec.u.rows(start, end - start).into_owned();
            let y = rec.y.rows(start, end - start).into_owned();
            let sim = self.simulate(&ValidationRecord {
                h: rec.h,
                u: &u,
                y: &y,
            });
            if sim.shape() != (end - start, p) {
                continue;
            }
            out.rows_mut(start, end - start).copy_from(&sim);
        }
        out
    }
}

/// The windows [s, s + every) of a record of `n` samples restarted every
/// `every` samples (the last one may be shorter).
pub fn restart_windows(n: usize, every: usize) -> Vec<(usize, usize)> {
    let every = every.max(1);
    (0..n)
        .step_by(every)
        .map(|s| (s, (s + every).min(n)))
        .collect()
}
