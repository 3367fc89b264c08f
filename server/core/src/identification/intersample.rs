//! A controller faster than its log: τ between log samples.
//!
//! A feedback controller running r times faster than the log (a 20 Hz loop
//! logged at 10 Hz: r = 2) applies, between log samples k and k+1, commands
//! the log never shows: τ(t_k + j·h/r) = τ_k + K_ν (ν(t) − ν_k) + K_η (η(t) − η_k)
//! for j = 1 … r−1, with K_ν = ∂τ/∂ν and K_η = ∂τ/∂η the controller's gains
//! on the measurements it feeds back. Averaged over the interval the vehicle
//! feels τ_k + c (K_ν ν̇ + K_η η̇) with c = h (r − 1)/(2r), so a model fitted
//! to the logged τ held over the interval identifies
//!
//!   M̂ = M − c K_ν,   D̂ = D − c K_η J,
//!
//! J mapping ν to (φ̇, θ̇) near level attitude. A PD attitude loop
//! (K_ν = −K_d) thus inflates the roll and pitch inertia by c·K_d — 8 % on
//! the independent truth's ROVs. The gains are estimated from the log itself:
//! the controller's law is memoryless in the measurements it logs, so
//! Δτ_k = K_ν Δν_k + K_η Δη_k + (integral action, reference switches), fitted
//! per DOF by least squares with the switches trimmed as outliers.

use nalgebra::{DMatrix, DVector};

use super::dataset::Segment;
use super::document::{LoggedController, from_rows, to_rows};
use crate::estimation::lambda::LambdaEstimate;
use crate::numbers::sig3;
use crate::planning::dof::Dof;
use crate::timeseries::median;

/// The controller's gains as seen in the log.
#[derive(Debug, Clone, PartialEq)]
pub struct ControllerGains {
    /// K_ν = ∂τ/∂ν over the modelled DOFs (n × n; rows: forces, columns: ν).
    pub k_nu: DMatrix<f64>,
    /// K_η on (φ, θ) (n × 2); zero when the attitude is not logged.
    pub k_attitude: DMatrix<f64>,
    /// Share of Δτ's variance the law explains, per force DOF (after trimming).
    pub r2: Vec<f64>,
    /// Log intervals used per force DOF.
    pub samples: Vec<usize>,
}

/// Least share of Δτ's variance the feedback law must explain for a force
/// DOF to be corrected: below it the commands between log samples are not
/// a function of the logged measurements (a model-based or filtered
/// controller), and that DOF is left as logged.
pub const MIN_R2: f64 = 0.5;

/// Relative σ of the intersample correction c·K: first order, it takes ν̇
/// constant over the log interval and leaves out the integral action and
/// the sensor noise the controller feeds back, which move M and D̄ in
/// proportion to the same gains. On the independent truth (20 Hz
/// autopilot logged at 10 Hz, 12 vessels) the corrected M's error stays
/// within about half the correction.
pub const CORRECTION_REL_STD: f64 = 0.5;

/// Rows whose residual exceeds this many robust standard deviations are
/// reference switches or integrator resets, not the feedback law.
const TRIM: f64 = 4.0;

/// Least squares of `y` on `x` (rows are samples), re-fitted twice without
/// the rows beyond [`TRIM`] robust σ; returns (coefficients, R², rows kept).
fn trimmed_fit(x: &DMatrix<f64>, y: &DVector<f64>) -> Option<(DVector<f64>, f64, usize)> {
    let mut keep: Vec<usize> = (0..y.len()).collect();
    let mut result = None;
    for _ in 0..3 {
        if keep.len() <= 2 * x.ncols() {
            return None;
        }
        let xs = DMatrix::from_fn(keep.len(), x.ncols(), |i, j| x[(keep[i], j)]);
        let ys = DVector::from_fn(keep.len(), |i, _| y[keep[i]]);
        let theta = xs.svd(true, true).solve(&ys, 1e-12).ok()?;
        let resid: Vec<f64> = (0..y.len())
            .map(|i| y[i] - (x.row(i) * &theta)[0])
            .collect();
        let mut kept: Vec<f64> = keep.iter().map(|&i| resid[i].abs()).collect();
        let ss_res: f64 = kept.iter().map(|v| v * v).sum();
        let scale = 1.4826 * median(&mut kept);
        let mean = ys.mean();
        let ss_tot: f64 = ys.iter().map(|v| (v - mean).powi(2)).sum();
        let r2 = if ss_tot > 0.0 {
            1.0 - ss_res / ss_tot
        } else {
            0.0
        };
        result = Some((theta, r2, keep.len()));
        if scale.is_nan() || scale <= 0.0 {
            break;
        }
        keep = (0..y.len())
            .filter(|&i| resid[i].abs() <= TRIM * scale)
            .collect();
    }
    result
}

