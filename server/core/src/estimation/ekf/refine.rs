//! Prediction-error refinement of θ after the staged EKF, on all runs at
//! once, with a calibrated covariance.
//!
//! The augmented EKF (Table 1) is a recursive, one-pass approximation: its
//! θ̂ depends on the order of the data and on θ's prior, and its P_θθ is
//! the linearization's, not the data's information. The refinement
//! minimises the negative log-likelihood of the innovations of the Kalman
//! predictor of the same run model (states x, θ fixed within a pass),
//! V(θ) = ½·Σ (eᵀS⁻¹e + ln det S) over every run
//! ([`super::sensitivity`]), by Levenberg–Marquardt from the EKF's θ̂, with
//! the Gauss–Newton gradient and Hessian of forward sensitivities.
//!
//! **What the std means.** θ̂'s covariance is the inverse Gauss–Newton
//! Hessian J⁻¹ (the Cramér–Rao bound when the noise model R, Q is right),
//! inflated per parameter when the residuals say the noise model is too
//! optimistic: by the innovations' variance ratio χ²/(N_meas − p) and by
//! the Newey–West sandwich J⁻¹·B·J⁻¹ of the per-sample scores (B over
//! lags up to 4·(N/100)^(2/9), which catches coloured innovations), the
//! larger of the three, never below J⁻¹. With a right noise model the
//! three agree and std is the CRB; θ̂ ± 2·std is then a 95 % interval.

use nalgebra::{DMatrix, DVector};

use super::dp_model::DpMomentumModel;
use super::error::EkfError;
use super::filter::RunData;
use super::model::{Rk4, RunModel};
use super::sensitivity::{PredictorNoise, PredictorPass, predictor_pass};
use super::staged::DpIdentConfig;
use crate::estimation::Progress;
use crate::simulation::dp_ship::N_THETA;

/// Stopping rules of the Levenberg–Marquardt iteration.
#[derive(Debug, Clone, PartialEq)]
pub struct RefineSettings {
    /// Most Gauss–Newton steps (each one predictor pass), ≥ 1.
    pub max_iterations: usize,
    /// Converged when the Gauss–Newton decrease ½·gᵀJ⁻¹g of V predicted
    /// at θ̂ is below this (log-likelihood units: the remaining step is
    /// √(2·tolerance) standard deviations long, 0.14 for the default 0.01).
    pub decrement_tolerance: f64,
    /// When no damped step lowers V any more, converged if the predicted
    /// decrease is below this (default 0.5: the remaining step is under one
    /// standard deviation).
    pub stall_tolerance: f64,
}

impl Default for RefineSettings {
    fn default() -> Self {
        RefineSettings {
            max_iterations: 20,
            decrement_tolerance: 1e-2,
            stall_tolerance: 0.5,
        }
    }
}

/// The refined θ and what stands behind it.
#[derive(Debug, Clone)]
pub struct Refinement {
    /// θ̂ minimising V.
    pub theta: DVector<f64>,
    /// Calibrated covariance (see the module documentation).
    pub theta_cov: DMatrix<f64>,
    /// J⁻¹, the Cramér–Rao bound under the stated noise model.
    pub crb_cov: DMatrix<f64>,
    /// χ²/(N_meas − p) of the innovations at θ̂ (≈ 1 for a right R, Q).
    pub variance_ratio: f64,
    /// Per parameter, std / √(J⁻¹)ii ≥ 1.
    pub inflation: DVector<f64>,
    /// V at the start (the EKF's θ̂) and at θ̂.
    pub nll_start: f64,
    /// V at θ̂.
    pub nll: f64,
    /// Accepted steps.
    pub iterations: usize,
    /// The predicted decrease fell below tolerance (else: iterations ran
    /// out or no step lowered V).
    pub converged: bool,
    /// The last Gauss–Newton decrease ½·gᵀJ⁻¹g predicted at θ̂.
    pub decrement: f64,
    /// The predictor pass at θ̂.
    pub pass: PredictorPass,
}

