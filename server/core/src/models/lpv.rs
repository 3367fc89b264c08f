//! Linear parameter-varying model scheduled on forward speed (thesis sec. 1.3,
//! eq. 1.8): one [`LinearVesselModel`] M_x ν̇ + D̄_x ν = γ per grid speed x.
//!
//! Scheduling (thesis sec. 2.6):
//! - [`Scheduling::Nearest`], eq. 2.17: the sub-model whose grid speed is
//!   nearest to u (the thesis writes argmin(u − r(i)); the distance |u − x_i|
//!   is meant). A tie midway between two grid points takes the lower one.
//! - [`Scheduling::Interpolate`], eq. 2.18: the outputs of the two sub-models
//!   bracketing u are blended, x̂(k+1|k) = w (Φ_l x + Γ_l u) +
//!   (1 − w)(Φ_u x + Γ_u u), w ∈ [0, 1]. The thesis does not spell out w(k);
//!   we take the linear weight w = (x_u − u)/(x_u − x_l), which is 1 at the
//!   lower grid point and 0 at the upper one, so the blend is continuous in u
//!   and returns the sub-model itself at a grid speed. Outside the grid only
//!   the nearest end model is used, as in the thesis — unless the model has
//!   an [`Extension`]: then, over its stated range, the end sub-models are
//!   extrapolated the way hull forces vary with speed (see
//!   [`super::lpv_schedule`]).
//!
//! Since both sub-models start from the same x(k) and u(k), blending outputs
//! equals blending the discrete matrices Φ and Γ ([`DiscreteLpv::at`]).
//! [`LpvModel::at`] blends the continuous M and D̄ instead, which keeps M
//! symmetric positive definite and D̄ dissipative when the grid models are.

use nalgebra::{DMatrix, DVector};

use super::error::{ModelError, check_finite};
pub use super::lpv_schedule::{Blend, Extension, ScheduleWeights, Scheduling};
use super::lpv_schedule::{blend as schedule_blend, schedule};
use super::predict::{check_record, free_run, k_step, no_prediction};
use super::state_space::DiscreteStateSpace;
use super::vessel::LinearVesselModel;
use crate::planning::dof::Dof;
use crate::validation::{Predictor, ValidationRecord};

/// M_x ν̇ + D̄_x ν = γ at each grid speed x (m/s, forward speed u through
/// the water as the INS measures it).
#[derive(Debug, Clone, PartialEq)]
pub struct LpvModel {
    grid_speeds: Vec<f64>,
    points: Vec<LinearVesselModel>,
    scheduling: Scheduling,
    extension: Option<Extension>,
    /// The vehicle's M per grid point for the second-order Coriolis–
    /// centripetal force C(δ)δ ([`second_order_force_about`]); `None`: the thesis's
    /// linear sub-models alone.
    coriolis: Option<Vec<DMatrix<f64>>>,
    /// Diagonal quadratic damping D_q per grid point (one entry per DOF,
    /// [`super::quadratic_damping::quadratic_force`]); `None`: linear damping only.
    quadratic: Option<Vec<DVector<f64>>>,
}

/// Speeds tabulated over each side of an extension. Φ = e^{Ah} is not
/// linear in A: extrapolating the end points' Φ linearly can leave the
/// unit circle where the extrapolated A is stable, so the extension is
/// discretized exactly at these speeds and interpolated between them.
pub(crate) const BEYOND_STEPS: usize = 8;

fn check_speed(speed: f64) -> Result<(), ModelError> {
    if speed.is_finite() {
        Ok(())
    } else {
        Err(ModelError::InvalidParameter {
            name: "speed",
            value: speed,
            requirement: "a finite forward speed in m/s",
        })
    }
}