/// The gains of the controller behind `segments`: each holds τ in its first
/// n input columns, η = [x y z φ θ ψ] after them when `with_attitude`, and ν
/// (n columns, the modelled DOFs) as outputs. `None` without enough data.
pub fn controller_gains(
    segments: &[&Segment],
    dofs: &[Dof],
    with_attitude: bool,
) -> Option<ControllerGains> {
    let n = dofs.len();
    let q = n + if with_attitude { 2 } else { 0 };
    let mut rows_x: Vec<f64> = Vec::new();
    let mut rows_y: Vec<f64> = Vec::new();
    let mut count = 0;
    for s in segments {
        if s.u.ncols() < n + if with_attitude { 6 } else { 0 } || s.y.ncols() != n {
            continue;
        }
        for k in 0..s.y.nrows().saturating_sub(1) {
            for j in 0..n {
                rows_x.push(s.y[(k + 1, j)] - s.y[(k, j)]);
            }
            if with_attitude {
                for j in [n + 3, n + 4] {
                    rows_x.push(s.u[(k + 1, j)] - s.u[(k, j)]);
                }
            }
            for i in 0..n {
                rows_y.push(s.u[(k + 1, i)] - s.u[(k, i)]);
            }
            count += 1;
        }
    }
    if count <= 4 * q {
        return None;
    }
    let x = DMatrix::from_row_slice(count, q, &rows_x);
    let all_y = DMatrix::from_row_slice(count, n, &rows_y);
    if x.iter().chain(all_y.iter()).any(|v| !v.is_finite()) {
        return None;
    }
    let mut k_nu = DMatrix::zeros(n, n);
    let mut k_attitude = DMatrix::zeros(n, 2);
    let (mut r2, mut samples) = (Vec::new(), Vec::new());
    for i in 0..n {
        let (theta, fit, used) = trimmed_fit(&x, &all_y.column(i).into_owned())?;
        for j in 0..n {
            k_nu[(i, j)] = theta[j];
        }
        if with_attitude {
            k_attitude[(i, 0)] = theta[n];
            k_attitude[(i, 1)] = theta[n + 1];
        }
        r2.push(fit);
        samples.push(used);
    }
    Some(ControllerGains {
        k_nu,
        k_attitude,
        r2,
        samples,
    })
}

/// c = h (r − 1)/(2r) for a controller `ratio` = r times faster than the log
/// at sample time `h` (s).
pub fn hidden_share(h: f64, ratio: f64) -> f64 {
    h * (ratio - 1.0).max(0.0) / (2.0 * ratio.max(1.0))
}

/// M and D̄ of the vehicle from those fitted to the logged τ: M = M̂ + c K_ν
/// and D̄ = D̄̂ + c K_η J (see the module docs), row by row for the force
/// DOFs whose law explains at least [`MIN_R2`] of Δτ; `dofs` order the
/// matrices.
pub fn corrected(
    m_hat: &DMatrix<f64>,
    d_hat: &DMatrix<f64>,
    gains: &ControllerGains,
    dofs: &[Dof],
    c: f64,
) -> (DMatrix<f64>, DMatrix<f64>) {
    let mut m = m_hat.clone();
    let mut d = d_hat.clone();
    for i in (0..dofs.len()).filter(|&i| gains.r2[i] >= MIN_R2) {
        for j in 0..dofs.len() {
            m[(i, j)] += c * gains.k_nu[(i, j)];
        }
        for (a, dof) in [(0, Dof::Roll), (1, Dof::Pitch)] {
            if let Some(j) = dofs.iter().position(|d| *d == dof) {
                d[(i, j)] += c * gains.k_attitude[(i, a)];
            }
        }
    }
    (m, d)
}

/// The controller's gains read from the log and c, when it runs faster than
/// the log at `rate_hz`; `Err` with the note to give when they can't be read.
pub(crate) fn logged_gains(
    segments: &[&Segment],
    dofs: &[Dof],
    with_attitude: bool,
    rate_hz: f64,
) -> Result<Option<(ControllerGains, f64)>, String> {
    let h = segments.first().map_or(0.0, |s| s.h);
    let ratio = rate_hz * h;
    if ratio < 1.0 + 1e-6 {
        return Ok(None);
    }
    let Some(gains) = controller_gains(segments, dofs, with_attitude) else {
        return Err("the controller's gains could not be read from the log (too few samples): M and D̄ are not corrected for its faster rate".into());
    };
    Ok(Some((gains, hidden_share(h, ratio))))
}

