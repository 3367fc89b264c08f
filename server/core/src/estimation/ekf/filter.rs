//! The off-line parallel state-augmented EKF (Fossen et al. 1995, Table 1,
//! eq. 20–25): N runs of the same model share one parameter vector θ, the
//! augmented state is ξ = [x_1; …; x_N; θ] with dim Nn + p, and the
//! measurements z = [z_1; …; z_N] are processed jointly at each sample.
//!
//! Per sample k: measurement update with z(k) (Joseph form), then the
//! propagation with u(k). Runs may differ in length; a finished run is held
//! (identity transition, no noise, no measurement). Covariance algebra is
//! blockwise ([`super::covariance`]).

use nalgebra::{DMatrix, DVector};

use super::covariance::{predict, symmetric_rank2_update};
use super::error::{EkfError, check_finite, check_len, check_variances};
use super::model::RunModel;
use crate::estimation::Progress;

/// Progress is reported (and cancellation checked) every this many samples.
const PROGRESS_EVERY: usize = 100;

/// One run's record: u (N_k × r) and z (N_k × m), one row per sample.
#[derive(Debug, Clone, Copy)]
pub struct RunData<'a> {
    /// Inputs u(k), held from sample k to k + 1.
    pub u: &'a DMatrix<f64>,
    /// Measurements z(k).
    pub z: &'a DMatrix<f64>,
}

/// Initial conditions and noise of the augmented EKF (Table 1); all
/// covariances diagonal.
#[derive(Debug, Clone, PartialEq)]
pub struct EkfSettings {
    /// Initial state x_i(0) of each run (N vectors of n).
    pub x0: Vec<Vec<f64>>,
    /// Initial parameter estimate θ(0) (p).
    pub theta0: Vec<f64>,
    /// Diagonal of P(0) for each run's states (n), > 0.
    pub p0_x: Vec<f64>,
    /// Diagonal of P(0) for θ (p), > 0.
    pub p0_theta: Vec<f64>,
    /// Process noise per sample on each run's states (n), ≥ 0.
    pub q_x: Vec<f64>,
    /// Parameter random walk per sample (p), ≥ 0 (0: constant θ, eq. 16).
    pub q_theta: Vec<f64>,
    /// Measurement noise variances (m), > 0.
    pub r: Vec<f64>,
}

/// What the filter returns.
#[derive(Debug, Clone, PartialEq)]
pub struct EkfOutput {
    /// θ̂ after the last measurement.
    pub theta: DVector<f64>,
    /// Its covariance P_θθ.
    pub theta_cov: DMatrix<f64>,
    /// θ̂ after each sample's update (K × p, K the longest run).
    pub theta_trace: DMatrix<f64>,
    /// Filtered states x̂_i(k|k) of each run (N_i × n).
    pub states: Vec<DMatrix<f64>>,
    /// Innovations z_i(k) − H·x̂_i(k|k−1) of each run (N_i × m).
    pub innovations: Vec<DMatrix<f64>>,
    /// The full augmented covariance P after the last update.
    pub covariance: DMatrix<f64>,
}

impl EkfOutput {
    /// Standard deviations √diag(P_θθ).
    pub fn theta_std(&self) -> DVector<f64> {
        self.theta_cov.diagonal().map(|v| v.max(0.0).sqrt())
    }
}

/// Wraps an angle difference to (−π, π].
pub(crate) fn wrap_angle(a: f64) -> f64 {
    let tau = std::f64::consts::TAU;
    let w = a - tau * (a / tau).round();
    if w <= -std::f64::consts::PI {
        w + tau
    } else {
        w
    }
}