impl Refinement {
    /// Standard deviations √diag of the calibrated covariance.
    pub fn theta_std(&self) -> DVector<f64> {
        self.theta_cov.diagonal().map(|v| v.max(0.0).sqrt())
    }
}

/// J + λ·diag(J) solved for −g; `None` if singular.
fn lm_step(info: &DMatrix<f64>, grad: &DVector<f64>, lambda: f64) -> Option<DVector<f64>> {
    let mut a = info.clone();
    let top = info.diagonal().amax().max(f64::MIN_POSITIVE);
    for i in 0..a.nrows() {
        a[(i, i)] += lambda * info[(i, i)].max(1e-12 * top);
    }
    a.cholesky().map(|c| -c.solve(grad))
}

/// Newey–West long-run covariance B = Σ_runs Σ_|l|≤L w_l Σ_k s_k s_{k+l}ᵀ of
/// the scores, Bartlett weights w_l = 1 − l/(L+1).
fn score_covariance(scores: &[DMatrix<f64>], p: usize) -> DMatrix<f64> {
    let mut b = DMatrix::zeros(p, p);
    for s in scores {
        let len = s.nrows();
        if len == 0 {
            continue;
        }
        let lags = (4.0 * (len as f64 / 100.0).powf(2.0 / 9.0)).floor() as usize;
        b.gemm_tr(1.0, s, s, 1.0);
        for l in 1..=lags.min(len - 1) {
            let w = 1.0 - l as f64 / (lags + 1) as f64;
            let head = s.rows(0, len - l);
            let tail = s.rows(l, len - l);
            let g = head.tr_mul(&tail);
            b += (&g + g.transpose()) * w;
        }
    }
    b
}