/// c·K_ν over the force DOFs that are corrected: the part of the vehicle's
/// M that a fit to the logged τ misses (M̂ = M − c K_ν), so M̂ + c K_ν is
/// what must be symmetric.
pub(crate) fn inertia_offset(gains: &ControllerGains, c: f64) -> DMatrix<f64> {
    DMatrix::from_fn(gains.k_nu.nrows(), gains.k_nu.ncols(), |i, j| {
        if gains.r2[i] >= MIN_R2 {
            c * gains.k_nu[(i, j)]
        } else {
            0.0
        }
    })
}

/// M and D̄ of every sub-model corrected for a controller faster than the
/// log (see the module docs), from [`logged_gains`]; said in `notes`.
pub(crate) fn correct_estimates(
    estimates: Vec<(f64, LambdaEstimate)>,
    gains: Result<Option<(ControllerGains, f64)>, String>,
    h: f64,
    rate_hz: f64,
    dofs: &[Dof],
    notes: &mut Vec<String>,
) -> (Vec<(f64, LambdaEstimate)>, Option<LoggedController>) {
    let (gains, c) = match gains {
        Ok(Some(g)) => g,
        Ok(None) => return (estimates, None),
        Err(note) => {
            notes.push(note);
            return (estimates, None);
        }
    };
    let ratio = rate_hz * h;
    let diag: Vec<String> = dofs
        .iter()
        .enumerate()
        .map(|(i, d)| match gains.r2[i] >= MIN_R2 {
            true => format!("{} {}", d.name(), sig3(gains.k_nu[(i, i)])),
            false => format!("{} not corrected (R² {:.2})", d.name(), gains.r2[i]),
        })
        .collect();
    notes.push(format!(
        "controller at {ratio:.2}× the log rate: the commands between log samples were rebuilt from its gains, read from the log (∂τ/∂ν diagonal, N·s/m and N·m·s/rad: {}; least squares on Δτ, switches trimmed, R² {:.2}–{:.2}); M changed by c·K_ν and D̄ by c·K_η with c = {:.4} s; predictions on these logs add the unlogged commands back",
        diag.join(", "),
        gains.r2.iter().copied().fold(f64::INFINITY, f64::min),
        gains.r2.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        c
    ));
    let applied = |k: &DMatrix<f64>| {
        DMatrix::from_fn(k.nrows(), k.ncols(), |i, j| {
            if gains.r2[i] >= MIN_R2 {
                k[(i, j)]
            } else {
                0.0
            }
        })
    };
    let controller = LoggedController {
        rate_hz,
        log_h_s: h,
        c_s: c,
        k_nu: to_rows(&applied(&gains.k_nu)),
        k_attitude: to_rows(&applied(&gains.k_attitude)),
    };
    let corrected = estimates
        .into_iter()
        .map(|(speed, mut est)| {
            // D̄ as a whole is what the data determine (its C(ν) part from M
            // included), so only c·K_η J moves it.
            let (mut m, d) = corrected(&est.m, &est.d_bar, &gains, dofs, c);
            // A fit under M + c K_ν = (M + c K_ν)ᵀ: couplings the structure
            // keeps apart stay zero in M (a cross gain read from noisy logs
            // is no inertia), so the corrected M is symmetric.
            if est.symmetry.is_some() {
                let blocks = est.mask.blocks();
                for ((x, &keep), &orig) in m.iter_mut().zip(blocks.iter()).zip(est.m.iter()) {
                    if !keep {
                        *x = orig;
                    }
                }
            }
            est.m = m;
            est.d_bar = d;
            widen_by_correction(&mut est, &gains, dofs, c);
            (speed, est)
        })
        .collect();
    (corrected, Some(controller))
}