fn validate(model: &dyn RunModel, runs: &[RunData<'_>], s: &EkfSettings) -> Result<(), EkfError> {
    if runs.is_empty() {
        return Err(EkfError::NoRuns);
    }
    let (n, p, r) = (model.n_states(), model.n_params(), model.n_inputs());
    let h = model.measurement_matrix();
    if h.ncols() != n {
        return Err(EkfError::Shape {
            field: "model.measurement_matrix".into(),
            expected: format!("m × {n}"),
            got: format!("{} × {}", h.nrows(), h.ncols()),
        });
    }
    let m = h.nrows();
    for (i, run) in runs.iter().enumerate() {
        let shape = |name: &str, mat: &DMatrix<f64>, cols: usize| {
            if mat.ncols() != cols || mat.nrows() == 0 {
                Err(EkfError::Shape {
                    field: format!("runs[{i}].{name}"),
                    expected: format!("N × {cols}, N ≥ 1"),
                    got: format!("{} × {}", mat.nrows(), mat.ncols()),
                })
            } else {
                Ok(())
            }
        };
        shape("u", run.u, r)?;
        shape("z", run.z, m)?;
        if run.u.nrows() != run.z.nrows() {
            return Err(EkfError::Shape {
                field: format!("runs[{i}].u"),
                expected: format!("{} rows (as runs[{i}].z)", run.z.nrows()),
                got: format!("{} rows", run.u.nrows()),
            });
        }
        check_finite(&format!("runs[{i}].u"), run.u.iter())?;
        check_finite(&format!("runs[{i}].z"), run.z.iter())?;
    }
    check_len("x0", s.x0.len(), runs.len())?;
    for (i, x0) in s.x0.iter().enumerate() {
        check_len(&format!("x0[{i}]"), x0.len(), n)?;
        check_finite(&format!("x0[{i}]"), x0)?;
    }
    check_len("theta0", s.theta0.len(), p)?;
    check_finite("theta0", &s.theta0)?;
    for (field, v, len, strict) in [
        ("p0_x", &s.p0_x, n, true),
        ("p0_theta", &s.p0_theta, p, true),
        ("q_x", &s.q_x, n, false),
        ("q_theta", &s.q_theta, p, false),
        ("r", &s.r, m, true),
    ] {
        check_len(field, v.len(), len)?;
        check_variances(field, v, strict)?;
    }
    Ok(())
}

/// Runs the parallel augmented EKF over `runs` (N ≥ 1) of `model`.
///
/// Reports progress in 0–1 under `label` every 100 samples and stops with
/// [`EkfError::Cancelled`] if asked.
pub fn parallel_ekf(
    model: &dyn RunModel,
    runs: &[RunData<'_>],
    settings: &EkfSettings,
    label: &str,
    progress: &mut dyn Progress,
) -> Result<EkfOutput, EkfError> {
    validate(model, runs, settings)?;
    let (n, p) = (model.n_states(), model.n_params());
    let h = model.measurement_matrix();
    let m = h.nrows();
    let nr = runs.len();
    let off = nr * n;
    let dim = off + p;
    let len: Vec<usize> = runs.iter().map(|r| r.z.nrows()).collect();
    let steps = *len.iter().max().unwrap_or(&0);
    let angles = model.angle_outputs().to_vec();

    let mut xi = DVector::zeros(dim);
    let mut pm = DMatrix::zeros(dim, dim);
    for i in 0..nr {
        for c in 0..n {
            xi[i * n + c] = settings.x0[i][c];
            pm[(i * n + c, i * n + c)] = settings.p0_x[c];
        }
    }
    for c in 0..p {
        xi[off + c] = settings.theta0[c];
        pm[(off + c, off + c)] = settings.p0_theta[c];
    }

    let mut out = EkfOutput {
        theta: DVector::zeros(p),
        theta_cov: DMatrix::zeros(p, p),
        theta_trace: DMatrix::zeros(steps, p),
        states: len.iter().map(|&l| DMatrix::zeros(l, n)).collect(),
        innovations: len.iter().map(|&l| DMatrix::zeros(l, m)).collect(),
        covariance: DMatrix::zeros(0, 0),
    };

    // Workspaces, allocated once.
    let mut phi_x: Vec<DMatrix<f64>> = vec![DMatrix::identity(n, n); nr];
    let mut phi_theta: Vec<DMatrix<f64>> = vec![DMatrix::zeros(n, p); nr];
    let mut at = DMatrix::zeros(dim, off);
    let mut phi_t = (DMatrix::zeros(n, n), DMatrix::zeros(p, n));
    let ht = h.transpose();
    let zero_q = vec![0.0; n];
    let mut x_next = vec![0.0; n];
    let mut u_buf = vec![0.0; model.n_inputs()];
    let mut update = UpdateWorkspace::new(dim, nr * m);

    for k in 0..steps {
        if k % PROGRESS_EVERY == 0 {
            progress.update(k as f64 / steps as f64, label)?;
        }
        // Measurement update with every run that has a sample k.
        let active: Vec<usize> = (0..nr).filter(|&i| k < len[i]).collect();
        update.measure(
            &mut pm,
            &mut xi,
            h,
            &ht,
            &active,
            n,
            &settings.r,
            |i, j| runs[i].z[(k, j)],
            &angles,
            k,
        )?;
        for (slot, &i) in active.iter().enumerate() {
            for j in 0..m {
                out.innovations[i][(k, j)] = update.innovation[slot * m + j];
            }
            for c in 0..n {
                out.states[i][(k, c)] = xi[i * n + c];
            }
        }
        for c in 0..p {
            out.theta_trace[(k, c)] = xi[off + c];
        }
        if k + 1 == steps {
            break;
        }
        // Propagation with u(k) for runs that go on; the others are held.
        let theta: Vec<f64> = xi.rows(off, p).iter().copied().collect();
        let mut q_runs: Vec<&[f64]> = Vec::with_capacity(nr);
        for i in 0..nr {
            if k + 1 < len[i] {
                for (c, v) in u_buf.iter_mut().enumerate() {
                    *v = runs[i].u[(k, c)];
                }
                let x = &xi.as_slice()[i * n..(i + 1) * n];
                model.transition(
                    x,
                    &u_buf,
                    &theta,
                    &mut x_next,
                    &mut phi_x[i],
                    &mut phi_theta[i],
                );
                xi.rows_mut(i * n, n).copy_from_slice(&x_next);
                q_runs.push(&settings.q_x);
            } else {
                phi_x[i].fill_with_identity();
                phi_theta[i].fill(0.0);
                q_runs.push(&zero_q);
            }
        }
        predict(
            &mut pm,
            n,
            &phi_x,
            &phi_theta,
            &q_runs,
            &settings.q_theta,
            &mut at,
            &mut phi_t,
        );
    }
    progress.update(1.0, label)?;
    out.theta = xi.rows(off, p).into_owned();
    out.theta_cov = pm.view((off, off), (p, p)).into_owned();
    out.covariance = pm;
    Ok(out)
}

/// Scratch of the joint measurement update.
struct UpdateWorkspace {
    u: DMatrix<f64>,
    k: DMatrix<f64>,
    w: DMatrix<f64>,
    innovation: Vec<f64>,
}

impl UpdateWorkspace {
    fn new(dim: usize, m_max: usize) -> Self {
        UpdateWorkspace {
            u: DMatrix::zeros(dim, m_max),
            k: DMatrix::zeros(dim, m_max),
            w: DMatrix::zeros(dim, m_max),
            innovation: vec![0.0; m_max],
        }
    }

    /// Joint update with the runs `active` (Table 1): S = H·P·Hᵀ + R,
    /// K = P·Hᵀ·S⁻¹, ξ += K·(z − H·ξ), Joseph-form P.
    #[allow(clippy::too_many_arguments)]
    fn measure(
        &mut self,
        pm: &mut DMatrix<f64>,
        xi: &mut DVector<f64>,
        h: &DMatrix<f64>,
        ht: &DMatrix<f64>,
        active: &[usize],
        n: usize,
        r: &[f64],
        z: impl Fn(usize, usize) -> f64,
        angles: &[usize],
        step: usize,
    ) -> Result<(), EkfError> {
        let m = h.nrows();
        let mm = active.len() * m;
        let dim = pm.nrows();
        if mm == 0 {
            return Ok(());
        }
        if self.u.ncols() != mm {
            self.u = DMatrix::zeros(dim, mm);
            self.k = DMatrix::zeros(dim, mm);
            self.w = DMatrix::zeros(dim, mm);
        }
        // U = P·Hᵀ: only run i's columns of P meet H_i.
        for (slot, &i) in active.iter().enumerate() {
            self.u
                .columns_mut(slot * m, m)
                .gemm(1.0, &pm.columns(i * n, n), ht, 0.0);
        }
        // S = H·U + R.
        let mut s = DMatrix::zeros(mm, mm);
        for (slot, &i) in active.iter().enumerate() {
            s.rows_mut(slot * m, m)
                .gemm(1.0, h, &self.u.rows(i * n, n), 0.0);
            for j in 0..m {
                s[(slot * m + j, slot * m + j)] += r[j];
            }
        }
        let s = (&s + s.transpose()) * 0.5;
        let chol = s.clone().cholesky().ok_or(EkfError::Diverged { step })?;
        // Kᵀ = S⁻¹·Uᵀ.
        let kt = chol.solve(&self.u.transpose());
        kt.transpose_to(&mut self.k);
        // Innovation e = z − H·x̂ (angles wrapped).
        for (slot, &i) in active.iter().enumerate() {
            for j in 0..m {
                let hx: f64 = (0..n).map(|c| h[(j, c)] * xi[i * n + c]).sum();
                let mut e = z(i, j) - hx;
                if angles.contains(&j) {
                    e = wrap_angle(e);
                }
                self.innovation[slot * m + j] = e;
            }
        }
        let e = DVector::from_column_slice(&self.innovation[..mm]);
        xi.gemv(1.0, &self.k, &e, 1.0);
        // W = K·S/2 − U, then P += K·Wᵀ + W·Kᵀ (Joseph form).
        self.w.copy_from(&self.u);
        self.w.gemm(0.5, &self.k, &s, -1.0);
        symmetric_rank2_update(pm, &self.k, &self.w);
        Ok(())
    }
}
