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

use crate::estimation::lambda::{Experiment, Inversion, LambdaEstimate, LambdaSettings, identify};
use crate::estimation::{Cancelled, Progress};
use crate::models::coriolis::coriolis;
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

/// γ' = γ − J ν̄ per run, with ν̄ the step mean ½(ν_k + ν_{k+1}) (held
/// over the step like γ).
fn moved(exps: &[Experiment], j: &DMatrix<f64>) -> Vec<Experiment> {
    exps.iter()
        .map(|e| {
            let rows = e.nu.nrows();
            let mut g = e.gamma.clone();
            for k in 0..rows {
                let next = if k + 1 < rows { k + 1 } else { k };
                let nu = (e.nu.row(k) + e.nu.row(next)).transpose() * 0.5;
                let f = j * nu;
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
) -> Result<(LambdaEstimate, Option<DMatrix<f64>>), crate::estimation::lambda::LambdaError> {
    let mut est = identify(exps, settings)?;
    let mut jc = None;
    for pass in 0..PASSES {
        progress
            .update(pass as f64 / PASSES as f64, "C(ν) from M at the grid speed")
            .map_err(|Cancelled| crate::estimation::lambda::LambdaError::Cancelled)?;
        let vehicle = match &settings.inertia_offset {
            Some(s) if s.shape() == est.m.shape() => &est.m + s,
            _ => est.m.clone(),
        };
        let Some(j) = coriolis_jacobian(&vehicle, &settings.dofs, u0) else {
            return Ok((est, None));
        };
        est = identify(&moved(exps, &j), settings)?;
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
/// `coriolis`, else the plain fit), progress spread over the points.
pub(crate) fn fit_points(
    points: &[(f64, Vec<Experiment>)],
    settings: &LambdaSettings,
    coriolis: bool,
    progress: &mut dyn Progress,
    notes: &mut Vec<String>,
) -> Result<Vec<(f64, LambdaEstimate)>, crate::estimation::lambda::LambdaError> {
    let count = points.len().max(1);
    let mut out = Vec::with_capacity(points.len());
    for (g, (u0, exps)) in points.iter().enumerate() {
        let mut sub = crate::estimation::SubProgress::new(
            progress,
            g as f64 / count as f64,
            (g + 1) as f64 / count as f64,
        );
        sub.update(0.0, &format!("grid point {:.2} m/s", u0))
            .map_err(|Cancelled| crate::estimation::lambda::LambdaError::Cancelled)?;
        let fit = |s: &LambdaSettings, sub: &mut dyn Progress| {
            if coriolis {
                identify_with_coriolis(exps, s, *u0, sub).map(|r| r.0)
            } else {
                identify(exps, s)
            }
        };
        let est = match fit(settings, &mut sub) {
            // A mode faster than the sample rate leaves Φ with a negative
            // eigenvalue, which has no continuous-time logarithm: the
            // thesis's map (eq. 2.14–2.15) still gives a model.
            Err(e) if e.field() == "a_lambda" && settings.inversion == Inversion::Exact => {
                let mut thesis = settings.clone();
                thesis.inversion = Inversion::Thesis;
                notes.push(format!(
                    "at {u0:.2} m/s the exact sampled-data map failed ({e}); the thesis's map A = (A_λ − I)/T was used"
                ));
                fit(&thesis, &mut sub)?
            }
            r => r?,
        };
        out.push((*u0, est));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

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