/// The correction's own σ: [`CORRECTION_REL_STD`] of each entry it moved,
/// added in quadrature to the fit's σ of M and D̄.
fn widen_by_correction(est: &mut LambdaEstimate, gains: &ControllerGains, dofs: &[Dof], c: f64) {
    let add = |s: &mut f64, shift: f64| {
        let extra = CORRECTION_REL_STD * shift.abs();
        if extra > 0.0 && extra.is_finite() {
            *s = s.hypot(extra);
        }
    };
    for i in (0..dofs.len()).filter(|&i| gains.r2[i] >= MIN_R2) {
        for j in 0..dofs.len() {
            if est.std_m[(i, j)] > 0.0 {
                add(&mut est.std_m[(i, j)], c * gains.k_nu[(i, j)]);
            }
        }
        for (a, dof) in [(0, Dof::Roll), (1, Dof::Pitch)] {
            if let Some(j) = dofs.iter().position(|d| *d == dof)
                && est.std_d_bar[(i, j)] > 0.0
            {
                add(&mut est.std_d_bar[(i, j)], c * gains.k_attitude[(i, a)]);
            }
        }
    }
}

/// M and D̄ as a log of `controller` sees them (M − c K_ν, D̄ − c K_η J):
/// the model that predicts ν from the logged τ held over each interval.
pub fn logged_equivalent(
    m: &DMatrix<f64>,
    d_bar: &DMatrix<f64>,
    controller: &LoggedController,
    dofs: &[Dof],
) -> Option<(DMatrix<f64>, DMatrix<f64>)> {
    shifted(m, d_bar, controller, dofs, -controller.c_s)
}

/// The error for a stored controller whose gains do not fit the model.
pub(crate) fn malformed_controller() -> super::error::IdentifyError {
    super::error::IdentifyError::invalid(
        "document.lpv.logged_controller",
        "K_ν must be n × n and K_η n × 2",
    )
}

/// The vehicle's M and D̄ from those a log of `controller` sees: the
/// inverse of [`logged_equivalent`].
pub fn vehicle_from_logged(
    m: &DMatrix<f64>,
    d_bar: &DMatrix<f64>,
    controller: &LoggedController,
    dofs: &[Dof],
) -> Option<(DMatrix<f64>, DMatrix<f64>)> {
    shifted(m, d_bar, controller, dofs, controller.c_s)
}

