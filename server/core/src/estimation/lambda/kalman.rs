//! The covariance-form Kalman filter over the parameters of one output row,
//! for a random-walk parameter model θ_{k+1} = θ_k + w_k, w_k ~ N(0, Q)
//! (slowly drifting dynamics). With Q = 0 its end state equals the
//! information-form posterior of [`super::posterior`] (tested), which is
//! the fast path. Cost O(p²) per sample and row.
//!
//! Each run appends a nuisance state e₀ (the run's own transient a^k·e₀)
//! with a diffuse prior, and drops (marginalizes) it at the end of the
//! run: θ and P carry over from run to run; the signals are never
//! concatenated.

use nalgebra::{DMatrix, DVector};

use super::regressors::RunRegressors;

/// Prior standard deviation of a run's transient e₀, in multiples of the
/// largest |e₀| the filter could produce (|ν| over the filter gain).
const TRANSIENT_PRIOR_SCALE: f64 = 10.0;

/// Runs the filter for row `i` over `runs`; returns (θ_S, P_S).
#[allow(clippy::too_many_arguments)]
pub(crate) fn kalman_row(
    runs: &[RunRegressors<'_>],
    i: usize,
    free: &[usize],
    theta0_s: DVector<f64>,
    p0_s: DMatrix<f64>,
    r: f64,
    q_s: &DVector<f64>,
    transient: Option<f64>,
) -> (DVector<f64>, DMatrix<f64>) {
    let k = free.len();
    let mut theta = theta0_s;
    let mut p = p0_s;
    for run in runs {
        // Augmented state [θ_S; e₀] when the transient is estimated.
        let m = k + usize::from(transient.is_some());
        let mut th = DVector::zeros(m);
        th.rows_mut(0, k).copy_from(&theta);
        let mut pp = DMatrix::zeros(m, m);
        pp.view_mut((0, 0), (k, k)).copy_from(&p);
        if let Some(c) = transient {
            let ymax = run.y.column(i).amax();
            let s = TRANSIENT_PRIOR_SCALE * (ymax + r.sqrt()) / c;
            pp[(k, k)] = s * s;
        }
        let mut phi = DVector::zeros(m);
        let mut pphi = DVector::zeros(m);
        for t in 0..run.phi.nrows() {
            for (a, &j) in free.iter().enumerate() {
                phi[a] = run.phi[(t, j)];
            }
            if m > k {
                phi[k] = run.psi[t];
            }
            pphi.gemv(1.0, &pp, &phi, 0.0);
            let s = phi.dot(&pphi) + r;
            let innovation = run.y[(t, i)] - phi.dot(&th);
            th.axpy(innovation / s, &pphi, 1.0);
            // P ← P − PφφᵀP/s, symmetric rank-one downdate.
            pp.ger(-1.0 / s, &pphi, &pphi, 1.0);
            for a in 0..k {
                pp[(a, a)] += q_s[a];
            }
        }
        theta = th.rows(0, k).into_owned();
        p = pp.view((0, 0), (k, k)).into_owned();
    }
    (theta, p)
}
