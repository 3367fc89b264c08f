//! Subspace identification (N4SID family) of combined deterministic–
//! stochastic LTI models from sea-trial runs, at a cost linear in the
//! number of samples.
//!
//! Van Overschee & De Moor (1994, 1996), with the notation U_p, U_f, Y_p,
//! Y_f (past/future block-Hankel inputs and outputs, i block rows each),
//! O_i (oblique projection Y_f /_{U_f} W_p), Γ_i (extended observability
//! matrix), W₁ O_i W₂ (weighted projection):
//!
//! 1. [`hankel`]: L of H = [U_f; U_p; Y_p; Y_f] = L Qᵀ (never N × N, never
//!    H in full): the Cholesky factor of H Hᵀ built from lagged
//!    cross-products ([`gram`]) when H is well conditioned, else chunked QR;
//!    several runs stack their Hankel columns, each run with its own
//!    initial state (never concatenated signals).
//! 2. [`projection`]: O_i, weighting (N4SID, MOESP, CVA), thin SVD, order
//!    from the singular-value gap or fixed, Γ_i and the state map.
//! 3. [`system`]: A, B, C, D by least squares on the estimated states
//!    X̂_i = Γ_i^† O_i and X̂_{i+1} = Γ_{i−1}^† O_{i+1}, residual covariances.
//! 4. [`riccati`]: K of the innovation form from Q, S, R (filter DARE).
//!
//! The variant implemented is the state-sequence ("Algorithm 1"-type)
//! N4SID with MOESP weighting by default; it is consistent for white or
//! persistently exciting inputs as i grows, and exact on noise-free data.
//!
//! Every channel is scaled to unit RMS before the Hankel step (conditioning
//! and a scale-free order choice); the model is returned in physical units.
//! Offsets are not removed: pass deviations from the trim point.
//!
//! Memory: beyond the caller's signals, the largest allocation is r × r
//! on the Gram route and at most the QR work matrix (c + r) × r doubles, r = 2i(m + l), c = chunk rows (default
//! 8r): independent of N. For i = 10, m = l = 6: r = 240, 4.1 MB.

pub mod continuous;
pub mod error;
mod gram;
mod hankel;
pub mod model;
mod projection;
pub mod riccati;
pub mod settings;
mod system;

#[cfg(test)]
mod tests;

pub use continuous::{ContinuousModel, D2cError, d2c};
pub use error::N4sidError;
pub use model::{N4sidModel, NoiseCovariances};
pub use riccati::{KalmanGain, kalman_gain};
pub use settings::{N4sidSettings, Weighting};

use nalgebra::DMatrix;

use crate::estimation::{Progress, SubProgress};
use hankel::Layout;

/// Default chunk rows per QR update, as a multiple of r = 2i(m + l):
/// measured fastest between 4r and 16r, and the work matrix stays small.
const CHUNK_FACTOR: usize = 8;

/// Output residual variance (scaled units) below which the data are taken
/// as noise-free when the Riccati equation has no solution.
const DETERMINISTIC_RESIDUAL: f64 = 1e-12;

/// Identifies an innovation-form model from one or more experiments
/// `(u, y)` (N_e × m inputs, N_e × l outputs, one row per sample).
pub fn n4sid(
    experiments: &[(&DMatrix<f64>, &DMatrix<f64>)],
    settings: &N4sidSettings,
    progress: &mut dyn Progress,
) -> Result<N4sidModel, N4sidError> {
    let (m, l) = check_inputs(experiments, settings)?;
    let i = settings.horizon;
    let layout = Layout { m, l, i };
    let (u_scale, y_scale) = channel_scales(experiments, m, l)?;
    let r = layout.rows();
    let chunk = settings.chunk_rows.unwrap_or(CHUNK_FACTOR * r);
    let (lq, _route) = hankel::hankel_lq(
        experiments,
        &u_scale,
        &y_scale,
        layout,
        chunk,
        &mut SubProgress::new(progress, 0.0, 0.95),
    )?;
    check_excitation(&lq)?;
    progress.update(0.95, "oblique projection and SVD")?;
    let sub = projection::subspace(&lq, settings.weighting, settings.order, settings.max_order)?;
    progress.update(0.97, "least squares on the states")?;
    let fit = system::fit_state_space(&lq, &sub, settings.estimate_d)?;
    let kg = match riccati::kalman_gain(&fit.a, &fit.c, &fit.q, &fit.s, &fit.r) {
        Ok(kg) => kg,
        // Noise-free data (output residual below 1e-6 of the unit RMS): the
        // model is deterministic and any K is a predictor; K = 0.
        Err(_) if fit.r.trace() <= DETERMINISTIC_RESIDUAL * l as f64 => KalmanGain {
            p: DMatrix::zeros(sub.order, sub.order),
            k: DMatrix::zeros(sub.order, l),
            innovation_covariance: fit.r.clone(),
        },
        Err(e) => return Err(e),
    };
    progress.update(1.0, "done")?;

    // Back to physical units: u_s = Su⁻¹ u, y_s = Sy⁻¹ y.
    let su_inv = DMatrix::from_diagonal(&nalgebra::DVector::from_iterator(
        m,
        u_scale.iter().map(|s| 1.0 / s),
    ));
    let sy = DMatrix::from_diagonal(&nalgebra::DVector::from_column_slice(&y_scale));
    let sy_inv = DMatrix::from_diagonal(&nalgebra::DVector::from_iterator(
        l,
        y_scale.iter().map(|s| 1.0 / s),
    ));
    Ok(N4sidModel {
        b: &fit.b * &su_inv,
        c: &sy * &fit.c,
        d: &sy * &fit.d * &su_inv,
        k: &kg.k * &sy_inv,
        a: fit.a,
        h: settings.h,
        order: sub.order,
        horizon: i,
        weighting: settings.weighting,
        singular_values: sub.singular_values,
        noise: NoiseCovariances {
            q: fit.q,
            s: &fit.s * &sy,
            r: &sy * &fit.r * &sy,
        },
        innovation_covariance: &sy * &kg.innovation_covariance * &sy,
        state_covariance: kg.p,
        hankel_columns: lq.columns,
        output_names: (0..l).map(|k| format!("y{k}")).collect(),
    })
}