fn shifted(
    m: &DMatrix<f64>,
    d_bar: &DMatrix<f64>,
    controller: &LoggedController,
    dofs: &[Dof],
    c: f64,
) -> Option<(DMatrix<f64>, DMatrix<f64>)> {
    let n = dofs.len();
    let k_nu = from_rows(&controller.k_nu).filter(|k| k.shape() == (n, n))?;
    let k_attitude = from_rows(&controller.k_attitude).filter(|k| k.shape() == (n, 2))?;
    let gains = ControllerGains {
        k_nu,
        k_attitude,
        r2: vec![1.0; n],
        samples: vec![0; n],
    };
    Some(corrected(m, d_bar, &gains, dofs, c))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_vehicle_view_inverts_the_logged_view() {
        let controller = LoggedController {
            rate_hz: 20.0,
            log_h_s: 0.1,
            c_s: 0.025,
            k_nu: vec![vec![-400.0, 3.0], vec![-2.0, -60.0]],
            k_attitude: vec![vec![0.0, 5.0], vec![-7.0, 0.0]],
        };
        let dofs = [Dof::Roll, Dof::Pitch];
        let m = DMatrix::from_row_slice(2, 2, &[30.0, 1.0, 1.0, 40.0]);
        let d = DMatrix::from_row_slice(2, 2, &[5.0, 0.5, 0.2, 8.0]);
        let (ml, dl) = logged_equivalent(&m, &d, &controller, &dofs).unwrap();
        assert!(
            (ml[(0, 0)] - 40.0).abs() < 1e-12 && (dl[(1, 0)] - (0.2 + 0.025 * 7.0)).abs() < 1e-12
        );
        let (mv, dv) = vehicle_from_logged(&ml, &dl, &controller, &dofs).unwrap();
        assert!((mv - &m).abs().max() < 1e-12 && (dv - &d).abs().max() < 1e-12);
        let bad = LoggedController {
            k_nu: vec![vec![1.0]],
            ..controller
        };
        assert!(vehicle_from_logged(&m, &d, &bad, &dofs).is_none());
    }
    use crate::rng::SplitMix64;

    /// Roll of a pendulum-like vehicle, M ṗ + D p + K φ = τ, under a PD
    /// loop τ = −k_p (φ_m − φ_ref) − k_d p_m at 20 Hz on noisy measurements
    /// (φ_ref a square wave switching on controller ticks), integrated at
    /// 1 kHz and logged at 10 Hz.
    fn flown(k_p: f64, k_d: f64) -> Segment {
        let (m, d, k) = (40.0, 12.0, 300.0);
        let mut rng = SplitMix64::new(7);
        let (mut phi, mut p) = (0.0f64, 0.0f64);
        let (mut u, mut y) = (Vec::new(), Vec::new());
        let ticks = 20 * 300;
        for j in 0..ticks {
            let reference = if (j / 97) % 2 == 0 { 0.1 } else { -0.1 };
            let (phi_m, p_m) = (phi + 0.002 * rng.normal(), p + 0.004 * rng.normal());
            let tau = -k_p * (phi_m - reference) - k_d * p_m;
            if j % 2 == 0 {
                // τ_roll, then η = [x y z φ θ ψ].
                u.extend([tau, 0.0, 0.0, 0.0, phi_m, 0.0, 0.0]);
                y.push(p_m);
            }
            for _ in 0..50 {
                let acc = (tau - d * p - k * phi.sin()) / m;
                phi += 1e-3 * p;
                p += 1e-3 * acc;
            }
        }
        let rows = y.len();
        Segment {
            run_id: "roll".into(),
            h: 0.1,
            t0: 0.0,
            u: DMatrix::from_row_slice(rows, 7, &u),
            y: DMatrix::from_row_slice(rows, 1, &y),
        }
    }

    #[test]
    fn a_pd_loop_is_read_from_its_log_despite_reference_switches() {
        let seg = flown(400.0, 120.0);
        let g = controller_gains(&[&seg], &[Dof::Roll], true).unwrap();
        assert!((g.k_nu[(0, 0)] + 120.0).abs() < 2.0, "K_ν = {}", g.k_nu);
        assert!(
            (g.k_attitude[(0, 0)] + 400.0).abs() < 8.0,
            "K_φ = {}",
            g.k_attitude
        );
        assert!(g.r2[0] > 0.99, "{:?}", g.r2);
        // The switches were trimmed, not fitted.
        assert!(g.samples[0] < seg.y.nrows() - 1);
    }

    #[test]
    fn the_correction_removes_c_times_the_gains() {
        let g = ControllerGains {
            k_nu: DMatrix::from_row_slice(2, 2, &[-120.0, 0.0, 0.0, -50.0]),
            k_attitude: DMatrix::from_row_slice(2, 2, &[-400.0, 0.0, 0.0, -300.0]),
            r2: vec![1.0, 1.0],
            samples: vec![100, 100],
        };
        let c = hidden_share(0.1, 2.0);
        assert!((c - 0.025).abs() < 1e-15);
        assert_eq!(hidden_share(0.1, 1.0), 0.0);
        let dofs = [Dof::Roll, Dof::Pitch];
        let m_hat = DMatrix::from_row_slice(2, 2, &[43.0, 0.0, 0.0, 90.0]);
        let d_hat = DMatrix::from_row_slice(2, 2, &[22.0, 0.0, 0.0, 27.5]);
        let (m, d) = corrected(&m_hat, &d_hat, &g, &dofs, c);
        assert!((m[(0, 0)] - 40.0).abs() < 1e-12 && (m[(1, 1)] - 88.75).abs() < 1e-12);
        assert!((d[(0, 0)] - 12.0).abs() < 1e-12 && (d[(1, 1)] - 20.0).abs() < 1e-12);
        // A pitch law that explains little of Δτ leaves pitch as fitted.
        let weak = ControllerGains {
            r2: vec![1.0, 0.2],
            ..g.clone()
        };
        let (m, d) = corrected(&m_hat, &d_hat, &weak, &dofs, c);
        assert!((m[(0, 0)] - 40.0).abs() < 1e-12 && m[(1, 1)] == 90.0 && d[(1, 1)] == 27.5);
        // What the log sees is the fitted pair again.
        let lc = LoggedController {
            rate_hz: 20.0,
            log_h_s: 0.1,
            c_s: c,
            k_nu: to_rows(&g.k_nu),
            k_attitude: to_rows(&g.k_attitude),
        };
        let (m_phys, d_phys) = corrected(&m_hat, &d_hat, &g, &dofs, c);
        let (m_log, d_log) = logged_equivalent(&m_phys, &d_phys, &lc, &dofs).unwrap();
        assert!((m_log - &m_hat).abs().max() < 1e-12 && (d_log - &d_hat).abs().max() < 1e-12);
        let bad = LoggedController {
            k_nu: vec![vec![1.0]],
            ..lc
        };
        assert!(logged_equivalent(&m_phys, &d_phys, &bad, &dofs).is_none());
    }
}
