//! Truth values to grade identified models against.
//!
//! Writing f(ν) = C(ν)ν + D(ν)ν (no current, M = M_RB + M_A), the plant is
//! M ν̇ + f(ν) + g(η) = τ. A linear-affine model about an operating point is
//! f(ν) ≈ D̄ν + b. Two truths are given:
//! - the tangent ([`Vessel::linearization`]): D̄ = ∂f/∂ν at ν₀ = (u₀, 0, …, 0),
//!   b = f(ν₀) − D̄ν₀;
//! - the statistical linearization ([`effective_linearization`]): the least-
//!   squares fit of f over the true states actually flown. An estimator that
//!   fits a linear model to quadratic damping converges to this one, not to
//!   the tangent (e.g. sway under ±a excitation: D̄_vv ≈ l₀ + l_u u₀ + q E|v|³/E v²).

use nalgebra::{DMatrix, Matrix6, SMatrix, SVector, Vector6};

use crate::campaign::Run;
use crate::forces::coriolis_jacobian;
use crate::vessel::Vessel;

/// M ν̇ + D̄ν + b + g(η) = τ about an operating point.
#[derive(Debug, Clone, PartialEq)]
pub struct Linearization {
    /// Forward speed u₀ of the operating point (m/s); for a fit, the mean u.
    pub u0: f64,
    /// M = M_RB + M_A.
    pub m: Matrix6<f64>,
    /// D̄: ∂(C(ν)ν + D(ν)ν)/∂ν (tangent) or its least-squares fit.
    pub d_bar: Matrix6<f64>,
    /// b: C(ν₀)ν₀ + D(ν₀)ν₀ − D̄ν₀ (tangent) or the fitted intercept.
    pub bias: Vector6<f64>,
    /// W − B (N) of g(η).
    pub w_minus_b: f64,
    /// z_G W − z_B B (N·m) of g(η).
    pub zg_w_minus_zb_b: f64,
}

impl Linearization {
    /// The model's force D̄ν + b at `nu`.
    pub fn force(&self, nu: &Vector6<f64>) -> Vector6<f64> {
        self.d_bar * nu + self.bias
    }
}

impl Vessel {
    /// The analytic tangent at ν₀ = (u₀, 0, 0, 0, 0, 0).
    pub fn linearization(&self, u0: f64) -> Linearization {
        self.linearization_at(&Vector6::new(u0, 0.0, 0.0, 0.0, 0.0, 0.0))
    }

    /// The analytic tangent at any ν₀.
    pub fn linearization_at(&self, nu0: &Vector6<f64>) -> Linearization {
        let m = self.m();
        let d_bar = coriolis_jacobian(&m, nu0) + self.damping_jacobian(nu0);
        Linearization {
            u0: nu0[0],
            m,
            d_bar,
            bias: self.hydrodynamic_force(nu0) - d_bar * nu0,
            w_minus_b: self.w_minus_b,
            zg_w_minus_zb_b: self.zg_w_minus_zb_b(),
        }
    }

    /// ∂f/∂ν at `nu0` by central differences of step `h` (a check on the
    /// analytic tangent).
    pub fn central_difference_jacobian(&self, nu0: &Vector6<f64>, h: f64) -> Matrix6<f64> {
        let mut j = Matrix6::zeros();
        for k in 0..6 {
            let mut e = Vector6::zeros();
            e[k] = h;
            let d = (self.hydrodynamic_force(&(nu0 + e)) - self.hydrodynamic_force(&(nu0 - e)))
                / (2.0 * h);
            j.set_column(k, &d);
        }
        j
    }
}

/// The statistical linearization over `runs`: least squares of the TRUE
/// f(ν) = C(ν)ν + D(ν)ν on [ν, 1], ν the noise-free true velocities at the
/// runs' log instants. Pass the runs an estimator fits at one grid point
/// (usually the dynamic ones). Directions never excited get D̄ columns from
/// the pseudo-inverse (zero on the centred regressor), so read only what was
/// flown.
pub fn effective_linearization(vessel: &Vessel, runs: &[&Run]) -> Linearization {
    fit_affine(vessel, &stacked(runs))
}

