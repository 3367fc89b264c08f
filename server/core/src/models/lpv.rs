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
}

/// An [`LpvModel`] discretized (ZOH) at one sample time, ready to step.
#[derive(Debug, Clone, PartialEq)]
pub struct DiscreteLpv {
    grid_speeds: Vec<f64>,
    points: Vec<DiscreteStateSpace>,
    /// Column of ν holding the surge velocity u, if surge is modelled.
    surge: Option<usize>,
    /// The extension's models (exact discretizations of [`LpvModel::at`])
    /// at evenly spaced speeds from each grid end outwards to the edge,
    /// below and above; empty without an extension.
    beyond: [Vec<(f64, DiscreteStateSpace)>; 2],
}

/// Speeds tabulated over each side of an extension. Φ = e^{Ah} is not
/// linear in A: extrapolating the end points' Φ linearly can leave the
/// unit circle where the extrapolated A is stable, so the extension is
/// discretized exactly at these speeds and interpolated between them.
const BEYOND_STEPS: usize = 8;

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
        let ((l, wl), (u, wu)) = self.pair(speed, scheduling);
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
    /// second weight 0 when one model serves).
    fn pair(
        &self,
        speed: f64,
        scheduling: Scheduling,
    ) -> ((&DiscreteStateSpace, f64), (&DiscreteStateSpace, f64)) {
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
                        return ((prev.1, w), (model, 1.0 - w));
                    }
                    prev = (*s, model);
                }
                return ((prev.1, 1.0), (prev.1, 0.0));
            }
        }
        let w = schedule(g, speed, scheduling);
        (
            (&self.points[w.lower], w.w_lower),
            (&self.points[w.upper], 1.0 - w.w_lower),
        )
    }

    /// x̂(k+1 | k) from ν(k) = `x` and γ(k) = `u`, scheduled on the surge
    /// entry of `x` (thesis eq. 2.16–2.18); without a surge DOF, on the
    /// first grid point. A non-finite speed schedules on the first grid point
    /// too (its prediction is non-finite anyway).
    pub fn step(&self, x: &DVector<f64>, u: &DVector<f64>, scheduling: Scheduling) -> DVector<f64> {
        let ((l, wl), (m, wm)) = match self.surge {
            Some(i) if x[i].is_finite() => self.pair(x[i], scheduling),
            _ => self.pair(self.grid_speeds[0], Scheduling::Nearest),
        };
        let lower = l.step(x, u);
        if wm == 0.0 {
            return lower;
        }
        lower * wl + m.step(x, u) * wm
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
        self.dofs()
            .iter()
            .map(|d| d.velocity_symbol().to_string())
            .collect()
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simulation::integrate::simulate as rk4_simulate;
    use crate::validation::nrmse_fit_columns;

    const GRID: [f64; 3] = [0.5, 1.0, 1.5];

    /// Surge–yaw sub-model at grid speed `x`: surge damping grows with speed,
    /// surge couples into yaw through D̄[yaw,surge] (Munk-like moment).
    fn point(x: f64) -> LinearVesselModel {
        let m = DMatrix::from_row_slice(2, 2, &[5000.0, 0.0, 0.0, 3000.0]);
        let d = DMatrix::from_row_slice(
            2,
            2,
            &[300.0 + 600.0 * x, 0.0, 150.0 * x, 400.0 + 200.0 * x],
        );
        LinearVesselModel::new(vec![Dof::Surge, Dof::Yaw], m, d).unwrap()
    }

    fn lpv() -> LpvModel {
        LpvModel::new(GRID.to_vec(), GRID.iter().map(|&x| point(x)).collect()).unwrap()
    }

    #[test]
    fn grid_speeds_return_their_sub_model() {
        let lpv = lpv();
        for (i, &x) in GRID.iter().enumerate() {
            for s in [Scheduling::Nearest, Scheduling::Interpolate] {
                let w = lpv.weights(x, s).unwrap();
                assert_eq!((w.lower, w.upper, w.w_lower), (i, i, 1.0));
                assert_eq!(&lpv.at(x, s).unwrap(), &lpv.points()[i]);
            }
        }
        // Outside the grid: the end models (thesis's edge rule).
        for s in [Scheduling::Nearest, Scheduling::Interpolate] {
            assert_eq!(lpv.weights(0.1, s).unwrap().lower, 0);
            assert_eq!(lpv.weights(2.4, s).unwrap().upper, 2);
        }
        // Nearest: 0.74 → 0.5, 0.76 → 1.0, tie 0.75 → the lower point.
        let near = |v| lpv.weights(v, Scheduling::Nearest).unwrap().lower;
        assert_eq!((near(0.74), near(0.76), near(0.75)), (0, 1, 0));
        assert!(lpv.weights(f64::NAN, Scheduling::Nearest).is_err());
    }

    #[test]
    fn midway_interpolation_is_the_average() {
        let lpv = lpv();
        let mid = lpv.at(1.25, Scheduling::Interpolate).unwrap();
        let (a, b) = (&lpv.points()[1], &lpv.points()[2]);
        assert!((mid.m() - (a.m() + b.m()) * 0.5).amax() < 1e-12);
        assert!((mid.d_bar() - (a.d_bar() + b.d_bar()) * 0.5).amax() < 1e-12);
        // Surge damping is linear in x, so the average equals the model at 1.25.
        assert!((mid.d_bar()[(0, 0)] - (300.0 + 600.0 * 1.25)).abs() < 1e-9);
        // A quarter of the way: w_lower = 0.75.
        let w = lpv.weights(1.125, Scheduling::Interpolate).unwrap();
        assert_eq!((w.lower, w.upper), (1, 2));
        assert!((w.w_lower - 0.75).abs() < 1e-15);
        // Discrete: Φ and Γ averaged.
        let d = lpv.discretize(0.1).unwrap();
        let dm = d.at(1.25, Scheduling::Interpolate).unwrap();
        let (pa, pb) = (&d.points()[1], &d.points()[2]);
        assert!((dm.phi() - (pa.phi() + pb.phi()) * 0.5).amax() < 1e-15);
        assert!((dm.gamma() - (pa.gamma() + pb.gamma()) * 0.5).amax() < 1e-15);
    }

    /// Truth: ν̇ = A_i ν + B_i γ with i the grid point nearest to the forward
    /// speed sampled at the start of each interval (piecewise constant in
    /// speed), integrated by fine RK4. Surge is driven to hold 0.5, 1.0,
    /// 1.5, 1.0 m/s in turn with a square-wave perturbation; yaw is excited
    /// by its own square wave.
    fn truth_record(n: usize, h: f64) -> (DMatrix<f64>, DMatrix<f64>) {
        let lpv = lpv();
        let targets = [0.5, 1.0, 1.5, 1.0];
        let seg = n / targets.len() + 1;
        let u = DMatrix::from_fn(n, 2, |k, j| {
            let sq = if (k / [13, 29][j]) % 2 == 0 {
                1.0
            } else {
                -1.0
            };
            if j == 0 {
                let x = targets[k / seg];
                (300.0 + 600.0 * x) * x + 120.0 * sq
            } else {
                80.0 * sq
            }
        });
        let sub = 40;
        let mut y = DMatrix::zeros(n, 2);
        let mut x = vec![0.5, 0.0];
        for k in 0..n {
            y[(k, 0)] = x[0];
            y[(k, 1)] = x[1];
            let w = lpv.weights(x[0], Scheduling::Nearest).unwrap();
            let p = &lpv.points()[w.lower];
            let (a, b) = (p.a().clone(), p.b().clone());
            let g = vec![vec![u[(k, 0)], u[(k, 1)]]; sub];
            let xs = rk4_simulate(
                |s, gg, ds| {
                    let dv =
                        &a * DVector::from_column_slice(s) + &b * DVector::from_column_slice(gg);
                    ds.copy_from_slice(dv.as_slice());
                },
                &x,
                &g,
                h / sub as f64,
            );
            x = xs[sub].clone();
        }
        (u, y)
    }

    #[test]
    fn predictor_follows_a_piecewise_constant_speed_truth() {
        let h = 0.1;
        let n = 1600;
        let (u, y) = truth_record(n, h);
        // The record visits every grid cell.
        let (lo, hi) = (y.column(0).min(), y.column(0).max());
        assert!(lo < 0.6 && hi > 1.4, "u range {lo}..{hi}");
        let rec = ValidationRecord { h, u: &u, y: &y };

        let nearest = lpv().with_scheduling(Scheduling::Nearest);
        for k in [1, 10] {
            let yh = nearest.predict_k_step(&rec, k);
            let err = (yh.rows(k, n - k) - y.rows(k, n - k)).amax();
            assert!(err < 1e-9, "nearest, k = {k}: max error {err}");
        }
        let sim_err = (nearest.simulate(&rec) - &y).amax();
        assert!(sim_err < 1e-8, "nearest free run: {sim_err}");

        // Interpolation blends neighbours the truth does not blend: close but
        // not exact. A single LTI model (1.0 m/s) is clearly worse in surge.
        let fit = |p: &dyn Predictor| nrmse_fit_columns(&y, &p.simulate(&rec))[0].unwrap();
        let f_interp = fit(&lpv());
        let f_lti = fit(&lpv().points()[1]);
        assert!(
            f_interp > 0.9 && f_interp < 1.0 - 1e-6,
            "interpolated fit {f_interp}"
        );
        assert!(f_lti < 0.5, "LTI fit {f_lti} vs LPV {f_interp}");
    }

    /// Below the grid, within an extension: D̄ linear and the load quadratic
    /// in speed (exact for the tangents of d_l·u + d_q·u|u|), M the lowest
    /// point's even when the points' estimates of it differ; the discrete
    /// model is the exact discretization there, not an extrapolated Φ.
    #[test]
    fn an_extension_extrapolates_damping_and_load_and_keeps_m() {
        let (d_l, d_q) = (300.0, 600.0);
        let points = GRID
            .iter()
            .map(|&x| {
                let m = DMatrix::from_row_slice(2, 2, &[5000.0 + 200.0 * x, 0.0, 0.0, 3000.0]);
                let d =
                    DMatrix::from_row_slice(2, 2, &[d_l + 2.0 * d_q * x, 0.0, 150.0 * x, 400.0]);
                LinearVesselModel::new(vec![Dof::Surge, Dof::Yaw], m, d)
                    .unwrap()
                    .with_load(DVector::from_vec(vec![-d_q * x * x, 10.0 * x]))
                    .unwrap()
            })
            .collect();
        let ext = Extension {
            from_mps: 0.2,
            to_mps: 1.5,
        };
        let lpv = LpvModel::new(GRID.to_vec(), points).unwrap();
        assert!(
            lpv.clone()
                .with_extension(Extension {
                    from_mps: 0.6,
                    to_mps: 1.5
                })
                .is_err()
        );
        let lpv = lpv.with_extension(ext).unwrap();
        let at = lpv.at(0.35, Scheduling::Interpolate).unwrap();
        assert_eq!(at.m(), lpv.points()[0].m());
        assert!((at.d_bar()[(0, 0)] - (d_l + 2.0 * d_q * 0.35)).abs() < 1e-9);
        assert!((at.d_bar()[(1, 0)] - 150.0 * 0.35).abs() < 1e-9);
        assert!((at.load()[0] + d_q * 0.35 * 0.35).abs() < 1e-9);
        assert!((at.load()[1] - 3.5).abs() < 1e-9);
        // Below the extension: its edge model; above the grid: held.
        assert_eq!(
            lpv.at(0.05, Scheduling::Interpolate).unwrap(),
            lpv.at(0.2, Scheduling::Interpolate).unwrap()
        );
        assert_eq!(
            &lpv.at(1.9, Scheduling::Interpolate).unwrap(),
            &lpv.points()[2]
        );
        // 0.35 m/s is one of the tabulated speeds (0.5 − 0.3·4/8).
        let d = lpv.discretize(0.1).unwrap();
        let exact = at.discretize(0.1).unwrap();
        let tab = d.at(0.35, Scheduling::Interpolate).unwrap();
        assert!((tab.phi() - exact.phi()).amax() < 1e-12);
        assert!((tab.offset() - exact.offset()).amax() < 1e-12);
        // Between tabulated speeds, close to the exact discretization.
        let mid = d.at(0.3, Scheduling::Interpolate).unwrap();
        let exact = lpv
            .at(0.3, Scheduling::Interpolate)
            .unwrap()
            .discretize(0.1)
            .unwrap();
        assert!((mid.phi() - exact.phi()).amax() < 1e-5);
        // Nearest scheduling ignores the extension.
        assert_eq!(&lpv.at(0.3, Scheduling::Nearest).unwrap(), &lpv.points()[0]);
    }

    #[test]
    fn without_surge_the_first_grid_point_is_used() {
        let mk = |x: f64| {
            LinearVesselModel::new(
                vec![Dof::Sway, Dof::Yaw],
                DMatrix::from_row_slice(2, 2, &[7000.0, 100.0, 100.0, 3000.0]),
                DMatrix::from_row_slice(2, 2, &[900.0 * x, 0.0, 0.0, 500.0 * x]),
            )
            .unwrap()
        };
        let lpv = LpvModel::new(GRID.to_vec(), GRID.iter().map(|&x| mk(x)).collect()).unwrap();
        let u = DMatrix::from_fn(200, 2, |k, j| {
            if (k / (17 + 5 * j)) % 2 == 0 {
                300.0
            } else {
                -200.0
            }
        });
        let y = DMatrix::from_fn(200, 2, |k, j| 2.0 + (0.1 * k as f64 + j as f64).sin());
        let rec = ValidationRecord {
            h: 0.1,
            u: &u,
            y: &y,
        };
        let a = lpv.predict_k_step(&rec, 5);
        let b = lpv.points()[0].predict_k_step(&rec, 5);
        assert!((a.rows(5, 195) - b.rows(5, 195)).amax() < 1e-12);
        assert_eq!(lpv.output_names(), ["v", "r"]);
    }

    #[test]
    fn inconsistent_grids_are_typed_errors() {
        let err = LpvModel::new(vec![1.0, 0.5], vec![point(1.0), point(0.5)]).unwrap_err();
        assert_eq!(
            err.to_string(),
            "LPV grid: grid_speeds must be strictly increasing, but grid_speeds[1] = 0.5 follows 1"
        );
        let err = LpvModel::new(vec![0.5], vec![point(0.5), point(1.0)]).unwrap_err();
        assert!(
            err.to_string()
                .contains("grid_speeds has 1 entries but points has 2"),
            "{err}"
        );
        let other = LinearVesselModel::new(
            vec![Dof::Surge, Dof::Sway],
            DMatrix::identity(2, 2),
            DMatrix::identity(2, 2),
        )
        .unwrap();
        let err = LpvModel::new(vec![0.5, 1.0], vec![point(0.5), other]).unwrap_err();
        assert_eq!(
            err.to_string(),
            "LPV grid: points[1] models [surge, sway] but points[0] models [surge, yaw]"
        );
        let err = LpvModel::new(vec![f64::NAN], vec![point(0.5)]).unwrap_err();
        assert_eq!(
            err.to_string(),
            "grid_speeds contains NaN or infinite entries"
        );
        assert!(LpvModel::new(vec![], vec![]).is_err());
    }
}
