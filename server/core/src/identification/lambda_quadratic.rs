//! Quadratic damping estimated with M and D̄: the functions |ν_i|ν_i as
//! exogenous columns of the λ regression (M ν̇ + D̄ν + F·e = γ), one per DOF
//! other than surge, each acting on its own DOF only. F_ii is D_q,i of
//! [`crate::models::quadratic_damping`].
//!
//! Surge's X_|u|u comes from the drag curve over the grid ([`surge_drag`]):
//! each sub-model's D̄[surge,surge] is the tangent X_u + 2X_|u|u·u₀ of the
//! surge drag at its speed, so half the slope over the grid speeds is
//! X_|u|u — what a resistance test measures. The sub-models are then
//! refitted with X_|u|u times the remainder of |u|u beyond each tangent
//! ([`crate::models::quadratic_damping::surge_remainder`], (u − u₀)²
//! ahead) on the known side: without it a point fitted over ±a of surge
//! holds the secant, its load off by X_|u|u·a², an error the quadratic
//! extrapolation of the load beyond the grid amplifies (independent truth,
//! vessel 5: 19 % too much drag at 0.3 m/s from a 0.5 … 2 m/s grid, and a
//! free run that lost 0.06 in surge and, through the schedule, 0.12 in
//! heave). Estimated inside each point instead, as a column like the other
//! DOFs', the remainder (≈ a² through a square wave) is told from the
//! constant load only by the surge runs' mean force against the other
//! runs', and came out 35–50 % low with σ that did not cover it (vessels
//! 2, 8, 9: |z| 5.8–8.3).
//!
//! D_q is a property of the hull, not of the forward speed: each grid
//! point's estimate is pooled into one per campaign by inverse variance
//! (the spread inflating the std, Birge ratio), as g(η) is, and the
//! sub-models are then fitted with D_q|δ|δ on the known side. Within one
//! grid point the amplitudes flown are few and |v|v stays close to a·v, so
//! a point alone separates D_q from D̄ poorly; over the campaign it does.
//!
//! Without it, a sub-model fitted to ±a of sway carries the damping right
//! at ±a; flown at other amplitudes — a validation run, a mission — it
//! over- or under-damps, and the free run drifts from the recordings by
//! more than noise (independent truth: hulls whose damping is 30–70 %
//! quadratic lost 0.05–0.10 of free-run fit in yaw and sway).

use nalgebra::{DMatrix, DVector};

use crate::estimation::lambda::{Exogenous, Experiment, LambdaEstimate};
use crate::models::quadratic_damping::{surge_remainder, surge_tangent};
use crate::numbers::sig3;
use crate::planning::dof::Dof;
use crate::planning::vessel::VesselProfile;

/// Unit of D_q of DOF `d`.
pub(crate) fn unit(d: Dof) -> &'static str {
    if d.is_angular() {
        "N·m·s²/rad²"
    } else {
        "N·s²/m²"
    }
}

/// Name of DOF `d`'s column: |v|v.
pub(crate) fn name(d: Dof) -> String {
    let s = d.velocity_symbol();
    format!("|{s}|{s}")
}

/// The columns of ν that get a quadratic column in the regression: all
/// but surge (whose X_|u|u [`surge_drag`] gives), and surge too when every
/// grid speed is 0 m/s (a DP vessel: no drag curve over speeds, and at
/// u₀ = 0 surge's remainder beyond its tangent is |u|u itself).
pub(crate) fn columns(dofs: &[Dof], grid: &[f64]) -> Vec<usize> {
    let at_rest = at_rest(grid);
    (0..dofs.len())
        .filter(|&i| dofs[i] != Dof::Surge || at_rest)
        .collect()
}

/// Every grid speed is 0 m/s (and there is one).
pub(crate) fn at_rest(grid: &[f64]) -> bool {
    !grid.is_empty() && grid.iter().all(|u| *u == 0.0)
}