/// The statistical linearization of a model that carries diagonal
/// quadratic damping `d_q` for a sub-model at forward speed `u0` (m/s):
/// least squares of f(ν) − q(ν) on [ν, 1] over `runs` as
/// [`effective_linearization`], q_i = d_q,i |ν_i|ν_i in sway … yaw and in
/// surge d_q,0 times the part of |u|u beyond its tangent at u₀,
/// |u|u − |u₀|u₀ − 2|u₀|(u − u₀) (the tangent is the sub-model's). Grade
/// the D̄ and load of M ν̇ + D̄ν + q(ν) + b = γ with the truth's own
/// quadratic coefficients against this (surge's is D_lu,0 + D_q,0: the
/// speed-dependent linear damping D_lu|u| is quadratic in surge).
pub fn effective_linearization_given_quadratic(
    vessel: &Vessel,
    runs: &[&Run],
    d_q: &Vector6<f64>,
    u0: f64,
) -> Linearization {
    let nus = stacked(runs);
    fit_affine_of(vessel, &nus, |nu| {
        let mut f = vessel.hydrodynamic_force(nu);
        for i in 1..6 {
            f[i] -= d_q[i] * nu[i].abs() * nu[i];
        }
        let u = nu[0];
        f[0] -= d_q[0] * (u.abs() * u - u0.abs() * u0 - 2.0 * u0.abs() * (u - u0));
        f
    })
}

/// The true velocities of `runs` at their log instants, stacked (N×6).
fn stacked(runs: &[&Run]) -> DMatrix<f64> {
    let rows: usize = runs.iter().map(|r| r.truth.nu.nrows()).sum();
    assert!(rows > 6, "a linearization needs logged samples");
    DMatrix::from_fn(rows, 6, |i, j| {
        let mut k = i;
        for r in runs {
            if k < r.truth.nu.nrows() {
                return r.truth.nu[(k, j)];
            }
            k -= r.truth.nu.nrows();
        }
        unreachable!()
    })
}

/// Least squares f(ν) ≈ D̄ν + b over the rows of `nus` (N×6), on centred
/// regressors for conditioning, solved by SVD.
pub fn fit_affine(vessel: &Vessel, nus: &DMatrix<f64>) -> Linearization {
    fit_affine_of(vessel, nus, |nu| vessel.hydrodynamic_force(nu))
}

/// Least squares `force(ν)` ≈ D̄ν + b over the rows of `nus`.
fn fit_affine_of(
    vessel: &Vessel,
    nus: &DMatrix<f64>,
    force: impl Fn(&Vector6<f64>) -> Vector6<f64>,
) -> Linearization {
    let n = nus.nrows();
    let mean = Vector6::from_fn(|j, _| nus.column(j).mean());
    let mut xtx = SMatrix::<f64, 6, 6>::zeros();
    let mut xty = SMatrix::<f64, 6, 6>::zeros();
    let mut fmean = Vector6::zeros();
    for i in 0..n {
        let nu: Vector6<f64> = SVector::from_fn(|j, _| nus[(i, j)]);
        let x = nu - mean;
        let f = force(&nu);
        xtx += x * x.transpose();
        xty += x * f.transpose();
        fmean += f;
    }
    fmean /= n as f64;
    // f − f̄ ≈ D̄ (ν − ν̄): solve (XᵀX) D̄ᵀ = XᵀY, XᵀX is 6×6.
    let scale = xtx.diagonal().max().max(f64::MIN_POSITIVE);
    let svd = xtx.svd(true, true);
    let d_t = svd
        .solve(&xty, 1e-10 * scale)
        .expect("SVD computed with U and V");
    let d_bar = d_t.transpose();
    Linearization {
        u0: mean[0],
        m: vessel.m(),
        d_bar,
        bias: fmean - d_bar * mean,
        w_minus_b: vessel.w_minus_b,
        zg_w_minus_zb_b: vessel.zg_w_minus_zb_b(),
    }
}
