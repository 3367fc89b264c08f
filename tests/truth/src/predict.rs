//! What the TRUE plant predicts on a logged run, for grading an identified
//! model's predictions against the best achievable: the same log (noisy
//! measured ν, η; logged τ held over each log interval, so the odd 20 Hz
//! commands the plant really saw are unknown here too), the true equations.
//!
//! Every function returns an N×6 matrix of ν aligned with the log rows. Row
//! j holds the prediction of ν_j; rows with no prediction (before the first
//! horizon, and restart rows) hold the measured ν_j. With an actuator lag
//! the lag state starts at the logged τ at each start.

use nalgebra::{DMatrix, Vector6};

use crate::campaign::Log;
use crate::plant::{Plant, State};
use crate::vessel::Vessel;

/// Internal RK4 step (s): 200 Hz, as in the campaign.
const H_MAX: f64 = 0.005;

/// The four standard predictions on one log.
#[derive(Debug, Clone, PartialEq)]
pub struct TruePredictions {
    /// 1-step-ahead (one log interval).
    pub one_step: DMatrix<f64>,
    /// 10-step-ahead.
    pub k_step: DMatrix<f64>,
    /// Free run from the measured initial state over the whole log.
    pub free_run: DMatrix<f64>,
    /// Free run restarted from the measured state every 10 s.
    pub restarted_10s: DMatrix<f64>,
}

fn row(m: &DMatrix<f64>, i: usize) -> Vector6<f64> {
    Vector6::from_fn(|j, _| m[(i, j)])
}

fn start(log: &Log, i: usize) -> State {
    State {
        eta: row(&log.eta, i),
        nu: row(&log.nu, i),
        tau_act: row(&log.tau, i),
    }
}

/// Integrates from log row `i` to row `i + 1` with τ_i held.
fn interval(plant: &Plant, log: &Log, x: &State, i: usize) -> State {
    let tau = row(&log.tau, i);
    plant.advance(x, &tau, log.t[i + 1] - log.t[i], H_MAX)
}

/// k-step-ahead predictions: ν̂_j from the measured state at row j − k and
/// the logged τ over rows j − k … j − 1.
pub fn predict_k_step(vessel: &Vessel, log: &Log, k: usize) -> DMatrix<f64> {
    assert!(k >= 1, "k-step prediction needs k ≥ 1");
    let plant = Plant::new(vessel);
    let n = log.t.len();
    let mut out = log.nu.clone();
    for j in k..n {
        let mut x = start(log, j - k);
        for i in j - k..j {
            x = interval(&plant, log, &x, i);
        }
        out.row_mut(j).copy_from(&x.nu.transpose());
    }
    out
}

/// Free runs restarted from the measured state at the first row and then at
/// the first row at least `every_s` seconds after the last restart.
pub fn free_run_restarted(vessel: &Vessel, log: &Log, every_s: f64) -> DMatrix<f64> {
    let plant = Plant::new(vessel);
    let n = log.t.len();
    let mut out = log.nu.clone();
    if n == 0 {
        return out;
    }
    let mut x = start(log, 0);
    let mut t_restart = log.t[0];
    for i in 0..n - 1 {
        x = interval(&plant, log, &x, i);
        if log.t[i + 1] - t_restart >= every_s - 1e-9 {
            x = start(log, i + 1);
            t_restart = log.t[i + 1];
        } else {
            out.row_mut(i + 1).copy_from(&x.nu.transpose());
        }
    }
    out
}

/// The whole-run free run from the measured initial state.
pub fn free_run(vessel: &Vessel, log: &Log) -> DMatrix<f64> {
    free_run_restarted(vessel, log, f64::INFINITY)
}

/// 1-step, 10-step, free run and 10 s restarted free run of the true plant.
pub fn true_predictions(vessel: &Vessel, log: &Log) -> TruePredictions {
    TruePredictions {
        one_step: predict_k_step(vessel, log, 1),
        k_step: predict_k_step(vessel, log, 10),
        free_run: free_run(vessel, log),
        restarted_10s: free_run_restarted(vessel, log, 10.0),
    }
}
