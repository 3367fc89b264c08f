//! The augmented model: the baseline M ν̇ + D̄ ν = τ_a − g(η) plus the chosen
//! terms, with its simulator (free run) and k-step predictor on recorded
//! inputs. The model is driven by (τ_c, η) and predicts ν; η is taken from
//! the record (as γ = τ − g(η) is in the thesis), except that a 6-DOF
//! model integrates φ and θ from its own p, q, r (see
//! [`AugmentedModel::attitude_in_loop`]), as the baseline's predictor does.

use std::cell::RefCell;
use std::rc::Rc;

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::candidates::{Effect, ShapeKind, TermContext, Trig};
use super::data::{Baseline, Record, Restoring};
use super::svf::lag_zoh;
use crate::identification::attitude_loop::euler_rates;
use crate::models::quadratic_damping::QuadraticDamping;
use crate::planning::Dof;
use crate::simulation::exponential::EtdRk4;
use crate::simulation::integrate::rk4_step;

mod predict;
pub(crate) use predict::{State, free_run, k_step};

/// One term of the augmented model with its estimates.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct ModelTerm {
    /// The effect.
    pub effect: Effect,
    /// Linear coefficients θ (see [`Effect::coefficient_names`]).
    pub coefficients: Vec<f64>,
    /// Covariance of θ (HAC, row-major), same order.
    pub covariance: Vec<Vec<f64>>,
    /// Shape parameter of an actuator effect: T_a (s), delay (samples),
    /// τ_max or δ (N, N·m).
    pub shape: Option<f64>,
    /// Standard deviation of the shape parameter from the profile's curvature.
    pub shape_std: Option<f64>,
}

impl ModelTerm {
    /// Standard deviation of coefficient `j` from the covariance's diagonal
    /// (`None` when absent or not finite).
    pub fn coefficient_std(&self, j: usize) -> Option<f64> {
        self.covariance
            .get(j)
            .and_then(|r| r.get(j))
            .map(|v| v.max(0.0).sqrt())
            .filter(|s| s.is_finite())
    }
}

/// Baseline plus chosen terms.
#[derive(Debug, Clone, PartialEq)]
pub struct AugmentedModel {
    /// Modeled DOFs.
    pub dofs: Vec<Dof>,
    /// M, with refitted rows and coupling entries.
    pub m: DMatrix<f64>,
    /// D̄, with refitted rows and coupling entries.
    pub d_bar: DMatrix<f64>,
    /// g(η) of the baseline.
    pub restoring: Restoring,
    /// M that C(ν) of a Coriolis term is built from (the fitted M, iterated
    /// to a fixed point, or the baseline's when no C(ν)ν term is fitted).
    pub m_ref: DMatrix<f64>,
    /// D̄ the current acts through (likewise, for a current).
    pub d_ref: DMatrix<f64>,
    /// The added terms.
    pub terms: Vec<ModelTerm>,
    /// The vehicle's M of the baseline's C(δ)δ, if it carries one.
    pub coriolis: Option<DMatrix<f64>>,
    /// D_q of the baseline's D_q|δ|δ, if it carries one.
    pub quadratic: Option<QuadraticDamping>,
    m_inv: DMatrix<f64>,
    /// ‖M⁻¹D̄‖∞ (1/s), a bound on the fastest linear mode: an RK4 step of h
    /// is split so that h·rate ≤ 2, inside RK4's stability interval
    /// (−2.78, 0]; beyond [`STIFF_STEP`] the step is ETDRK4's instead.
    rate: f64,
    /// L = −M⁻¹D̄, the linear part a stiff model's steps integrate exactly.
    linear: DMatrix<f64>,
}

/// h·‖M⁻¹D̄‖∞ above which a sample interval is integrated by ETDRK4 (the
/// linear modes exactly) instead of RK4 sub-steps (more than two of them).
const STIFF_STEP: f64 = 4.0;

/// The smallest eigenvalue of ½(M + Mᵀ): positive when the kinetic energy
/// ½νᵀMν is (refitted rows leave M slightly asymmetric).
pub fn inertia_floor(m: &DMatrix<f64>) -> f64 {
    ((m + m.transpose()) * 0.5).symmetric_eigenvalues().min()
}

/// The input the vessel actually feels, per DOF: the held command after
/// delay, saturation and dead zone, and the time constant of a lag after it.
pub(crate) struct AppliedInput {
    pub held: Vec<Vec<f64>>,
    pub lag: Vec<Option<f64>>,
}