/// X_|u|u and its std from the sub-models' D̄[surge,surge] (index
/// `surge`) at their grid speeds ([`drag_curve`]).
pub(crate) fn surge_drag(points: &[(f64, LambdaEstimate)], surge: usize) -> Option<(f64, f64)> {
    let obs: Vec<(f64, f64, f64)> = points
        .iter()
        .map(|(u0, e)| (*u0, e.d_bar[(surge, surge)], e.std_d_bar[(surge, surge)]))
        .collect();
    drag_curve(&obs)
}

/// X_|u|u and its std from (u₀, D̄[surge,surge], σ) per grid point: half
/// the slope of the inverse-variance weighted least-squares line through
/// them (the tangent of X_u u + X_|u|u|u|u at u₀ is X_u + 2X_|u|u|u₀|),
/// its σ scaled by √(χ²/dof) where the points scatter beyond their σ.
/// `None` with fewer than two points of distinct speed and positive σ, or
/// a slope not above 2σ (a drag that does not grow with speed is not
/// quadratic).
fn drag_curve(points: &[(f64, f64, f64)]) -> Option<(f64, f64)> {
    let obs: Vec<(f64, f64, f64)> = points
        .iter()
        .filter(|(_, y, sd)| *sd > 0.0 && sd.is_finite() && y.is_finite())
        .map(|&(u0, y, sd)| (u0.abs(), y, 1.0 / (sd * sd)))
        .collect();
    if obs.len() < 2 {
        return None;
    }
    let sw: f64 = obs.iter().map(|o| o.2).sum();
    let xm = obs.iter().map(|o| o.2 * o.0).sum::<f64>() / sw;
    let ym = obs.iter().map(|o| o.2 * o.1).sum::<f64>() / sw;
    let sxx: f64 = obs.iter().map(|o| o.2 * (o.0 - xm).powi(2)).sum();
    if sxx <= 0.0 {
        return None;
    }
    let slope = obs
        .iter()
        .map(|o| o.2 * (o.0 - xm) * (o.1 - ym))
        .sum::<f64>()
        / sxx;
    let mut var = 1.0 / sxx;
    let dof = obs.len() - 2;
    if dof > 0 {
        let chi2: f64 = obs
            .iter()
            .map(|o| o.2 * (o.1 - ym - slope * (o.0 - xm)).powi(2))
            .sum();
        var *= (chi2 / dof as f64).max(1.0);
    }
    let (x, sd) = (0.5 * slope, 0.5 * var.sqrt());
    (x > 2.0 * sd).then_some((x, sd))
}

/// `spec` (or none) with one column per entry of `cols` appended, acting
/// on its own DOF; prior std of D_q ten times the DOF's force limit over
/// its velocity limit squared (weak).
pub(crate) fn specification(
    spec: Option<Exogenous>,
    profile: &VesselProfile,
    dofs: &[Dof],
    cols: &[usize],
) -> Option<Exogenous> {
    if cols.is_empty() {
        return spec;
    }
    let n = dofs.len();
    let base = spec.unwrap_or_else(|| super::joint_restoring::no_exogenous(profile, dofs));
    let q0 = base.names.len();
    let mut names = base.names.clone();
    names.extend(cols.iter().map(|&i| name(dofs[i])));
    let pattern = DMatrix::from_fn(n, q0 + cols.len(), |i, j| {
        if j < q0 {
            base.pattern[(i, j)]
        } else {
            cols[j - q0] == i
        }
    });
    // One prior std per DOF row serves all its columns: the weak force
    // scale; a D_q at the velocity limit gives a force of that order.
    Some(Exogenous {
        names,
        pattern,
        force_std: base.force_std,
    })
}

/// ν_i at the middle of step k extrapolated from samples k and k−1,
/// 1.5 ν_i(k) − 0.5 ν_i(k−1) (ν_i(0) at the first): second-order like the
/// model's |δ(k)|δ(k+1), without ν(k+1).
fn midstep(nu: &DMatrix<f64>, k: usize, i: usize) -> f64 {
    if k == 0 {
        nu[(0, i)]
    } else {
        1.5 * nu[(k, i)] - 0.5 * nu[(k - 1, i)]
    }
}

