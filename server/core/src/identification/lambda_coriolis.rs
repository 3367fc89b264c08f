//! C(ν)ν from M at the grid speed (Fossen 2011, eq. 6.43): at forward speed
//! u₀ the Coriolis and centripetal forces of rigid body and added mass
//! couple surge–heave–pitch and sway–roll–yaw (the Munk moment among them)
//! by terms fixed by M and u₀. Linearized about ν₀ = (u₀, 0, …),
//! C(ν)ν ≈ C(ν₀)ν₀ + J_C(M, u₀)(ν − ν₀), so the sub-model is
//!
//! M ν̇ + (D + J_C) ν + b = γ,
//!
//! D the damping (dissipative), b absorbing the constant part. The λ
//! regression is linear in M and D only through A_λ, B_λ, so J_C is moved to
//! the known side, γ' = γ − J_C(M̂)ν, with M̂ from the previous pass, and
//! the fit repeated to a fixed point. The structure's mask then constrains
//! D (and M), while the couplings at speed come from physics, not from
//! free entries the data barely determine.

use nalgebra::{DMatrix, DVector};

use super::document::{LpvDoc, from_rows};
use crate::estimation::lambda::{
    Experiment, Inversion, LambdaError, LambdaEstimate, LambdaSettings, identify,
};
use crate::estimation::{Cancelled, NoProgress, Progress};
use crate::models::coriolis::{coriolis, second_order_force_about};
use crate::planning::dof::Dof;

/// Fixed-point passes of M̂ → J_C → fit.
pub(crate) const PASSES: usize = 3;

/// J_C = ∂(C(ν)ν)/∂ν at ν₀ = (u₀, 0, …) from sym(M), for the 6-DOF or
/// the 3-DOF horizontal DOF set; `None` for other sets (no C(ν) form).
/// C(ν)ν is quadratic in ν, so central differences are exact.
pub(crate) fn coriolis_jacobian(m: &DMatrix<f64>, dofs: &[Dof], u0: f64) -> Option<DMatrix<f64>> {
    let n = dofs.len();
    let six = dofs == Dof::ALL;
    let three = dofs == [Dof::Surge, Dof::Sway, Dof::Yaw];
    if !(six || three) {
        return None;
    }
    let ms = (m + m.transpose()) * 0.5;
    let f = |nu: &DVector<f64>| coriolis(&ms, nu).ok().map(|c| c * nu);
    let mut nu0 = DVector::zeros(n);
    nu0[0] = u0;
    let step = 1.0;
    let mut j = DMatrix::zeros(n, n);
    for c in 0..n {
        let mut plus = nu0.clone();
        plus[c] += step;
        let mut minus = nu0.clone();
        minus[c] -= step;
        let d = (f(&plus)? - f(&minus)?) / (2.0 * step);
        j.set_column(c, &d);
    }
    j.iter().all(|v| v.is_finite()).then_some(j)
}

/// The vehicle's M, DOFs and grid speed for C(δ)δ on the known side.
struct SecondOrder<'a> {
    m: &'a DMatrix<f64>,
    dofs: &'a [Dof],
    surge: usize,
    u0: f64,
}

/// γ' = γ − J ν̄ (and − C(δ̄)δ̄, δ̄ = ν̄ − (u₀, 0, …), with `second`) per
/// run, with ν̄ the step mean ½(ν_k + ν_{k+1}) (held over the step like γ).
fn moved(exps: &[Experiment], j: &DMatrix<f64>, second: Option<&SecondOrder>) -> Vec<Experiment> {
    exps.iter()
        .map(|e| {
            let rows = e.nu.nrows();
            let mut g = e.gamma.clone();
            for k in 0..rows {
                let next = if k + 1 < rows { k + 1 } else { k };
                let nu = (e.nu.row(k) + e.nu.row(next)).transpose() * 0.5;
                let mut f = j * &nu;
                if let Some(s) = second {
                    let c = second_order_force_about(s.dofs, s.m, nu.as_slice(), s.surge, s.u0);
                    f += DVector::from_vec(c);
                }
                for i in 0..g.ncols() {
                    g[(k, i)] -= f[i];
                }
            }
            Experiment {
                h: e.h,
                nu: e.nu.clone(),
                gamma: g,
                exogenous: e.exogenous.clone(),
            }
        })
        .collect()
}