/// Applies the static actuator effects (delay → saturation → dead zone)
/// of `terms` to the command `tau` of DOF `dof`; returns the lag, if any.
pub(crate) fn actuate(tau: &[f64], dof: Dof, shapes: &[(Effect, f64)]) -> (Vec<f64>, Option<f64>) {
    let mut x = tau.to_vec();
    let mut lag = None;
    let mine = shapes.iter().filter(|(e, _)| e.acts_on(dof));
    let mut delay = None;
    let mut sat = None;
    let mut dz = None;
    for (e, v) in mine {
        match e.shape() {
            Some(ShapeKind::DelaySamples) => delay = Some(v.max(0.0)),
            Some(ShapeKind::SaturationLevel) => sat = Some(v.abs()),
            Some(ShapeKind::DeadZoneWidth) => dz = Some(v.abs()),
            Some(ShapeKind::LagTime) => lag = Some(v.max(1e-6)),
            None => {}
        }
    }
    if let Some(d) = delay.filter(|&d| d > 0.0) {
        x = delayed(tau, d);
    }
    if let Some(l) = sat {
        x.iter_mut().for_each(|v| *v = v.clamp(-l, l));
    }
    if let Some(w) = dz {
        x.iter_mut().for_each(|v| {
            *v = if v.abs() <= w {
                0.0
            } else {
                *v - w * v.signum()
            };
        });
    }
    (x, lag)
}

/// The held command `tau` delayed by `d` ≥ 0 samples, a fraction of a
/// sample included: over interval k the thrust is τ(k − n) for the part
/// 1 − f and τ(k − n − 1) for the part f of it (d = n + f), and the model,
/// which holds its input over each interval, gets their mean
/// (1 − f)·τ(k − n) + f·τ(k − n − 1) — the same impulse into the hull.
/// Before the log's start the first command holds.
pub(crate) fn delayed(tau: &[f64], d: f64) -> Vec<f64> {
    let n = d.floor() as usize;
    let f = d - n as f64;
    let first = tau.first().copied().unwrap_or(0.0);
    let at = |k: usize, back: usize| k.checked_sub(back).map_or(first, |i| tau[i]);
    (0..tau.len())
        .map(|k| {
            let now = at(k, n);
            if f == 0.0 {
                now
            } else {
                (1.0 - f) * now + f * at(k, n + 1)
            }
        })
        .collect()
}

impl AugmentedModel {
    /// Its M, D̄ and g(η) without the terms: what a further discovery
    /// refits the terms against.
    pub fn baseline(&self) -> Baseline {
        Baseline {
            dofs: self.dofs.clone(),
            m: self.m.clone(),
            d_bar: self.d_bar.clone(),
            restoring: self.restoring,
            coriolis: self.coriolis.clone(),
            quadratic: self.quadratic.clone(),
        }
    }

    /// The baseline alone.
    pub fn from_baseline(b: &Baseline) -> Self {
        Self::new(
            b.dofs.clone(),
            b.m.clone(),
            b.d_bar.clone(),
            b.restoring,
            b.m.clone(),
            b.d_bar.clone(),
            vec![],
        )
        .with_coriolis(b.coriolis.clone())
        .with_quadratic(b.quadratic.clone())
    }

    /// The same model carrying the second-order Coriolis force C(δ)δ of
    /// the vehicle's inertia `m` (`None`: without it).
    pub fn with_coriolis(mut self, m: Option<DMatrix<f64>>) -> Self {
        self.coriolis = m;
        self
    }

    /// The same model carrying the quadratic damping D_q|δ|δ of `d_q`
    /// (`None`: without it).
    pub fn with_quadratic(mut self, d_q: Option<QuadraticDamping>) -> Self {
        self.quadratic = d_q;
        self
    }

    /// A model from its parts (M must be invertible; a singular M is
    /// replaced by its diagonal so simulation never panics).
    pub fn new(
        dofs: Vec<Dof>,
        m: DMatrix<f64>,
        d_bar: DMatrix<f64>,
        restoring: Restoring,
        m_ref: DMatrix<f64>,
        d_ref: DMatrix<f64>,
        terms: Vec<ModelTerm>,
    ) -> Self {
        let m_inv = m.clone().try_inverse().unwrap_or_else(|| {
            DMatrix::from_diagonal(&m.diagonal().map(|x| if x != 0.0 { 1.0 / x } else { 0.0 }))
        });
        let a = &m_inv * &d_bar;
        let rate = (0..a.nrows())
            .map(|i| a.row(i).iter().map(|x| x.abs()).sum::<f64>())
            .fold(0.0, f64::max);
        AugmentedModel {
            dofs,
            m,
            d_bar,
            restoring,
            m_ref,
            d_ref,
            terms,
            m_inv,
            rate: if rate.is_finite() { rate } else { 0.0 },
            linear: -a,
            coriolis: None,
            quadratic: None,
        }
    }

