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

use super::covariance::{axpy, predict, symmetric_rank2_update};
use super::error::{EkfError, check_finite, check_len, check_variances};
use super::model::RunModel;
use crate::estimation::Progress;
use crate::kernels::has_avx2_fma;

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
        theta_trace: DMatrix::zeros(0, p),
        states: len.iter().map(|&l| DMatrix::zeros(l, n)).collect(),
        innovations: len.iter().map(|&l| DMatrix::zeros(l, m)).collect(),
        covariance: DMatrix::zeros(0, 0),
    };

    // Workspaces, allocated once.
    let mut phi_x: Vec<DMatrix<f64>> = vec![DMatrix::identity(n, n); nr];
    let mut phi_theta: Vec<DMatrix<f64>> = vec![DMatrix::zeros(n, p); nr];
    let mut at = DMatrix::zeros(dim, off);

    let zero_q = vec![0.0; n];
    let mut x_next = vec![0.0; n];
    let mut u_buf = vec![0.0; model.n_inputs()];
    let mut update = UpdateWorkspace::new(dim, nr * m);
    let mut trace: Vec<f64> = Vec::with_capacity(steps * p);

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
        // Row-major while filtering (contiguous), transposed at the end.
        trace.extend_from_slice(&xi.as_slice()[off..]);
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
        );
    }
    progress.update(1.0, label)?;
    out.theta_trace = DMatrix::from_row_slice(steps, p, &trace);
    out.theta = xi.rows(off, p).into_owned();
    out.theta_cov = pm.view((off, off), (p, p)).into_owned();
    out.covariance = pm;
    Ok(out)
}

/// Scratch of the joint measurement update (dim × M, M = N·m at most).
struct UpdateWorkspace {
    u: DMatrix<f64>,
    k: DMatrix<f64>,
    w: DMatrix<f64>,
    s: DMatrix<f64>,
    innovation: Vec<f64>,
}

impl UpdateWorkspace {
    fn new(dim: usize, m_max: usize) -> Self {
        UpdateWorkspace {
            u: DMatrix::zeros(dim, m_max),
            k: DMatrix::zeros(dim, m_max),
            w: DMatrix::zeros(dim, m_max),
            s: DMatrix::zeros(m_max, m_max),
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
        active: &[usize],
        n: usize,
        r: &[f64],
        z: impl Fn(usize, usize) -> f64,
        angles: &[usize],
        step: usize,
    ) -> Result<(), EkfError> {
        #[cfg(target_arch = "x86_64")]
        if has_avx2_fma() {
            // SAFETY: the CPU has the features the function is compiled for.
            return unsafe { self.measure_avx2(pm, xi, h, active, n, r, z, angles, step) };
        }
        self.measure_body::<false>(pm, xi, h, active, n, r, z, angles, step)
    }

    /// [`Self::measure`] compiled for AVX2 and FMA (equal to rounding).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    #[allow(clippy::too_many_arguments)]
    fn measure_avx2(
        &mut self,
        pm: &mut DMatrix<f64>,
        xi: &mut DVector<f64>,
        h: &DMatrix<f64>,
        active: &[usize],
        n: usize,
        r: &[f64],
        z: impl Fn(usize, usize) -> f64,
        angles: &[usize],
        step: usize,
    ) -> Result<(), EkfError> {
        self.measure_body::<true>(pm, xi, h, active, n, r, z, angles, step)
    }

    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn measure_body<const FMA: bool>(
        &mut self,
        pm: &mut DMatrix<f64>,
        xi: &mut DVector<f64>,
        h: &DMatrix<f64>,
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
            // Fewer runs left: resize once per change.
            *self = UpdateWorkspace::new(dim, mm);
        }
        // U = P·Hᵀ: only run i's columns of P meet H_i.
        {
            let ps = pm.as_slice();
            let us = self.u.as_mut_slice();
            for (slot, &i) in active.iter().enumerate() {
                for j in 0..m {
                    let col = &mut us[(slot * m + j) * dim..(slot * m + j + 1) * dim];
                    col.fill(0.0);
                    for c in 0..n {
                        let a = h[(j, c)];
                        if a != 0.0 {
                            axpy::<FMA>(col, a, &ps[(i * n + c) * dim..(i * n + c + 1) * dim]);
                        }
                    }
                }
            }
        }
        // S = H·U + R (symmetrized).
        for (slot, &i) in active.iter().enumerate() {
            for b in 0..mm {
                for j in 0..m {
                    let mut v = 0.0;
                    for c in 0..n {
                        v += h[(j, c)] * self.u[(i * n + c, b)];
                    }
                    self.s[(slot * m + j, b)] = v;
                }
            }
            for (j, rj) in r.iter().enumerate() {
                self.s[(slot * m + j, slot * m + j)] += rj;
            }
        }
        for a in 0..mm {
            for b in 0..a {
                let v = 0.5 * (self.s[(a, b)] + self.s[(b, a)]);
                self.s[(a, b)] = v;
                self.s[(b, a)] = v;
            }
        }
        let s_inv = self
            .s
            .clone()
            .cholesky()
            .ok_or(EkfError::Diverged { step })?
            .inverse();
        // K = U·S⁻¹, column by column.
        {
            let us = self.u.as_slice();
            let ks = self.k.as_mut_slice();
            for l in 0..mm {
                let col = &mut ks[l * dim..(l + 1) * dim];
                col.fill(0.0);
                for j in 0..mm {
                    axpy::<FMA>(col, s_inv[(j, l)], &us[j * dim..(j + 1) * dim]);
                }
            }
        }
        // Innovation e = z − H·x̂ (angles wrapped), then ξ += K·e.
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
        {
            let ks = self.k.as_slice();
            let x = xi.as_mut_slice();
            for l in 0..mm {
                axpy::<FMA>(x, self.innovation[l], &ks[l * dim..(l + 1) * dim]);
            }
        }
        // W = K·S/2 − U, then P += K·Wᵀ + W·Kᵀ (Joseph form).
        {
            let ks = self.k.as_slice();
            let us = self.u.as_slice();
            let ws = self.w.as_mut_slice();
            for l in 0..mm {
                let col = &mut ws[l * dim..(l + 1) * dim];
                for (wv, &uv) in col.iter_mut().zip(&us[l * dim..(l + 1) * dim]) {
                    *wv = -uv;
                }
                for j in 0..mm {
                    axpy::<FMA>(col, 0.5 * self.s[(j, l)], &ks[j * dim..(j + 1) * dim]);
                }
            }
        }
        symmetric_rank2_update(pm, &self.k, &self.w);
        Ok(())
    }
}