/// The sub-model at `u0` with C(ν)ν from its own M: returns the estimate
/// with `d_bar` = D + J_C (and A, B consistent with it) and J_C. M is the
/// vehicle's: the fit's M̂ plus the settings' inertia offset (what a
/// controller faster than the log hides). Without a C(ν) form for the DOF
/// set, the plain fit.
pub(crate) fn identify_with_coriolis(
    exps: &[Experiment],
    settings: &LambdaSettings,
    u0: f64,
    progress: &mut dyn Progress,
) -> Result<(LambdaEstimate, Option<DMatrix<f64>>), LambdaError> {
    let mut est = identify(exps, settings)?;
    let mut jc = None;
    for pass in 0..PASSES {
        progress
            .update(pass as f64 / PASSES as f64, "C(ν) from M at the grid speed")
            .map_err(|Cancelled| LambdaError::Cancelled)?;
        let vehicle = match &settings.inertia_offset {
            Some(s) if s.shape() == est.m.shape() => &est.m + s,
            _ => est.m.clone(),
        };
        let Some(j) = coriolis_jacobian(&vehicle, &settings.dofs, u0) else {
            return Ok((est, None));
        };
        let surge = settings.dofs.iter().position(|d| *d == Dof::Surge);
        let second = match surge {
            Some(surge) if settings.second_order_coriolis => Some(SecondOrder {
                m: &vehicle,
                dofs: &settings.dofs,
                surge,
                u0,
            }),
            _ => None,
        };
        est = identify(&moved(exps, &j, second.as_ref()), settings)?;
        jc = Some(j);
    }
    if let Some(j) = &jc {
        // The fit is of D; the sub-model's D̄ carries C(ν)'s linearization.
        est.d_bar += j;
        est.a = -(&est.b * &est.d_bar);
    }
    Ok((est, jc))
}

/// Every grid point's sub-model ([`identify_with_coriolis`] when
/// `coriolis`, else the plain fit). The points are independent: they are
/// fitted side by side on the pool, as many at a time as it has threads,
/// and progress (and a cancel) is taken between those rounds. The first
/// error by point is returned, as in order.
pub(crate) fn fit_points(
    points: &[(f64, Vec<Experiment>)],
    settings: &LambdaSettings,
    coriolis: bool,
    progress: &mut dyn Progress,
    notes: &mut Vec<String>,
) -> Result<Vec<(f64, LambdaEstimate)>, LambdaError> {
    use rayon::prelude::*;
    let count = points.len().max(1);
    let width = rayon::current_num_threads().max(1);
    let mut out = Vec::with_capacity(points.len());
    for round in points.chunks(width) {
        let done = out.len();
        progress
            .update(
                done as f64 / count as f64,
                &format!("grid point {:.2} m/s", round[0].0),
            )
            .map_err(|Cancelled| LambdaError::Cancelled)?;
        let fitted: Vec<_> = round
            .par_iter()
            .map(|(u0, exps)| fit_point(*u0, exps, settings, coriolis))
            .collect();
        for ((u0, _), r) in round.iter().zip(fitted) {
            let (est, note) = r?;
            notes.extend(note);
            out.push((*u0, est));
        }
    }
    progress
        .update(1.0, "grid points fitted")
        .map_err(|Cancelled| LambdaError::Cancelled)?;
    Ok(out)
}

/// One grid point's fit, with a note when the exact sampled-data map had
/// to give way to the thesis's.
fn fit_point(
    u0: f64,
    exps: &[Experiment],
    settings: &LambdaSettings,
    coriolis: bool,
) -> Result<(LambdaEstimate, Option<String>), LambdaError> {
    let fit = |s: &LambdaSettings| {
        if coriolis {
            identify_with_coriolis(exps, s, u0, &mut NoProgress).map(|r| r.0)
        } else {
            identify(exps, s)
        }
    };
    match fit(settings) {
        // A mode faster than the sample rate leaves Φ with a negative
        // eigenvalue, which has no continuous-time logarithm: the
        // thesis's map (eq. 2.14–2.15) still gives a model.
        Err(e) if e.field() == "a_lambda" && settings.inversion == Inversion::Exact => {
            let mut thesis = settings.clone();
            thesis.inversion = Inversion::Thesis;
            let note = format!(
                "at {u0:.2} m/s the exact sampled-data map failed ({e}); the thesis's map A = (A_λ − I)/T was used"
            );
            Ok((fit(&thesis)?, Some(note)))
        }
        r => Ok((r?, None)),
    }
}

