//! One pass of the Kalman predictor of N runs with θ fixed, and the forward
//! sensitivities of its innovations to θ: what the prediction-error
//! refinement ([`super::refine`]) minimises and differentiates.
//!
//! Per run i and sample k (x̂⁻ the one-step prediction, P⁻ its covariance):
//!
//! - innovation e = z − H·x̂⁻ (angles wrapped), S = H·P⁻·Hᵀ + R, gain
//!   K = P⁻·Hᵀ·S⁻¹; x̂⁺ = x̂⁻ + K·e, P⁺ = P⁻ − K·H·P⁻;
//! - x̂⁻(k+1) = f(x̂⁺, u(k), θ), P⁻(k+1) = Φ_x·P⁺·Φ_xᵀ + Q.
//!
//! The criterion is the negative log-likelihood of the innovations,
//! V(θ) = ½·Σ (eᵀS⁻¹e + ln det S). Its Gauss–Newton gradient and Hessian
//! hold the gain and S at their values for this θ (the gain's dependence on
//! θ is second order near the optimum): with X = ∂x̂⁻/∂θ (n × p) and
//! ψ = ∂e/∂θ = −H·X,
//!
//! - X⁺ = X + K·ψ, X(k+1) = Φ_x·X⁺ + Φ_θ (Φ from the model's exact RK4 map),
//! - g = Σ ψᵀS⁻¹e, J = Σ ψᵀS⁻¹ψ (the Fisher information of θ when the
//!   noise model is right), and the per-sample scores ψᵀS⁻¹e for a
//!   residual-based (sandwich) covariance.

use nalgebra::{DMatrix, DVector};

use super::error::{EkfError, check_finite, check_len, check_variances};
use super::filter::{RunData, wrap_angle};
use super::model::RunModel;

/// The known part of the predictor: each run's initial state and the
/// diagonal noise model (per sample), as in the EKF's
/// [`EkfSettings`](super::EkfSettings) without θ's prior.
#[derive(Debug, Clone, PartialEq)]
pub struct PredictorNoise {
    /// x_i(0) of each run (N vectors of n).
    pub x0: Vec<Vec<f64>>,
    /// Diagonal of P(0) (n), > 0.
    pub p0_x: Vec<f64>,
    /// Process noise per sample (n), ≥ 0.
    pub q_x: Vec<f64>,
    /// Measurement noise variances (m), > 0.
    pub r: Vec<f64>,
}

/// What one predictor pass returns.
#[derive(Debug, Clone)]
pub struct PredictorPass {
    /// V(θ) = ½·Σ (eᵀS⁻¹e + ln det S) over every run and sample.
    pub nll: f64,
    /// Σ eᵀS⁻¹e (χ² of the normalized innovations).
    pub chi2: f64,
    /// Scalar measurements used (Σ N_i·m).
    pub count: usize,
    /// Gauss–Newton gradient g = Σ ψᵀS⁻¹e (p).
    pub grad: DVector<f64>,
    /// Gauss–Newton Hessian J = Σ ψᵀS⁻¹ψ (p × p).
    pub info: DMatrix<f64>,
    /// Per run, the scores ψᵀS⁻¹e of each sample (N_i × p); empty without
    /// sensitivities.
    pub scores: Vec<DMatrix<f64>>,
    /// Per run, the innovations e (N_i × m).
    pub innovations: Vec<DMatrix<f64>>,
}

impl PredictorPass {
    /// V(θ) per scalar measurement (comparable across data sets).
    pub fn nll_per_measurement(&self) -> f64 {
        self.nll / self.count.max(1) as f64
    }
}