/// DOF i's quadratic function over step k of an experiment at grid speed
/// `u0`: |ν_i(k)|·ν_i(k+½), for surge (`surge == Some(i)`) its remainder
/// beyond the tangent at u₀ with the same sampling.
fn function(nu: &DMatrix<f64>, k: usize, i: usize, surge: Option<usize>, u0: f64) -> f64 {
    let mid = midstep(nu, k, i);
    let q = nu[(k, i)].abs() * mid;
    if Some(i) == surge {
        q - surge_tangent(mid, u0)
    } else {
        q
    }
}

/// `exp` with the columns |ν_i|ν_i (i in `cols`) appended, over step k
/// |ν_i(k)|·ν_i(k+½) with ν_i(k+½) extrapolated from samples k and k−1
/// ([`midstep`]). The model applies the force linearly implicit,
/// |δ(k)|δ(k+1) ([`crate::models::LpvModel`], stable at any D_q), but as a
/// regressor that column carries ν(k+1): filtered, row k holds
/// |ν(k−1)|ν(k), whose noise is the regressand's own, and least squares
/// pulls D_q toward it (independent truth, 5 mm/s of velocity noise:
/// vessel 10 sway 104 ± 17 against 169 N·s²/m², σ not covering it on 2 of
/// 12 vessels; extrapolated, 135 ± 16 and ≥ 97 % within ±3σ on all 12).
/// |ν(k)|ν(k) alone lags the force by half a step: m came out 4 % high on
/// a strongly quadratic hull (unit test below).
pub(crate) fn append(exp: Experiment, cols: &[usize]) -> Experiment {
    if cols.is_empty() {
        return exp;
    }
    let rows = exp.nu.nrows();
    let q0 = exp.exogenous.ncols();
    let f = |k: usize, i: usize| function(&exp.nu, k, i, None, 0.0);
    let e = DMatrix::from_fn(rows, q0 + cols.len(), |k, j| {
        if j < q0 {
            exp.exogenous[(k, j)]
        } else {
            f(k, cols[j - q0])
        }
    });
    Experiment {
        exogenous: e,
        ..exp
    }
}

/// D_q and its std (n entries, zero where not estimated) from `est`;
/// `None` when it has no quadratic column.
pub(crate) fn of_estimate(
    est: &LambdaEstimate,
    dofs: &[Dof],
) -> Option<(DVector<f64>, DVector<f64>)> {
    let n = dofs.len();
    let mut d = DVector::zeros(n);
    let mut s = DVector::zeros(n);
    let mut any = false;
    for (i, dof) in dofs.iter().enumerate() {
        if let Some(j) = est.exogenous.iter().position(|e| *e == name(*dof)) {
            d[i] = est.force[(i, j)];
            s[i] = est.std_force[(i, j)];
            any = true;
        }
    }
    any.then_some((d, s))
}

/// One D_q for the campaign from the grid points' joint estimates `points`
/// (inverse-variance pooling per DOF), with its std and notes: entries
/// pooled negative or within 2σ of zero are left out (0) and said so.
/// `None` when no point estimated D_q or every entry was left out.
pub(crate) fn pool(
    points: &[(f64, LambdaEstimate)],
    dofs: &[Dof],
    notes: &mut Vec<String>,
) -> Option<(DVector<f64>, DVector<f64>)> {
    let grid: Vec<f64> = points.iter().map(|(u0, _)| *u0).collect();
    let cols = columns(dofs, &grid);
    let per_point: Vec<(DVector<f64>, DVector<f64>)> = points
        .iter()
        .filter_map(|(_, e)| of_estimate(e, dofs))
        .collect();
    if per_point.is_empty() {
        return None;
    }
    let n = dofs.len();
    let mut d = DVector::zeros(n);
    let mut s = DVector::zeros(n);
    let mut left_out = Vec::new();
    for i in cols.iter().copied() {
        let pairs: Vec<(f64, f64)> = per_point.iter().map(|(d, s)| (d[i], s[i])).collect();
        let Some(p) = super::joint_restoring::pool(&pairs) else {
            continue;
        };
        // Negative: not physical. Within 2σ of zero: not determined by the
        // data (one amplitude flown makes |v|v ≈ a·v), and a D_q that large
        // by chance stiffens the model for nothing.
        if p.value < 2.0 * p.std {
            left_out.push(format!(
                "{} ({} ± {} {})",
                dofs[i].name(),
                sig3(p.value),
                sig3(p.std),
                unit(dofs[i])
            ));
            continue;
        }
        d[i] = p.value;
        s[i] = p.std;
    }
    notes.push(format!(
        "quadratic damping D_q|δ|δ estimated with M and D̄ at every grid point and pooled over {} point(s) ({}): {}",
        per_point.len(),
        if at_rest(&grid) {
            "δ = ν: at 0 m/s surge's X_|u|u too"
        } else {
            "δ = ν except surge, whose X_|u|u the drag curve over the grid gives"
        },
        cols
            .iter()
            .filter(|&&i| s[i] > 0.0)
            .map(|&i| format!("{} {} ± {} {}", dofs[i].name(), sig3(d[i]), sig3(s[i]), unit(dofs[i])))
            .collect::<Vec<_>>()
            .join(", ")
    ));
    if !left_out.is_empty() {
        notes.push(format!(
            "quadratic damping left out where the data gave it negative or within 2σ of zero: {} (a quadratic force that feeds energy is not physical, one the data do not determine adds only noise; the linear damping carries those DOFs)",
            left_out.join(", ")
        ));
    }
    // Every entry left out: the model is linear, not "D_q = 0".
    (s.iter().any(|v| *v > 0.0)).then_some((d, s))
}