/// Shapes, finiteness, sample counts and settings; returns (m, l).
fn check_inputs(
    experiments: &[(&DMatrix<f64>, &DMatrix<f64>)],
    settings: &N4sidSettings,
) -> Result<(usize, usize), N4sidError> {
    let setting = |field, reason: &str| N4sidError::Setting {
        field,
        reason: reason.to_string(),
    };
    if !(settings.h.is_finite() && settings.h > 0.0) {
        return Err(setting("h", "sample time must be positive and finite"));
    }
    if settings.horizon < 2 {
        return Err(setting("horizon", "must be at least 2"));
    }
    if settings.chunk_rows == Some(0) {
        return Err(setting("chunk_rows", "must be at least 1"));
    }
    let (u0, y0) = experiments.first().ok_or(N4sidError::NoExperiments)?;
    let (m, l) = (u0.ncols(), y0.ncols());
    if m == 0 {
        return Err(N4sidError::Shape {
            experiment: 0,
            field: "u",
            expected: "at least one input column".into(),
            found: "0 columns".into(),
        });
    }
    if l == 0 {
        return Err(N4sidError::Shape {
            experiment: 0,
            field: "y",
            expected: "at least one output column".into(),
            found: "0 columns".into(),
        });
    }
    let i = settings.horizon;
    let mut columns = 0usize;
    for (e, (u, y)) in experiments.iter().enumerate() {
        if u.ncols() != m {
            return Err(N4sidError::Shape {
                experiment: e,
                field: "u",
                expected: format!("{m} columns"),
                found: format!("{} columns", u.ncols()),
            });
        }
        if y.ncols() != l || y.nrows() != u.nrows() {
            return Err(N4sidError::Shape {
                experiment: e,
                field: "y",
                expected: format!("{} × {l}", u.nrows()),
                found: format!("{} × {}", y.nrows(), y.ncols()),
            });
        }
        for (field, sig) in [("u", u), ("y", y)] {
            if let Some(k) = sig.iter().position(|v| !v.is_finite()) {
                return Err(N4sidError::NonFinite {
                    experiment: e,
                    field,
                    row: k % sig.nrows(),
                    column: k / sig.nrows(),
                });
            }
        }
        if u.nrows() < 2 * i {
            return Err(N4sidError::TooFewSamples {
                field: "experiments[].u",
                samples: u.nrows(),
                required: 2 * i,
            });
        }
        columns += u.nrows() + 1 - 2 * i;
    }
    let r = 2 * i * (m + l);
    if columns < 2 * r {
        // Fewer Hankel columns than twice the rows: L is not determined.
        return Err(N4sidError::TooFewSamples {
            field: "experiments",
            samples: columns + experiments.len() * (2 * i - 1),
            required: 2 * r + experiments.len() * (2 * i - 1),
        });
    }
    if let Some(n) = settings.order {
        if n > settings.max_order {
            return Err(N4sidError::OrderTooLarge {
                field: "order",
                order: n,
                max: settings.max_order,
            });
        }
        if n > l * (i - 1) {
            // X̂_{i+1} needs Γ_{i−1} (l(i−1) rows) of full column rank.
            return Err(N4sidError::OrderTooLarge {
                field: "horizon",
                order: n,
                max: l * (i - 1),
            });
        }
    }
    Ok((m, l))
}

/// RMS of every channel over all experiments (zero is an error).
fn channel_scales(
    experiments: &[(&DMatrix<f64>, &DMatrix<f64>)],
    m: usize,
    l: usize,
) -> Result<(Vec<f64>, Vec<f64>), N4sidError> {
    fn rms<'a>(
        field: &'static str,
        cols: impl Iterator<Item = &'a [f64]> + Clone,
        column: usize,
    ) -> Result<f64, N4sidError> {
        let n: usize = cols.clone().map(|c| c.len()).sum();
        let ss: f64 = cols.flat_map(|c| c.iter()).map(|v| v * v).sum();
        let s = (ss / n as f64).sqrt();
        if s > 0.0 && s.is_finite() {
            Ok(s)
        } else {
            Err(N4sidError::ZeroChannel { field, column })
        }
    }
    let us = (0..m)
        .map(|ch| {
            rms(
                "u",
                experiments.iter().map(|(u, _)| hankel::column(u, ch)),
                ch,
            )
        })
        .collect::<Result<Vec<_>, _>>()?;
    let ys = (0..l)
        .map(|ch| {
            rms(
                "y",
                experiments.iter().map(|(_, y)| hankel::column(y, ch)),
                ch,
            )
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok((us, ys))
}

/// [U_f; U_p] must have full row rank (inputs persistently exciting of
/// order 2i): its rows are the first 2mi of H, so the diagonal of L says.
fn check_excitation(lq: &hankel::HankelLq) -> Result<(), N4sidError> {
    let rows = 2 * lq.layout.mi();
    let diag: Vec<f64> = (0..rows).map(|k| lq.l[(k, k)].abs()).collect();
    let max = diag.iter().copied().fold(0.0, f64::max);
    match diag.iter().position(|&d| d <= 1e-9 * max) {
        Some(k) => Err(N4sidError::NotPersistentlyExciting { block_row: k }),
        None => Ok(()),
    }
}