/// One M for the vehicle from the grid points' `m` with their σ `std`:
/// per entry the inverse-variance mean (an entry fixed at every point, σ 0,
/// keeps the plain mean). M does not change with speed, and C(δ)δ built
/// from a point the data determine poorly (vessel 5 of the independent
/// truth at 2 m/s: heave 307 ± 48 against 227, pitch 23 ± 7 against 11)
/// puts a false Munk-type roll moment (Y_v̇ − Z_ẇ) v w into every step.
/// `None` when the pooled M is not symmetric positive definite.
pub(crate) fn pooled_inertia(m: &[DMatrix<f64>], std: &[DMatrix<f64>]) -> Option<DMatrix<f64>> {
    let first = m.first()?;
    let (r, c) = first.shape();
    if m.len() != std.len() || m.iter().chain(std).any(|x| x.shape() != (r, c)) {
        return None;
    }
    let pooled = DMatrix::from_fn(r, c, |i, j| {
        let weights: Vec<f64> = std
            .iter()
            .map(|s| {
                let v = s[(i, j)];
                if v > 0.0 && v.is_finite() {
                    1.0 / (v * v)
                } else {
                    0.0
                }
            })
            .collect();
        let total: f64 = weights.iter().sum();
        if total > 0.0 && weights.iter().all(|w| *w > 0.0) {
            m.iter()
                .zip(&weights)
                .map(|(x, w)| w * x[(i, j)])
                .sum::<f64>()
                / total
        } else {
            m.iter().map(|x| x[(i, j)]).sum::<f64>() / m.len() as f64
        }
    });
    let sym = (&pooled + pooled.transpose()) * 0.5;
    (sym.iter().all(|x| x.is_finite()) && sym.clone().cholesky().is_some()).then_some(sym)
}

/// The M of C(δ)δ in a stored LPV document: its points' `m` pooled by
/// [`pooled_inertia`], as the identification built it; `None` when a
/// matrix is ragged or the pool is not positive definite (then each
/// point's own M serves).
pub(crate) fn document_inertia(lpv: &LpvDoc) -> Option<DMatrix<f64>> {
    let m: Option<Vec<_>> = lpv.points.iter().map(|p| from_rows(&p.m)).collect();
    let std: Option<Vec<_>> = lpv.points.iter().map(|p| from_rows(&p.m_std)).collect();
    pooled_inertia(&m?, &std?)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two points: heave 230 ± 5 and 310 ± 50 pool to (230/25 + 310/2500) /
    /// (1/25 + 1/2500) = 230.79; an entry with σ 0 at one point (fixed)
    /// takes the plain mean; a pooled M that is not positive definite is
    /// refused.
    #[test]
    fn the_vehicle_inertia_pools_the_grid_points_by_inverse_variance() {
        let m1 = DMatrix::from_row_slice(2, 2, &[230.0, 4.0, 4.0, 10.0]);
        let m2 = DMatrix::from_row_slice(2, 2, &[310.0, 6.0, 6.0, 20.0]);
        let s1 = DMatrix::from_row_slice(2, 2, &[5.0, 1.0, 1.0, 0.0]);
        let s2 = DMatrix::from_row_slice(2, 2, &[50.0, 1.0, 1.0, 2.0]);
        let p = pooled_inertia(&[m1.clone(), m2.clone()], &[s1.clone(), s2.clone()]).unwrap();
        let heave = (230.0 / 25.0 + 310.0 / 2500.0) / (1.0 / 25.0 + 1.0 / 2500.0);
        assert!((p[(0, 0)] - heave).abs() < 1e-9, "{}", p[(0, 0)]);
        assert!((p[(0, 1)] - 5.0).abs() < 1e-12 && (p[(1, 0)] - 5.0).abs() < 1e-12);
        assert!((p[(1, 1)] - 15.0).abs() < 1e-12);
        let bad = DMatrix::from_row_slice(2, 2, &[1.0, 5.0, 5.0, 1.0]);
        assert!(pooled_inertia(&[bad.clone(), bad], &[s1.clone(), s1]).is_none());
        assert!(pooled_inertia(&[m1], &[]).is_none());
    }

    #[test]
    fn the_jacobian_of_a_diagonal_mass_at_speed_is_the_munk_and_yaw_coupling() {
        // Diagonal M = diag(m11 … m66): at ν₀ = (u₀, 0, …), C(ν)ν's
        // linearization has sway–yaw entries m11·u₀ (Y_r) and
        // (m22 − m11)·u₀ (N_v, the Munk moment), likewise heave–pitch.
        let m = DMatrix::from_diagonal(&DVector::from_vec(vec![
            300.0, 500.0, 600.0, 40.0, 90.0, 80.0,
        ]));
        let u0 = 1.5;
        let j = coriolis_jacobian(&m, &Dof::ALL, u0).unwrap();
        assert!((j[(1, 5)] - 300.0 * u0).abs() < 1e-9, "{j}");
        assert!((j[(5, 1)] - (500.0 - 300.0) * u0).abs() < 1e-9, "{j}");
        assert!((j[(2, 4)] + 300.0 * u0).abs() < 1e-9, "{j}");
        assert!((j[(4, 2)] + (600.0 - 300.0) * u0).abs() < 1e-9, "{j}");
        assert!(j[(0, 0)].abs() < 1e-9 && j[(1, 1)].abs() < 1e-9);
        assert!(
            coriolis_jacobian(
                &m.view((0, 0), (2, 2)).into_owned(),
                &[Dof::Surge, Dof::Heave],
                u0
            )
            .is_none()
        );
    }
}