impl LpvModel {
    /// An LPV model from its grid (m/s, strictly increasing, finite) and one
    /// sub-model per grid speed, all over the same DOFs in the same order.
    /// Scheduling defaults to [`Scheduling::Interpolate`].
    pub fn new(grid_speeds: Vec<f64>, points: Vec<LinearVesselModel>) -> Result<Self, ModelError> {
        if grid_speeds.is_empty() {
            return Err(ModelError::Grid {
                reason: "grid_speeds is empty; at least one sub-model is needed".into(),
            });
        }
        if grid_speeds.len() != points.len() {
            return Err(ModelError::Grid {
                reason: format!(
                    "grid_speeds has {} entries but points has {}; one sub-model per grid speed",
                    grid_speeds.len(),
                    points.len()
                ),
            });
        }
        check_finite("grid_speeds", grid_speeds.iter())?;
        for (i, pair) in grid_speeds.windows(2).enumerate() {
            if pair[1] <= pair[0] {
                return Err(ModelError::Grid {
                    reason: format!(
                        "grid_speeds must be strictly increasing, but grid_speeds[{}] = {} follows {}",
                        i + 1,
                        pair[1],
                        pair[0]
                    ),
                });
            }
        }
        for (i, p) in points.iter().enumerate().skip(1) {
            if p.dofs() != points[0].dofs() {
                let names = |d: &[Dof]| d.iter().map(|d| d.name()).collect::<Vec<_>>().join(", ");
                return Err(ModelError::Grid {
                    reason: format!(
                        "points[{i}] models [{}] but points[0] models [{}]",
                        names(p.dofs()),
                        names(points[0].dofs())
                    ),
                });
            }
        }
        Ok(LpvModel {
            grid_speeds,
            points,
            scheduling: Scheduling::default(),
            extension: None,
            coriolis: None,
            quadratic: None,
        })
    }

    /// The same model extended beyond its grid down to `ext.from_mps` and
    /// up to `ext.to_mps` (see [`Extension`]).
    ///
    /// # Errors
    /// [`ModelError::Grid`] when a bound is not finite or lies inside the
    /// grid.
    pub fn with_extension(mut self, ext: Extension) -> Result<Self, ModelError> {
        let (lo, hi) = (
            self.grid_speeds[0],
            self.grid_speeds[self.grid_speeds.len() - 1],
        );
        if !(ext.from_mps.is_finite() && ext.to_mps.is_finite())
            || ext.from_mps > lo
            || ext.to_mps < hi
        {
            return Err(ModelError::Grid {
                reason: format!(
                    "an extension must reach from at most the lowest grid speed ({lo} m/s) to at least the highest ({hi} m/s); got {} … {} m/s",
                    ext.from_mps, ext.to_mps
                ),
            });
        }
        self.extension = Some(ext);
        Ok(self)
    }

    /// The same model with the second-order Coriolis–centripetal force
    /// C(δ)δ of the vehicle's inertia `m` (one per grid point, the M of the
    /// vehicle rather than the M a log behind a faster controller shows):
    /// each sub-model is driven by γ − C(δ)δ ([`second_order_force_about`]).
    /// Beyond the grid the end point's M serves, as M does.
    ///
    /// # Errors
    /// [`ModelError::Grid`] without a surge DOF (δ is taken about the
    /// scheduled forward speed) or with one M per grid point missing;
    /// [`ModelError::Shape`] or a finiteness error for a malformed M.
    pub fn with_second_order_coriolis(mut self, m: Vec<DMatrix<f64>>) -> Result<Self, ModelError> {
        if !self.dofs().contains(&Dof::Surge) {
            return Err(ModelError::Grid {
                reason: "the second-order Coriolis force is taken about the forward speed: surge must be modelled".into(),
            });
        }
        self.one_per_point(m.len(), "M", "the Coriolis force")?;
        let n = self.dofs().len();
        for (k, mk) in m.iter().enumerate() {
            if mk.shape() != (n, n) {
                return Err(ModelError::Shape {
                    name: format!("coriolis M[{k}]"),
                    expected: format!("{n}×{n}"),
                    found: mk.shape(),
                });
            }
            check_finite("coriolis M", mk.iter())?;
        }
        self.coriolis = Some(m);
        Ok(self)
    }

    /// `Err` unless `got` (matrices `what` for `purpose`) is one per grid point.
    fn one_per_point(&self, got: usize, what: &str, purpose: &str) -> Result<(), ModelError> {
        if got == self.points.len() {
            return Ok(());
        }
        Err(ModelError::Grid {
            reason: format!(
                "one {what} per grid point is needed for {purpose}: got {got} for {} points",
                self.points.len()
            ),
        })
    }

    /// The same model without the second-order Coriolis force.
    pub fn without_second_order_coriolis(mut self) -> Self {
        self.coriolis = None;
        self
    }