/// `exp` (at grid speed `u0`, m/s) with the known D_q|δ|δ moved to the
/// force side, γ' = γ − F, F over step k as it was estimated ([`append`]):
/// D_q,i |δ_i(k)| δ_i(k+½), surge's remainder beyond its tangent at u₀.
/// In a known current `exp` holds the velocity through the water
/// ([`super::ned_current::Relative::apply`]), which the drag acts on
/// (Fossen 2011, eq. 10.1: D(ν_r)ν_r).
pub(crate) fn subtract(
    exp: Experiment,
    d_q: &DVector<f64>,
    surge: Option<usize>,
    u0: f64,
) -> Experiment {
    let rows = exp.nu.nrows();
    let nu = &exp.nu;
    let mut gamma = exp.gamma.clone();
    for k in 0..rows {
        for i in 0..gamma.ncols().min(d_q.len()) {
            if d_q[i] != 0.0 {
                gamma[(k, i)] -= d_q[i] * function(nu, k, i, surge, u0);
            }
        }
    }
    Experiment { gamma, ..exp }
}

/// σ of a sub-model fitted with D_q known (`est`, from `exps` at grid speed
/// `u0`) widened by D_q's own σ (`d_std`): an error δ in D_q,i moves row i
/// of D̄ (and its load) by −δ·β_i, β_i the least-squares coefficients of
/// DOF i's quadratic function (surge's remainder about u₀) on
/// [ν, 1] over the samples (the part of the quadratic force a linear
/// model absorbs), so σ²(D̄_ij) += β_ij²σ_i², σ²(b_i) += β_i0²σ_i² and
/// σ²(A_kj) += Σ_i (M⁻¹_ki β_ij σ_i)² (A = −M⁻¹D̄, first order), for the
/// entries the fit estimated.
pub(crate) fn widen(
    est: &mut LambdaEstimate,
    exps: &[Experiment],
    d_std: &DVector<f64>,
    dofs: &[Dof],
    u0: f64,
) {
    let n = dofs.len();
    let surge = dofs.iter().position(|d| *d == Dof::Surge);
    let rows: usize = exps.iter().map(|e| e.nu.nrows()).sum();
    if rows <= n + 1 {
        return;
    }
    // [ν, 1] of every run, stacked.
    let mut x = DMatrix::from_element(rows, n + 1, 1.0);
    let mut start = 0;
    for e in exps {
        let k = e.nu.nrows();
        x.view_mut((start, 0), (k, n))
            .copy_from(&e.nu.columns(0, n));
        start += k;
    }
    let svd = x.clone().svd(true, true);
    let m_inv = est.m.clone().try_inverse();
    let constant = est
        .exogenous
        .iter()
        .position(|e| e == super::joint_restoring::CONSTANT);
    for i in 0..n.min(d_std.len()) {
        let s = d_std[i];
        if !(s > 0.0 && s.is_finite()) {
            continue;
        }
        let q = DVector::from_fn(rows, |k, _| {
            let v = x[(k, i)];
            if Some(i) == surge {
                surge_remainder(v, u0)
            } else {
                v.abs() * v
            }
        });
        let Ok(beta) = svd.solve(&q, 1e-12 * svd.singular_values.max()) else {
            continue;
        };
        // Only entries the fit estimated (σ > 0); fixed ones stay fixed.
        let free: Vec<usize> = (0..n).filter(|&j| est.std_d_bar[(i, j)] > 0.0).collect();
        for j in free {
            let add = (beta[j] * s).powi(2);
            est.std_d_bar[(i, j)] = (est.std_d_bar[(i, j)].powi(2) + add).sqrt();
            if let Some(m_inv) = &m_inv {
                let free_a: Vec<usize> = (0..n).filter(|&k| est.std_a[(k, j)] > 0.0).collect();
                for k in free_a {
                    let a = (m_inv[(k, i)] * beta[j] * s).powi(2);
                    est.std_a[(k, j)] = (est.std_a[(k, j)].powi(2) + a).sqrt();
                }
            }
        }
        if let Some(c) = constant.filter(|&c| est.std_force[(i, c)] > 0.0) {
            let add = (beta[n] * s).powi(2);
            est.std_force[(i, c)] = (est.std_force[(i, c)].powi(2) + add).sqrt();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::planning::examples::surveyor_rov;

    #[test]
    fn each_dof_gets_its_own_column_and_surge_its_remainder_about_the_grid_speed() {
        let dofs = vec![Dof::Surge, Dof::Sway, Dof::Yaw];
        // The regression's columns leave surge to the drag curve.
        let cols = columns(&dofs, &[1.0]);
        assert_eq!(cols, vec![1, 2]);
        let spec = specification(None, &surveyor_rov(), &dofs, &cols).unwrap();
        assert_eq!(spec.names, vec!["|v|v", "|r|r"]);
        assert!(spec.pattern[(1, 0)] && spec.pattern[(2, 1)]);
        assert!(!spec.pattern[(0, 0)] && !spec.pattern[(2, 0)] && !spec.pattern[(1, 1)]);
        let exp = Experiment {
            h: 0.1,
            nu: DMatrix::from_row_slice(2, 3, &[1.0, -0.2, 0.4, 1.4, 0.2, 0.0]),
            gamma: DMatrix::zeros(2, 3),
            exogenous: DMatrix::zeros(2, 0),
        };
        let e = append(exp.clone(), &cols).exogenous;
        // |v(k)| times v extrapolated to mid-step: row 0 its own sample,
        // |v(0)| v(0) = −0.04, |r(0)| r(0) = 0.16; row 1 0.2·(0.3 + 0.1), 0
        assert!((e[(0, 0)] + 0.04).abs() < 1e-12 && (e[(0, 1)] - 0.16).abs() < 1e-12);
        assert!((e[(1, 0)] - 0.08).abs() < 1e-12 && e[(1, 1)].abs() < 1e-12);
        // Subtracting D_q moves the same functions to the force side; surge
        // about u₀ = 1: row 0 (1 − 1)² = 0; row 1 with u(k+½) = 1.6:
        // |u(k)|u(k+½) − |u₀|u₀ − 2|u₀|(u(k+½) − u₀) = 1.4·1.6 − 1 − 2·0.6.
        let d_q = DVector::from_vec(vec![30.0, 50.0, 7.0]);
        let g = subtract(exp, &d_q, Some(0), 1.0).gamma;
        let want = [[0.0, -0.04, 0.16], [0.04, 0.08, 0.0]];
        for k in 0..2 {
            for i in 0..3 {
                assert!((g[(k, i)] + d_q[i] * want[k][i]).abs() < 1e-12, "{k} {i}");
            }
        }
    }

    /// Tangents of 20u + 30|u|u at 0.5 … 2 m/s (D̄ = 20 + 60u₀) give
    /// X_|u|u = 30 with the σ of the weighted line; scattered beyond their σ
    /// the σ grows by √(χ²/dof); a flat drag is not quadratic.
    #[test]
    fn the_drag_curve_over_the_grid_gives_x_uu() {
        let at = |u0: f64, d: f64, sd: f64| (u0, d, sd);
        let exact: Vec<_> = [0.5, 1.0, 1.5, 2.0]
            .iter()
            .map(|&u| at(u, 20.0 + 60.0 * u, 2.0))
            .collect();
        let (x, sd) = drag_curve(&exact).unwrap();
        // σ of the slope: 2/√Σ(u − ū)² = 2/√1.25; X's is half.
        assert!((x - 30.0).abs() < 1e-9 && (sd - 0.5 * 2.0 / 1.25f64.sqrt()).abs() < 1e-9);
        let scattered: Vec<_> = [(0.5, 4.0), (1.0, -4.0), (1.5, -4.0), (2.0, 4.0)]
            .iter()
            .map(|&(u, e)| at(u, 20.0 + 60.0 * u + e, 2.0))
            .collect();
        let (x2, sd2) = drag_curve(&scattered).unwrap();
        assert!((x2 - 30.0).abs() < 1e-9 && sd2 > 1.5 * sd, "{x2} ± {sd2}");
        let flat: Vec<_> = [0.5, 1.0, 1.5].iter().map(|&u| at(u, 50.0, 2.0)).collect();
        assert!(drag_curve(&flat).is_none());
        assert!(drag_curve(&exact[..1]).is_none());
    }

    /// Sway of m v̇ + d v + q|v|v = τ flown with square waves of three
    /// amplitudes (integrated here by RK4 at 1 ms, sampled at 10 Hz with
    /// the force held): the λ regression with |v|v among its functions
    /// returns m, d and q within 3 %.
    #[test]
    fn the_lambda_regression_separates_quadratic_from_linear_damping() {
        use crate::estimation::lambda::{LambdaSettings, Prior, Structure, identify};
        let (m, d, q) = (450.0_f64, 120.0_f64, 600.0_f64);
        let dofs = vec![Dof::Sway];
        let h = 0.1;
        let mut exps = Vec::new();
        for (a, period) in [(40.0, 80), (150.0, 60), (400.0, 50)] {
            let n = 600;
            let tau = DMatrix::from_fn(n, 1, |k, _| if (k / period) % 2 == 0 { a } else { -a });
            let mut nu = DMatrix::zeros(n, 1);
            let mut v = 0.0_f64;
            for k in 0..n {
                nu[(k, 0)] = v;
                let f = |v: f64| (tau[(k, 0)] - d * v - q * v.abs() * v) / m;
                let dt = h / 100.0;
                for _ in 0..100 {
                    let k1 = f(v);
                    let k2 = f(v + 0.5 * dt * k1);
                    let k3 = f(v + 0.5 * dt * k2);
                    let k4 = f(v + dt * k3);
                    v += dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
                }
            }
            let exp = Experiment {
                h,
                nu,
                gamma: tau,
                exogenous: DMatrix::zeros(n, 0),
            };
            exps.push(append(exp, &columns(&dofs, &[1.0])));
        }
        let mut settings = LambdaSettings::new(
            dofs.clone(),
            1.0,
            Structure::Diagonal,
            Prior::weak(
                DMatrix::from_element(1, 1, 300.0),
                DMatrix::from_element(1, 1, 300.0),
            ),
        );
        settings.exogenous = specification(None, &surveyor_rov(), &dofs, &columns(&dofs, &[1.0]));
        let est = identify(&exps, &settings).unwrap();
        let (d_q, d_q_std) = of_estimate(&est, &dofs).unwrap();
        for (what, got, want, std) in [
            ("M", est.m[(0, 0)], m, est.std_m[(0, 0)]),
            ("D̄", est.d_bar[(0, 0)], d, est.std_d_bar[(0, 0)]),
            ("D_q", d_q[0], q, d_q_std[0]),
        ] {
            // Noise-free data: σ reflects only the λ model's residual, so
            // the check is relative.
            assert!(
                (got - want).abs() <= 0.03 * want,
                "{what}: {got} vs {want} ± {std}"
            );
        }
    }
}