    fn ctx(&self) -> TermContext<'_> {
        TermContext {
            dofs: &self.dofs,
            m_ref: &self.m_ref,
            d_ref: &self.d_ref,
        }
    }

    fn shapes(&self) -> Vec<(Effect, f64)> {
        self.terms
            .iter()
            .filter_map(|t| t.shape.map(|s| (t.effect, s)))
            .collect()
    }

    pub(crate) fn applied_input(&self, rec: &Record) -> AppliedInput {
        let shapes = self.shapes();
        let mut held = Vec::with_capacity(self.dofs.len());
        let mut lag = Vec::with_capacity(self.dofs.len());
        for (i, &d) in self.dofs.iter().enumerate() {
            let (x, l) = actuate(rec.tau.column(i).as_slice(), d, &shapes);
            held.push(x);
            lag.push(l);
        }
        AppliedInput { held, lag }
    }

    /// ν̇ from (ν, τ_a, η): M⁻¹(τ_a − g(η) − D̄ν − Σθφ(ν, η)).
    fn nu_dot(
        &self,
        nu: &[f64],
        tau_a: &[f64],
        g: &[f64],
        eta: &[f64; 6],
        trig: Option<&Trig>,
        out: &mut [f64],
    ) {
        let n = self.dofs.len();
        let ctx = self.ctx();
        // The terms' left-hand-side forces, then γ − D̄ν minus them.
        let mut lhs = [0.0; 6];
        for t in &self.terms {
            if matches!(t.effect, Effect::Coupling { .. }) || t.coefficients.is_empty() {
                continue;
            }
            t.effect
                .add_force_at(&t.coefficients, &ctx, nu, eta, trig, &mut lhs[..n]);
        }
        let mut f = [0.0; 6];
        for i in 0..n {
            let damping: f64 = nu
                .iter()
                .enumerate()
                .map(|(j, v)| self.d_bar[(i, j)] * v)
                .sum();
            f[i] = tau_a[i] - g[i] - damping - lhs[i];
        }
        if let (Some(m), Some(s)) = (
            &self.coriolis,
            self.dofs.iter().position(|d| *d == Dof::Surge),
        ) {
            let c = crate::models::coriolis::second_order_force(&self.dofs, m, &nu[..n], s);
            for i in 0..n {
                f[i] -= c[i];
            }
        }
        if let Some(d) = &self.quadratic {
            let q = self.quadratic_force(d, &nu[..n], eta[5]);
            for i in 0..n {
                f[i] -= q[i];
            }
        }
        for (i, o) in out.iter_mut().enumerate().take(n) {
            *o = f[..n]
                .iter()
                .enumerate()
                .map(|(j, fj)| self.m_inv[(i, j)] * fj)
                .sum();
        }
    }

    /// The current (V_N, V_E) of a current term, if the model carries one.
    pub fn current(&self) -> Option<[f64; 2]> {
        self.terms
            .iter()
            .find(|t| t.effect == Effect::Current && t.coefficients.len() == 2)
            .map(|t| [t.coefficients[0], t.coefficients[1]])
    }

    /// D_q|δ_r|δ_r at `nu` and heading `psi`: on the velocity through the
    /// water ν_r = ν − ν_c(ψ) when the model carries a current (the hull's
    /// drag follows it, as the fit's `through_water`), else on ν.
    fn quadratic_force(&self, d: &QuadraticDamping, nu: &[f64], psi: f64) -> Vec<f64> {
        let surge = self.dofs.iter().position(|d| *d == Dof::Surge);
        let Some(current) = self.current() else {
            return d.force(nu, surge);
        };
        let (uc, vc) = crate::models::current::body_current(current, psi);
        let rel: Vec<f64> = nu
            .iter()
            .zip(&self.dofs)
            .map(|(v, dof)| match dof {
                Dof::Surge => v - uc,
                Dof::Sway => v - vc,
                _ => *v,
            })
            .collect();
        d.force(&rel, surge)
    }

    /// Whether ½(M + Mᵀ) is positive definite: the kinetic energy ½νᵀMν
    /// of the model is positive.
    pub fn inertia_positive(&self) -> bool {
        let low = inertia_floor(&self.m);
        low.is_finite() && low > 0.0
    }

    /// Whether φ and θ are integrated from the model's own p, q, r (six
    /// DOFs in [`Dof::ALL`] order), as the vehicle does: driven by the
    /// measured attitude, roll and pitch would lose their restoring spring
    /// and a force error δ would drift the rate by δ/D instead of tilting
    /// the hull by δ/(z_G·W − z_B·B).
    pub fn attitude_in_loop(&self) -> bool {
        self.dofs == Dof::ALL
    }

    /// The actuator chain of `rec` as this model sees it: the held command
    /// per DOF and the lag states at every sample (exact for ZOH input).
    pub(crate) fn drive(&self, rec: &Record) -> Drive {
        let input = self.applied_input(rec);
        let lags = self.lag_states(&input, rec.h);
        Drive {
            input,
            lags,
            etd: RefCell::default(),
        }
    }

    /// The state at sample `k` taken from the record: measured ν and, with
    /// the attitude in the loop, measured (φ, θ).
    pub(crate) fn measured_state(&self, rec: &Record, k: usize) -> State {
        State {
            nu: (0..self.dofs.len()).map(|i| rec.nu[(k, i)]).collect(),
            attitude: self
                .attitude_in_loop()
                .then(|| [rec.eta[(k, 3)], rec.eta[(k, 4)]]),
        }
    }

    /// One sample interval k → k+1 from `x` (RK4, sub-stepped as the model
    /// stiffens; a stiff linear part by ETDRK4, its modes exactly): τ held, η between samples linear in the record (φ and θ the
    /// model's own when in the loop), the lag states starting from their
    /// exact values at k.
    pub(crate) fn step(&self, rec: &Record, drive: &Drive, k: usize, x0: &State) -> State {
        let n = self.dofs.len();
        let input = &drive.input;
        let lag_dofs: Vec<usize> = (0..n).filter(|&i| input.lag[i].is_some()).collect();
        let att = x0.attitude.is_some();
        let mut x: Vec<f64> = x0.nu.clone();
        x.extend(
            lag_dofs
                .iter()
                .map(|&i| drive.lags[i].as_ref().map_or(0.0, |l| l[k])),
        );
        let a0 = x.len();
        if let Some([phi, theta]) = x0.attitude {
            x.extend([phi, theta]);
        }
        // The time within the sample interval as a state (ḟ = 1/h): RK4
        // evaluates its stages at the right fraction of the interval.
        let fr = x.len();
        x.push(0.0);
        let u: Vec<f64> = (0..n).map(|i| input.held[i][k]).collect();
        let len = rec.len();
        let e0 = rec.eta_at(k);
        let e1 = rec.eta_at((k + 1).min(len - 1));
        // A stiff linear part is integrated exactly (ETDRK4): only the
        // quadratic damping's rate then sets the sub-steps.
        let stiff = rec.h * self.rate > STIFF_STEP;
        let linear_rate = if stiff { 0.0 } else { self.rate };
        let sub = ((rec.h * (linear_rate + self.quadratic_rate(&x0.nu)) / 2.0).ceil() as usize)
            .clamp(1, 200);
        let h = rec.h / sub as f64;
        let mut f = |x: &[f64], u: &[f64], dx: &mut [f64]| {
            let frac = x[fr];
            dx[fr] = 1.0 / rec.h;
            let mut eta: [f64; 6] = std::array::from_fn(|j| e0[j] + frac * (e1[j] - e0[j]));
            if att {
                eta[3] = x[a0];
                eta[4] = x[a0 + 1];
                let (phi_dot, theta_dot) = euler_rates(x[a0], x[a0 + 1], x[3], x[4], x[5]);
                dx[a0] = phi_dot;
                dx[a0 + 1] = theta_dot;
            }
            // n ≤ 6: the DOFs are distinct.
            let mut tau_a = [0.0; 6];
            tau_a[..n].copy_from_slice(u);
            for (s, &i) in lag_dofs.iter().enumerate() {
                let t_a = input.lag[i].unwrap_or(1.0);
                tau_a[i] = x[n + s];
                dx[n + s] = (u[i] - x[n + s]) / t_a;
            }
            // The angles' sines and cosines once per stage, for g(η) and
            // every term that reads them.
            let trig = Trig::of(&eta);
            let g6 = self.restoring.g_at(trig.phi, trig.theta);
            let mut g = [0.0; 6];
            for (gi, d) in g.iter_mut().zip(&self.dofs) {
                *gi = g6[d.index()];
            }
            self.nu_dot(
                &x[..n],
                &tau_a[..n],
                &g[..n],
                &eta,
                Some(&trig),
                &mut dx[..n],
            );
        };
        if stiff {
            let etd = drive.etd(sub, || EtdRk4::new(&self.linear, h));
            let l = &self.linear;
            let mut nl = |x: &[f64], u: &[f64], dx: &mut [f64]| {
                f(x, u, dx);
                for (i, d) in dx.iter_mut().enumerate().take(n) {
                    *d -= (0..n).map(|j| l[(i, j)] * x[j]).sum::<f64>();
                }
            };
            for _ in 0..sub {
                etd.step(&mut nl, &mut x, &u);
            }
        } else {
            for _ in 0..sub {
                rk4_step(&mut f, &mut x, &u, h);
            }
        }
        let next = State {
            nu: x[..n].to_vec(),
            attitude: att.then(|| [x[a0], x[a0 + 1]]),
        };
        if next.is_finite() {
            next
        } else {
            // A diverging candidate: restart from rest rather than overflow.
            let mut rest = self.measured_state(rec, (k + 1).min(len - 1));
            rest.nu.iter_mut().for_each(|v| *v = 0.0);
            rest
        }
    }

    /// The largest rate ‖M⁻¹ ∂(D_q|δ|δ)/∂ν‖∞ = max_i Σ_j |M⁻¹_ij| 2 d_j |δ_j|
    /// (1/s) at `nu`: quadratic damping stiffens the ODE as the motion
    /// grows, and the sub-steps follow it.
    fn quadratic_rate(&self, nu: &[f64]) -> f64 {
        let Some(d) = &self.quadratic else {
            return 0.0;
        };
        let surge = self.dofs.iter().position(|x| *x == Dof::Surge);
        let n = self.dofs.len();
        let rate = (0..n)
            .map(|i| {
                (0..n)
                    .filter(|&j| Some(j) != surge)
                    .map(|j| {
                        self.m_inv[(i, j)].abs()
                            * 2.0
                            * d.d_q.get(j).copied().unwrap_or(0.0)
                            * nu.get(j).map_or(0.0, |v| v.abs())
                    })
                    .sum::<f64>()
            })
            .fold(0.0, f64::max);
        if rate.is_finite() { rate } else { 0.0 }
    }

    fn lag_states(&self, input: &AppliedInput, h: f64) -> Vec<Option<Vec<f64>>> {
        input
            .lag
            .iter()
            .zip(&input.held)
            .map(|(l, x)| l.map(|t| lag_zoh(x, t, h)))
            .collect()
    }

    /// Free-run simulation from the recorded ν(0) (thesis eq. 2.20–2.21),
    /// N × n.
    pub fn simulate(&self, rec: &Record) -> DMatrix<f64> {
        let drive = self.drive(rec);
        free_run(
            rec,
            self.dofs.len(),
            |r, k| self.measured_state(r, k),
            |k, x| self.step(rec, &drive, k, x),
        )
    }

    /// k-step-ahead prediction ν̂(t | t−k) from the measured ν(t−k) (and
    /// attitude); rows t < k are NaN.
    pub fn predict_k_step(&self, rec: &Record, k: usize) -> DMatrix<f64> {
        let drive = self.drive(rec);
        k_step(
            rec,
            self.dofs.len(),
            k,
            |r, t| self.measured_state(r, t),
            |s, x| self.step(rec, &drive, s, x),
        )
    }
}

/// The actuator chain of one record as one model sees it.
pub(crate) struct Drive {
    input: AppliedInput,
    lags: Vec<Option<Vec<f64>>>,
    /// A stiff model's ETDRK4 coefficients per sub-step count, made on
    /// first use.
    etd: RefCell<Vec<(usize, Rc<EtdRk4>)>>,
}

impl Drive {
    fn etd(&self, sub: usize, make: impl FnOnce() -> EtdRk4) -> Rc<EtdRk4> {
        if let Some((_, e)) = self.etd.borrow().iter().find(|(s, _)| *s == sub) {
            return e.clone();
        }
        let e = Rc::new(make());
        self.etd.borrow_mut().push((sub, e.clone()));
        e
    }
}

#[cfg(test)]
mod tests;