    /// The vehicle's M per grid point of the second-order Coriolis force,
    /// if the model carries it.
    pub fn second_order_coriolis(&self) -> Option<&[DMatrix<f64>]> {
        self.coriolis.as_deref()
    }

    /// The same model with diagonal quadratic damping D_q|δ|δ, one D_q per
    /// grid point (n entries, N·s²/m² or N·m·s²/rad²): each sub-model is
    /// driven by γ − D_q|δ|δ ([`super::quadratic_damping::quadratic_force`]),
    /// taken linearly implicit over each step; with surge modelled, its
    /// entry is X_|u|u and the sub-model at u₀ is driven by its remainder
    /// beyond the tangent ([`super::quadratic_damping::surge_remainder`]),
    /// with Heun's rule. Beyond the grid the end point's D_q serves.
    ///
    /// # Errors
    /// [`ModelError::Grid`] with one D_q per grid point missing;
    /// [`ModelError::Shape`] for a wrong length; an invalid-parameter error
    /// for a negative or non-finite entry (D_q must dissipate).
    pub fn with_quadratic_damping(mut self, d_q: Vec<DVector<f64>>) -> Result<Self, ModelError> {
        self.one_per_point(d_q.len(), "D_q", "the quadratic damping")?;
        let n = self.dofs().len();
        for (k, d) in d_q.iter().enumerate() {
            if d.len() != n {
                return Err(ModelError::Shape {
                    name: format!("D_q[{k}]"),
                    expected: format!("{n}×1"),
                    found: (d.len(), 1),
                });
            }
            if let Some(&v) = d.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
                return Err(ModelError::InvalidParameter {
                    name: "D_q",
                    value: v,
                    requirement: "finite and ≥ 0 (quadratic damping dissipates)",
                });
            }
        }
        self.quadratic = Some(d_q);
        Ok(self)
    }

    /// The same model without quadratic damping.
    pub fn without_quadratic_damping(mut self) -> Self {
        self.quadratic = None;
        self
    }

    /// D_q per grid point, if the model carries quadratic damping.
    pub fn quadratic_damping(&self) -> Option<&[DVector<f64>]> {
        self.quadratic.as_deref()
    }

    /// The speeds the model extends to beyond its grid, if any.
    pub fn extension(&self) -> Option<Extension> {
        self.extension
    }

    /// Weights of the sub-models at `speed` (m/s), with the extension.
    pub fn blend_at(&self, speed: f64, scheduling: Scheduling) -> Result<Blend, ModelError> {
        check_speed(speed)?;
        Ok(schedule_blend(
            &self.grid_speeds,
            self.extension,
            speed,
            scheduling,
        ))
    }

    /// The same model predicting with `scheduling`.
    pub fn with_scheduling(mut self, scheduling: Scheduling) -> Self {
        self.scheduling = scheduling;
        self
    }

    /// Grid speeds (m/s).
    pub fn grid_speeds(&self) -> &[f64] {
        &self.grid_speeds
    }
    /// Sub-models, one per grid speed.
    pub fn points(&self) -> &[LinearVesselModel] {
        &self.points
    }
    /// Modelled DOFs (shared by all sub-models).
    pub fn dofs(&self) -> &[Dof] {
        self.points[0].dofs()
    }
    /// Scheduling used by the [`Predictor`] implementation.
    pub fn scheduling(&self) -> Scheduling {
        self.scheduling
    }

    /// Which grid points serve forward speed `speed` (m/s), with weights.
    pub fn weights(
        &self,
        speed: f64,
        scheduling: Scheduling,
    ) -> Result<ScheduleWeights, ModelError> {
        check_speed(speed)?;
        Ok(schedule(&self.grid_speeds, speed, scheduling))
    }

    /// The continuous model at forward speed `speed` (m/s): the nearest
    /// sub-model, or M and D̄ blended with the weights of eq. 2.18 (and the
    /// load with its own weights beyond the grid, see [`Extension`]).
    pub fn at(&self, speed: f64, scheduling: Scheduling) -> Result<LinearVesselModel, ModelError> {
        let b = self.blend_at(speed, scheduling)?;
        let [(i, wi), (j, wj)] = b.dynamics;
        if i == j {
            return Ok(self.points[i].clone());
        }
        let (l, u) = (&self.points[i], &self.points[j]);
        let load = b
            .load
            .iter()
            .fold(DVector::zeros(l.load().len()), |acc, &(k, v)| {
                acc + self.points[k].load() * v
            });
        // Beyond the grid M stays the end point's: it does not change with
        // speed, and extrapolating the points' estimates would amplify their
        // scatter.
        let m = if b.extrapolated {
            l.m().clone()
        } else {
            l.m() * wi + u.m() * wj
        };
        LinearVesselModel::new(l.dofs().to_vec(), m, l.d_bar() * wi + u.d_bar() * wj)?
            .with_load(load)
    }

    /// Every sub-model discretized (ZOH) at sample time `h` (s).
    pub fn discretize(&self, h: f64) -> Result<DiscreteLpv, ModelError> {
        let points = self
            .points
            .iter()
            .map(|p| p.discretize(h))
            .collect::<Result<Vec<_>, _>>()?;
        let g = &self.grid_speeds;
        let (lo, hi) = (g[0], g[g.len() - 1]);
        let table = |end: f64, edge: f64| -> Result<Vec<(f64, DiscreteStateSpace)>, ModelError> {
            if g.len() < 3 || edge == end {
                return Ok(Vec::new());
            }
            (1..=BEYOND_STEPS)
                .map(|k| {
                    let s = end + (edge - end) * k as f64 / BEYOND_STEPS as f64;
                    Ok((s, self.at(s, Scheduling::Interpolate)?.discretize(h)?))
                })
                .collect()
        };
        let beyond = match self.extension {
            Some(e) => [table(lo, e.from_mps)?, table(hi, e.to_mps)?],
            None => [Vec::new(), Vec::new()],
        };
        Ok(DiscreteLpv {
            grid_speeds: self.grid_speeds.clone(),
            points,
            surge: self.dofs().iter().position(|d| *d == Dof::Surge),
            beyond,
            dofs: self.dofs().to_vec(),
            coriolis: self.coriolis.clone(),
            quadratic: self.quadratic.clone(),
        })
    }

    /// [`Predictor::predict_k_step`] with the reason when the record does not
    /// fit (see [`LinearVesselModel::try_predict_k_step`]).
    pub fn try_predict_k_step(
        &self,
        rec: &ValidationRecord<'_>,
        k: usize,
    ) -> Result<DMatrix<f64>, ModelError> {
        let n = self.dofs().len();
        check_record(rec, n, n)?;
        let lpv = self.discretize(rec.h)?;
        k_step(rec, k, |x, u| lpv.step(x, u, self.scheduling))
    }

    /// [`Predictor::simulate`] with the reason when the record does not fit.
    pub fn try_simulate(&self, rec: &ValidationRecord<'_>) -> Result<DMatrix<f64>, ModelError> {
        let n = self.dofs().len();
        check_record(rec, n, n)?;
        let lpv = self.discretize(rec.h)?;
        Ok(free_run(rec, |x, u| lpv.step(x, u, self.scheduling)))
    }
}

/// The schedule variable is the forward speed u, read from the surge column
/// of y at the start of a prediction (measured ν(t−k)) and from the model's
/// own predicted u on the following steps, since nothing later is known at
/// t−k; the free run schedules on its simulated u. Without surge among the
/// modelled DOFs the first grid point's model is used throughout. A record
/// that does not fit yields all-NaN predictions (see
/// [`LpvModel::try_predict_k_step`]).
impl Predictor for LpvModel {
    fn output_names(&self) -> Vec<String> {
        Dof::velocity_symbols(self.dofs())
    }

    fn predict_k_step(&self, rec: &ValidationRecord<'_>, k: usize) -> DMatrix<f64> {
        self.try_predict_k_step(rec, k)
            .unwrap_or_else(|_| no_prediction(rec, self.dofs().len()))
    }

    fn simulate(&self, rec: &ValidationRecord<'_>) -> DMatrix<f64> {
        self.try_simulate(rec)
            .unwrap_or_else(|_| no_prediction(rec, self.dofs().len()))
    }
}

mod discrete;
pub use discrete::DiscreteLpv;

#[cfg(test)]
mod tests;
