//! [`DiscreteLpv`]: the LPV model discretized at one sample time and
//! stepped — the sub-models' Φ, Γ blended by the schedule, C(δ)δ and D_q
//! applied over each step.

use nalgebra::{DMatrix, DVector};

use super::check_speed;
use crate::models::coriolis::second_order_force_about;
use crate::models::error::ModelError;
use crate::models::lpv_schedule::{Scheduling, schedule};
use crate::models::quadratic_damping::surge_remainder;
use crate::models::state_space::DiscreteStateSpace;
use crate::planning::dof::Dof;

/// An [`super::LpvModel`] discretized (ZOH) at one sample time, ready to step.
#[derive(Debug, Clone, PartialEq)]
pub struct DiscreteLpv {
    pub(super) grid_speeds: Vec<f64>,
    pub(super) points: Vec<DiscreteStateSpace>,
    /// Column of ν holding the surge velocity u, if surge is modelled.
    pub(super) surge: Option<usize>,
    /// The extension's models (exact discretizations of [`super::LpvModel::at`])
    /// at evenly spaced speeds from each grid end outwards to the edge,
    /// below and above; empty without an extension.
    pub(super) beyond: [Vec<(f64, DiscreteStateSpace)>; 2],
    pub(super) dofs: Vec<Dof>,
    /// M per grid point for C(δ)δ, if the model carries it.
    pub(super) coriolis: Option<Vec<DMatrix<f64>>>,
    /// D_q per grid point, if the model carries it.
    pub(super) quadratic: Option<Vec<DVector<f64>>>,
}

/// A discrete sub-model, its blending weight and the grid point whose M
/// it has.
type Weighted<'a> = (&'a DiscreteStateSpace, f64, usize, f64);

impl DiscreteLpv {
    /// Grid speeds (m/s).
    pub fn grid_speeds(&self) -> &[f64] {
        &self.grid_speeds
    }
    /// Discretized sub-models, one per grid speed.
    pub fn points(&self) -> &[DiscreteStateSpace] {
        &self.points
    }

    /// The discrete model at `speed` (m/s): Φ and Γ blended with the weights
    /// of eq. 2.17/2.18, which is the thesis's blend of the two predictions
    /// (beyond the grid, within an [`Extension`], the blend of its two
    /// nearest tabulated models).
    pub fn at(&self, speed: f64, scheduling: Scheduling) -> Result<DiscreteStateSpace, ModelError> {
        check_speed(speed)?;
        let ((l, wl, _, _), (u, wu, _, _)) = self.pair(speed, scheduling);
        if wu == 0.0 {
            return Ok(l.clone());
        }
        DiscreteStateSpace::new(
            l.phi() * wl + u.phi() * wu,
            l.gamma() * wl + u.gamma() * wu,
            l.c().clone(),
            l.d().clone(),
            l.h(),
        )?
        .with_offset(l.offset() * wl + u.offset() * wu)
    }

    /// The two discrete models blended at `speed` with their weights (the
    /// second weight 0 when one model serves) and the grid point whose M
    /// each has.
    fn pair(&self, speed: f64, scheduling: Scheduling) -> (Weighted<'_>, Weighted<'_>) {
        let g = &self.grid_speeds;
        let last = g.len() - 1;
        let side = match scheduling {
            Scheduling::Interpolate if speed < g[0] => Some((0, 0)),
            Scheduling::Interpolate if speed > g[last] => Some((1, last)),
            _ => None,
        };
        if let Some((side, end)) = side {
            let table = &self.beyond[side];
            if !table.is_empty() {
                let dist = |s: f64| (s - g[end]).abs();
                let d = dist(speed);
                let mut prev = (g[end], &self.points[end]);
                for (s, model) in table {
                    if d <= dist(*s) {
                        let w = (dist(*s) - d) / (dist(*s) - dist(prev.0));
                        return ((prev.1, w, end, prev.0), (model, 1.0 - w, end, *s));
                    }
                    prev = (*s, model);
                }
                return ((prev.1, 1.0, end, prev.0), (prev.1, 0.0, end, prev.0));
            }
        }
        let w = schedule(g, speed, scheduling);
        (
            (&self.points[w.lower], w.w_lower, w.lower, g[w.lower]),
            (&self.points[w.upper], 1.0 - w.w_lower, w.upper, g[w.upper]),
        )
    }