/// Refines `theta0` by Levenberg–Marquardt on V(θ) over `runs`; reports
/// progress under `label` once per step and stops if asked.
pub fn refine_theta(
    model: &dyn RunModel,
    runs: &[RunData<'_>],
    noise: &PredictorNoise,
    theta0: &[f64],
    settings: &RefineSettings,
    label: &str,
    progress: &mut dyn Progress,
) -> Result<Refinement, EkfError> {
    if settings.max_iterations == 0 {
        return Err(EkfError::Invalid {
            field: "max_iterations".into(),
            reason: "at least one step is needed".into(),
        });
    }
    let p = model.n_params();
    let mut theta = DVector::from_column_slice(theta0);
    let mut cur = predictor_pass(model, runs, noise, theta.as_slice(), true)?;
    let nll_start = cur.nll;
    let mut lambda = 1e-3;
    let mut iterations = 0;
    let mut converged = false;
    let mut decrement = f64::INFINITY;
    for it in 0..settings.max_iterations {
        progress.update(it as f64 / settings.max_iterations as f64, label)?;
        let Some(gn) = lm_step(&cur.info, &cur.grad, 0.0) else {
            break;
        };
        decrement = -0.5 * cur.grad.dot(&gn);
        if decrement < settings.decrement_tolerance {
            converged = true;
            break;
        }
        let mut accepted = false;
        while lambda < 1e4 {
            let Some(step) = lm_step(&cur.info, &cur.grad, lambda) else {
                lambda *= 100.0;
                continue;
            };
            let trial = &theta + &step;
            match predictor_pass(model, runs, noise, trial.as_slice(), true) {
                Ok(pass) if pass.nll.is_finite() && pass.nll < cur.nll => {
                    theta = trial;
                    cur = pass;
                    lambda = (lambda * 0.1).max(1e-9);
                    accepted = true;
                    break;
                }
                Ok(_) | Err(EkfError::Diverged { .. }) => lambda *= 100.0,
                Err(e) => return Err(e),
            }
        }
        if !accepted {
            // No damped step lowers V: the gain held fixed in g and J no
            // longer describes V this close to its minimum. Within a
            // standard deviation of it, that is convergence.
            converged = decrement < settings.stall_tolerance;
            break;
        }
        iterations += 1;
    }
    progress.update(1.0, label)?;
    let crb_cov = cur
        .info
        .clone()
        .cholesky()
        .map(|c| c.inverse())
        .ok_or_else(|| EkfError::Invalid {
            field: "theta".into(),
            reason: "the data do not determine every parameter (singular information)".into(),
        })?;
    let variance_ratio = cur.chi2 / (cur.count.saturating_sub(p)).max(1) as f64;
    let sandwich = &crb_cov * score_covariance(&cur.scores, p) * &crb_cov;
    let inflation = DVector::from_fn(p, |i, _| {
        let crb = crb_cov[(i, i)].max(f64::MIN_POSITIVE);
        (sandwich[(i, i)] / crb).max(variance_ratio).max(1.0).sqrt()
    });
    let theta_cov = DMatrix::from_fn(p, p, |i, j| inflation[i] * crb_cov[(i, j)] * inflation[j]);
    Ok(Refinement {
        theta,
        theta_cov,
        crb_cov,
        variance_ratio,
        inflation,
        nll_start,
        nll: cur.nll,
        iterations,
        converged,
        decrement,
        pass: cur,
    })
}

/// A DP ship refined on all runs: the nine θ″ (those not `free` held).
#[derive(Debug, Clone)]
pub struct DpRefinement {
    /// θ″1 … θ″9 after the refinement.
    pub theta: [f64; N_THETA],
    /// Calibrated std (0 for parameters not refined).
    pub theta_std: [f64; N_THETA],
    /// The refinement of the free θ″.
    pub refinement: Refinement,
}

/// The momentum model's predictor (RK4 at `cfg.h`) with `free` θ″ and the
/// rest at `theta`, and its known noise and initial states on `runs`.
fn dp_predictor(
    cfg: &DpIdentConfig,
    runs: &[RunData<'_>],
    theta: &[f64; N_THETA],
    free: &[usize],
) -> Result<(Rk4<DpMomentumModel>, PredictorNoise), EkfError> {
    let (p0_x, q_x) = cfg.state_noise();
    let noise = PredictorNoise {
        x0: super::staged::initial_states(runs)?,
        p0_x,
        q_x,
        r: cfg.r.to_vec(),
    };
    let model = Rk4 {
        model: DpMomentumModel::new(cfg.m, cfg.thrust.clone(), *theta, free.to_vec()),
        h: cfg.h,
    };
    Ok((model, noise))
}

/// Refines the `free` θ″ of a DP ship (M, T and noise of `cfg`) jointly on
/// `runs` from `theta` (the staged EKF's θ̂).
pub fn refine_dp_ship(
    cfg: &DpIdentConfig,
    runs: &[RunData<'_>],
    free: &[usize],
    theta: &[f64; N_THETA],
    settings: &RefineSettings,
    progress: &mut dyn Progress,
) -> Result<DpRefinement, EkfError> {
    if free.is_empty() || free.iter().any(|&f| f >= N_THETA) {
        return Err(EkfError::Invalid {
            field: "free".into(),
            reason: "θ″ indices 0–8, at least one".into(),
        });
    }
    let (model, noise) = dp_predictor(cfg, runs, theta, free)?;
    let start: Vec<f64> = free.iter().map(|&f| theta[f]).collect();
    let refinement = refine_theta(
        &model,
        runs,
        &noise,
        &start,
        settings,
        "refinement",
        progress,
    )?;
    let mut out = *theta;
    let mut std = [0.0; N_THETA];
    let s = refinement.theta_std();
    for (c, &f) in free.iter().enumerate() {
        out[f] = refinement.theta[c];
        std[f] = s[c];
    }
    Ok(DpRefinement {
        theta: out,
        theta_std: std,
        refinement,
    })
}

/// V(θ″) of the Kalman predictor on `runs` (held-out runs: lower predicts
/// better; a difference of 2 is a likelihood ratio of e²).
pub fn dp_predictor_nll(
    cfg: &DpIdentConfig,
    runs: &[RunData<'_>],
    theta: &[f64; N_THETA],
) -> Result<f64, EkfError> {
    let (model, noise) = dp_predictor(cfg, runs, theta, &[])?;
    Ok(predictor_pass(&model, runs, &noise, &[], false)?.nll)
}