fn validate(
    model: &dyn RunModel,
    runs: &[RunData<'_>],
    noise: &PredictorNoise,
    theta: &[f64],
) -> Result<(), EkfError> {
    if runs.is_empty() {
        return Err(EkfError::NoRuns);
    }
    let (n, m) = (model.n_states(), model.measurement_matrix().nrows());
    check_len("theta", theta.len(), model.n_params())?;
    check_finite("theta", theta)?;
    check_len("x0", noise.x0.len(), runs.len())?;
    for (i, (x0, run)) in noise.x0.iter().zip(runs).enumerate() {
        check_len(&format!("x0[{i}]"), x0.len(), n)?;
        check_finite(&format!("x0[{i}]"), x0)?;
        if run.z.ncols() != m || run.u.ncols() != model.n_inputs() || run.u.nrows() < run.z.nrows()
        {
            return Err(EkfError::Shape {
                field: format!("runs[{i}]"),
                expected: format!("z N × {m}, u N × {}", model.n_inputs()),
                got: format!(
                    "z {} × {}, u {} × {}",
                    run.z.nrows(),
                    run.z.ncols(),
                    run.u.nrows(),
                    run.u.ncols()
                ),
            });
        }
    }
    check_len("p0_x", noise.p0_x.len(), n)?;
    check_variances("p0_x", &noise.p0_x, true)?;
    check_len("q_x", noise.q_x.len(), n)?;
    check_variances("q_x", &noise.q_x, false)?;
    check_len("r", noise.r.len(), m)?;
    check_variances("r", &noise.r, true)
}

/// Runs the Kalman predictor over every run at `theta`; with `sensitivities`
/// also g, J and the scores (else they are zero and empty).
pub fn predictor_pass(
    model: &dyn RunModel,
    runs: &[RunData<'_>],
    noise: &PredictorNoise,
    theta: &[f64],
    sensitivities: bool,
) -> Result<PredictorPass, EkfError> {
    validate(model, runs, noise, theta)?;
    let (n, p) = (model.n_states(), model.n_params());
    let h = model.measurement_matrix();
    let m = h.nrows();
    let angles = model.angle_outputs();
    let mut out = PredictorPass {
        nll: 0.0,
        chi2: 0.0,
        count: 0,
        grad: DVector::zeros(p),
        info: DMatrix::zeros(p, p),
        scores: Vec::with_capacity(runs.len()),
        innovations: Vec::with_capacity(runs.len()),
    };
    let mut phi_x = DMatrix::zeros(n, n);
    let mut phi_t = DMatrix::zeros(n, p);
    let mut x_next = vec![0.0; n];
    let mut hp = DMatrix::zeros(m, n);
    let mut gain = DMatrix::zeros(n, m);
    let mut tmp = DMatrix::zeros(n, n);
    let mut tmp2 = DMatrix::zeros(n, n);
    let mut tmp_t = DMatrix::zeros(n, p);
    let mut psi = DMatrix::zeros(m, p);
    let mut si_psi = DMatrix::zeros(m, p);
    let mut u = vec![0.0; model.n_inputs()];
    for (i, run) in runs.iter().enumerate() {
        let len = run.z.nrows();
        let mut x = DVector::from_column_slice(&noise.x0[i]);
        let mut pm = DMatrix::from_diagonal(&DVector::from_column_slice(&noise.p0_x));
        let mut sens = DMatrix::zeros(n, p);
        let mut scores = DMatrix::zeros(if sensitivities { len } else { 0 }, p);
        let mut innovations = DMatrix::zeros(len, m);
        for k in 0..len {
            // Measurement update.
            hp.gemm(1.0, h, &pm, 0.0);
            let mut s = &hp * h.transpose();
            for j in 0..m {
                s[(j, j)] += noise.r[j];
            }
            let s = (&s + s.transpose()) * 0.5;
            let chol = s.clone().cholesky().ok_or(EkfError::Diverged { step: k })?;
            let s_inv = chol.inverse();
            let log_det: f64 = 2.0 * chol.l().diagonal().iter().map(|d| d.ln()).sum::<f64>();
            let mut e = DVector::zeros(m);
            for j in 0..m {
                let hx: f64 = (0..n).map(|c| h[(j, c)] * x[c]).sum();
                e[j] = run.z[(k, j)] - hx;
                if angles.contains(&j) {
                    e[j] = wrap_angle(e[j]);
                }
                innovations[(k, j)] = e[j];
            }
            let si_e = &s_inv * &e;
            let q = e.dot(&si_e);
            out.chi2 += q;
            out.nll += 0.5 * (q + log_det);
            out.count += m;
            gain.gemm_tr(1.0, &hp, &s_inv, 0.0);
            x.gemv(1.0, &gain, &e, 1.0);
            if sensitivities {
                psi.gemm(-1.0, h, &sens, 0.0);
                si_psi.gemm(1.0, &s_inv, &psi, 0.0);
                let score = psi.tr_mul(&si_e);
                out.grad += &score;
                out.info.gemm_tr(1.0, &psi, &si_psi, 1.0);
                scores.row_mut(k).copy_from(&score.transpose());
                sens.gemm(1.0, &gain, &psi, 1.0);
            }
            pm.gemm(-1.0, &gain, &hp, 1.0);
            if !x.iter().all(|v| v.is_finite()) {
                return Err(EkfError::Diverged { step: k });
            }
            if k + 1 == len {
                break;
            }
            // Propagation with u(k).
            for (c, v) in u.iter_mut().enumerate() {
                *v = run.u[(k, c)];
            }
            model.transition(x.as_slice(), &u, theta, &mut x_next, &mut phi_x, &mut phi_t);
            x.copy_from_slice(&x_next);
            // Φ·P·Φᵀ = Φ·(Φ·P)ᵀ for symmetric P, then symmetrized.
            tmp.gemm(1.0, &phi_x, &pm, 0.0);
            tmp.transpose_to(&mut tmp2);
            tmp.gemm(1.0, &phi_x, &tmp2, 0.0);
            tmp.transpose_to(&mut tmp2);
            for r in 0..n {
                for c in 0..n {
                    pm[(r, c)] = 0.5 * (tmp[(r, c)] + tmp2[(r, c)]);
                }
                pm[(r, r)] += noise.q_x[r];
            }
            if sensitivities {
                tmp_t.copy_from(&phi_t);
                tmp_t.gemm(1.0, &phi_x, &sens, 1.0);
                sens.copy_from(&tmp_t);
            }
        }
        out.scores.push(scores);
        out.innovations.push(innovations);
    }
    out.info = (&out.info + out.info.transpose()) * 0.5;
    Ok(out)
}
