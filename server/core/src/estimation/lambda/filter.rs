//! The state-variable filter λ(s) = 1/(1+sT) (thesis eq. 1.9), discretized
//! exactly for signals held over each sample interval (zero-order hold).
//!
//! With a = e^{−h/T} the filter state obeys
//! `[λs]_{k+1} = a·[λs]_k + (1 − a)·s_k`, which is the exact solution of
//! T·ẋ = −x + s over [t_k, t_k + h] for s held at s_k. For γ (a thruster
//! command held by the controller) this is exact. For ν it is not an
//! inter-sample assumption but a discrete-time identity: with
//! ν_{k+1} = Φ ν_k + Γ γ_k (the exact sampled model), the filtered sequences
//! satisfy `ν_k = Ã [λν]_k + B̃ [λγ]_k + a^k e₀` exactly, with
//! Ã = (Φ − aI)/(1 − a), B̃ = Γ/(1 − a) (see [`super::transform`]).
//!
//! `[λs]_k` depends on s_0 … s_{k−1} only (strictly causal), so the
//! measurement noise of ν_k is uncorrelated with the regressor at k.

use nalgebra::DMatrix;

use super::error::{LambdaError, require_positive};

/// How the filter state is set at the start of a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FilterInit {
    /// `[λs]_0 = 0`: the signals are taken as zero before the run. At an LPV
    /// grid point ν and γ have large means (forward speed, the thrust that
    /// balances drag), so this starts with a large transient a^k·e₀.
    Zero,
    /// `[λs]_0 = s_0`: the signals are taken as constant before the run (the
    /// vessel in steady state at the grid speed), so the transient e₀ is
    /// only what ν_0 departs from equilibrium under γ_0.
    #[default]
    FirstSample,
}

/// The exact ZOH discretization of λ(s) = 1/(1+sT) at sample time h.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LambdaFilter {
    /// Filter time constant T (s).
    pub t: f64,
    /// Sample time h (s).
    pub h: f64,
    /// Pole a = e^{−h/T}.
    pub a: f64,
    /// Gain 1 − a (computed as −expm1(−h/T) to keep its digits when h ≪ T).
    pub c: f64,
}

impl LambdaFilter {
    /// The filter for time constant `t` and sample time `h`.
    ///
    /// # Errors
    /// `t_lambda` or `h` not finite or not > 0.
    pub fn new(t: f64, h: f64) -> Result<Self, LambdaError> {
        require_positive("t_lambda", t)?;
        require_positive("h", h)?;
        let x = -h / t;
        Ok(LambdaFilter {
            t,
            h,
            a: x.exp(),
            c: -x.exp_m1(),
        })
    }

    /// Filters every column of `signal` (N × channels, one row per sample):
    /// row k of the result is `[λs]_k`, driven by rows 0 … k−1.
    pub fn apply(&self, signal: &DMatrix<f64>, init: FilterInit) -> DMatrix<f64> {
        let (n, m) = signal.shape();
        let mut out = DMatrix::zeros(n, m);
        if n == 0 {
            return out;
        }
        for j in 0..m {
            let s = signal.column(j);
            let mut x = match init {
                FilterInit::Zero => 0.0,
                FilterInit::FirstSample => s[0],
            };
            let col = out.column_mut(j);
            for (k, o) in col.into_iter().enumerate() {
                *o = x;
                x = self.a * x + self.c * s[k];
            }
        }
        out
    }

    /// `a^k` for k = 0 … n−1: the shape of the initial-condition transient
    /// e_k = a^k·e₀ of the filtered regression.
    pub fn transient(&self, n: usize) -> Vec<f64> {
        let mut v = Vec::with_capacity(n);
        let mut p = 1.0;
        for _ in 0..n {
            v.push(p);
            p *= self.a;
        }
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simulation::integrate::rk4_step;

    #[test]
    fn step_response_is_the_analytic_exponential() {
        let (t, h) = (1.7, 0.1);
        let f = LambdaFilter::new(t, h).unwrap();
        let step = DMatrix::from_element(200, 1, 2.5);
        let y = f.apply(&step, FilterInit::Zero);
        for k in 0..200 {
            let exact = 2.5 * (1.0 - (-(k as f64) * h / t).exp());
            assert!((y[(k, 0)] - exact).abs() < 1e-13, "k={k}");
        }
        // Started from the first sample, a constant passes unchanged.
        let y = f.apply(&step, FilterInit::FirstSample);
        assert!(y.iter().all(|v| (v - 2.5).abs() < 1e-13));
    }

    #[test]
    fn matches_a_fine_rk4_solution_for_held_inputs() {
        // T ẋ = −x + s with s held over each h: the recursion is exact, so a
        // fine RK4 integration agrees to its own error.
        let (t, h) = (0.8, 0.1);
        let f = LambdaFilter::new(t, h).unwrap();
        let s = DMatrix::from_fn(300, 2, |k, j| ((k as f64) * 0.37 + j as f64).sin().signum());
        let y = f.apply(&s, FilterInit::Zero);
        for j in 0..2 {
            let mut x = [0.0];
            for k in 0..300 {
                assert!((y[(k, j)] - x[0]).abs() < 1e-10, "k={k} j={j}");
                for _ in 0..20 {
                    rk4_step(
                        &mut |x: &[f64], u: &[f64], dx: &mut [f64]| dx[0] = (u[0] - x[0]) / t,
                        &mut x,
                        &[s[(k, j)]],
                        h / 20.0,
                    );
                }
            }
        }
    }

    #[test]
    fn rejects_non_positive_time_constants() {
        assert_eq!(LambdaFilter::new(0.0, 0.1).unwrap_err().field(), "t_lambda");
        assert_eq!(LambdaFilter::new(1.0, f64::NAN).unwrap_err().field(), "h");
    }
}