    /// γ − C(δ)δ with grid point `k`'s M (γ itself without C(δ)δ), and
    /// for the sub-model linearized at `u0` (m/s) the remainder of surge's
    /// quadratic drag beyond its tangent, X_|u|u times
    /// [`super::quadratic_damping::surge_remainder`].
    fn driving(&self, x: &DVector<f64>, u: &DVector<f64>, k: usize, u0: f64) -> DVector<f64> {
        let mut out = u.clone();
        if let (Some(m), Some(i)) = (&self.coriolis, self.surge) {
            out -= DVector::from_vec(second_order_force_about(
                &self.dofs,
                &m[k],
                x.as_slice(),
                i,
                u0,
            ));
        }
        if let (Some(d), Some(i)) = (&self.quadratic, self.surge) {
            let x_uu = d[k].get(i).copied().unwrap_or(0.0);
            if x_uu != 0.0 {
                out[i] -= x_uu * surge_remainder(x[i], u0);
            }
        }
        out
    }

    /// `explicit` (the step from ν(k) = `x` without D_q|δ|δ) with the
    /// quadratic damping over the step as −D_q diag|δ(k)| δ(k+1): with
    /// K = Σ w Γ D_q diag|δ(k)|, (I + K) x⁺ = x̂. Linearly implicit, it
    /// damps at any D_q and step (the explicit force overshoots zero and
    /// diverges), and for one DOF m v̇ + d v + q|v|v = 0 under ZOH it is
    /// exact: 1/v(k+1) = e^{hd/m}(1/v(k) + q/d) − q/d.
    fn implicit_quadratic(
        &self,
        explicit: DVector<f64>,
        parts: [(&DiscreteStateSpace, f64, usize); 2],
        x: &DVector<f64>,
    ) -> DVector<f64> {
        let Some(d) = &self.quadratic else {
            return explicit;
        };
        let n = explicit.len();
        let mut lhs = DMatrix::<f64>::identity(n, n);
        for (model, w, k) in parts {
            if w == 0.0 {
                continue;
            }
            let gamma = model.gamma();
            for j in (0..n.min(gamma.ncols())).filter(|&j| Some(j) != self.surge) {
                let scale = w * d[k].get(j).copied().unwrap_or(0.0) * x[j].abs();
                for i in 0..n {
                    lhs[(i, j)] += gamma[(i, j)] * scale;
                }
            }
        }
        lhs.lu().solve(&explicit).unwrap_or(explicit)
    }

    /// x̂(k+1 | k) from ν(k) = `x` and γ(k) = `u`, scheduled on the surge
    /// entry of `x` (thesis eq. 2.16–2.18); without a surge DOF, on the
    /// first grid point. A non-finite speed schedules on the first grid point
    /// too (its prediction is non-finite anyway).
    pub fn step(&self, x: &DVector<f64>, u: &DVector<f64>, scheduling: Scheduling) -> DVector<f64> {
        self.step_at(x, u, scheduling, self.surge.map(|i| x[i]))
    }

    /// [`DiscreteLpv::step`] scheduled on `speed` (m/s) instead of the
    /// surge entry of `x`: a model in a current is scheduled on its speed
    /// through the water. `None` or non-finite: the first grid point.
    pub fn step_at(
        &self,
        x: &DVector<f64>,
        u: &DVector<f64>,
        scheduling: Scheduling,
        speed: Option<f64>,
    ) -> DVector<f64> {
        let ((l, wl, kl, sl), (m, wm, km, sm)) = match speed {
            Some(s) if s.is_finite() => self.pair(s, scheduling),
            _ => self.pair(self.grid_speeds[0], Scheduling::Nearest),
        };
        let blend = |force: &dyn Fn(usize, f64) -> DVector<f64>| {
            let lower = l.step(x, &force(kl, sl));
            if wm == 0.0 {
                lower
            } else {
                lower * wl + m.step(x, &force(km, sm)) * wm
            }
        };
        if self.coriolis.is_none() && self.quadratic.is_none() {
            return blend(&|_, _| u.clone());
        }
        // C(δ)δ and surge's quadratic remainder over the step by Heun's
        // rule: the mean of the start and the predicted end (held at the
        // start it lags fast turns); D_q|δ|δ linearly implicit about |δ| of
        // the start.
        let parts = [(l, wl, kl), (m, wm, km)];
        let predicted = self.implicit_quadratic(blend(&|k, s| self.driving(x, u, k, s)), parts, x);
        self.implicit_quadratic(
            blend(&|k, s| (self.driving(x, u, k, s) + self.driving(&predicted, u, k, s)) * 0.5),
            parts,
            x,
        )
    }
}
