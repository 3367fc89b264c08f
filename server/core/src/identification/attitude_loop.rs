//! A 6-DOF LPV model with g(η) in the loop: M_x ν̇ + D̄_x ν = τ + b − g(η),
//! with φ and θ integrated from the model's own ν (Fossen's Euler-angle
//! kinematics, φ̇ = p + (q sin φ + r cos φ) tan θ, θ̇ = q cos φ − r sin φ).
//!
//! Driving a free run with γ = τ − g(η) computed from the *measured*
//! attitude leaves roll and pitch without their restoring spring: a force
//! error of δ then drifts the rate by δ/D instead of tilting the vehicle by
//! δ/(z_G·W − z_B·B). Closing the loop through the simulated attitude is
//! what the true vehicle does, so free runs and restarted free runs measure
//! the model rather than the open-loop sensitivity of a hydrostatically
//! stiff DOF. The record's inputs are [τ | η] (η measured: used only for the
//! attitude at the start of a prediction).
//!
//! One step of length h holds τ (ZOH, as the identification does) and
//! averages g(η) over the step (trapezoid, the identification's γ): a Heun
//! predictor–corrector on the attitude.
//!
//! In a current fixed in NED ([`AttitudeLoop::with_current`]) the heading
//! is integrated too, ψ̇ = (q sin φ + r cos φ)/cos θ, and the current's
//! force of the simulated heading is averaged over the step like g(η)
//! ([`HeadingLoop::drive`]: the damping of −ν_c(ψ), M ν̇_c and D_q on
//! ν_r); the sub-models are then scheduled on the speed through the water.

use nalgebra::{DMatrix, DVector};

use super::heading_loop::HeadingLoop;
use crate::estimation::restoring::RestoringParams;
use crate::models::predict::no_prediction;
use crate::models::{DiscreteLpv, LpvModel};
use crate::planning::dof::Dof;
use crate::validation::{Predictor, ValidationRecord};

/// An LPV model over the six DOFs (in [`Dof::ALL`] order) with g(η) in the
/// loop; see the module docs.
#[derive(Debug, Clone)]
pub struct AttitudeLoop {
    lpv: LpvModel,
    restoring: RestoringParams,
    /// The current's force and scheduling, when the model carries one.
    current: Option<HeadingLoop>,
}

/// (φ, θ) in rad.
type Attitude = (f64, f64);

/// (φ, θ, ψ) in rad.
type Euler = (f64, f64, f64);

impl AttitudeLoop {
    /// `None` unless the model covers the six DOFs in [`Dof::ALL`] order
    /// (φ̇ and θ̇ need p, q and r).
    pub fn new(lpv: LpvModel, restoring: RestoringParams) -> Option<Self> {
        (lpv.dofs() == Dof::ALL).then_some(AttitudeLoop {
            lpv,
            restoring,
            current: None,
        })
    }

    /// The model in a current fixed in NED, V = [V_N, V_E] (m/s)
    /// ([`super::ned_current`]); `None` as for [`AttitudeLoop::new`].
    pub fn with_current(
        lpv: LpvModel,
        restoring: RestoringParams,
        v: nalgebra::Vector2<f64>,
    ) -> Option<Self> {
        let current = Some(HeadingLoop::new(lpv.clone(), v)?);
        Some(AttitudeLoop {
            current,
            ..Self::new(lpv, restoring)?
        })
    }

    /// Names of the record's input columns: the six force columns, then η.
    pub fn input_names(force_columns: &[String]) -> Vec<String> {
        let mut names = force_columns.to_vec();
        names.extend(
            ["x", "y", "z", "phi", "theta", "psi"]
                .iter()
                .map(|s| s.to_string()),
        );
        names
    }

    fn g(&self, (phi, theta): Attitude) -> DVector<f64> {
        DVector::from_column_slice(&self.restoring.g(&[0.0, 0.0, 0.0, phi, theta, 0.0]))
    }

    /// ν_c of the current at the attitude, zero without one.
    fn nu_c(&self, (phi, theta, psi): Euler) -> DVector<f64> {
        match &self.current {
            Some(c) => c.nu_c_tilted(phi, theta, psi),
            None => DVector::zeros(6),
        }
    }

    /// ν(k+1) and the attitude at k+1 from ν(k), the attitude at k and τ(k):
    /// the LPV model steps the velocity through the water ν_r = ν − ν_c(ψ)
    /// (as it was fitted, scheduled on u_r) with −g(η) of the attitude
    /// (Heun over the step), then ν(k+1) = ν_r(k+1) + ν_c(ψ(k+1)).
    fn step(
        &self,
        lpv: &DiscreteLpv,
        h: f64,
        nu: &DVector<f64>,
        att: Euler,
        tau: &DVector<f64>,
    ) -> (DVector<f64>, Euler) {
        let scheduling = self.lpv.scheduling();
        let nu_r = nu - self.nu_c(att);
        let speed = Some(nu_r[0]);
        let advance = |a: Euler, r0: Euler, r1: Euler| {
            (
                a.0 + 0.5 * h * (r0.0 + r1.0),
                a.1 + 0.5 * h * (r0.1 + r1.1),
                a.2 + 0.5 * h * (r0.2 + r1.2),
            )
        };
        // The body rates of ν_r are those of ν: the attitude follows either.
        let f0 = -self.g((att.0, att.1));
        let rate0 = euler_rate(att, nu);
        let nu_p = lpv.step_at(&nu_r, &(tau + &f0), scheduling, speed);
        let att_p = (
            att.0 + h * rate0.0,
            att.1 + h * rate0.1,
            att.2 + h * rate0.2,
        );
        let att_end = advance(att, rate0, euler_rate(att_p, &nu_p));
        let f1 = -self.g((att_end.0, att_end.1));
        let next_r = lpv.step_at(&nu_r, &(tau + (&f0 + &f1) * 0.5), scheduling, speed);
        let rate1 = euler_rate(att_end, &next_r);
        let att_next = advance(att, rate0, rate1);
        (next_r + self.nu_c(att_next), att_next)
    }

    /// The record's τ (first six columns) and measured attitude, or `None`
    /// when it does not fit the model.
    fn parts(&self, rec: &ValidationRecord<'_>) -> Option<(DMatrix<f64>, Vec<Euler>)> {
        let n = rec.y.nrows();
        if rec.y.ncols() != 6 || rec.u.shape() != (n, 12) || rec.h.is_nan() || rec.h <= 0.0 {
            return None;
        }
        if rec.u.iter().chain(rec.y.iter()).any(|v| !v.is_finite()) {
            return None;
        }
        let tau = rec.u.columns(0, 6).into_owned();
        let att = (0..n)
            .map(|k| (rec.u[(k, 9)], rec.u[(k, 10)], rec.u[(k, 11)]))
            .collect();
        Some((tau, att))
    }
}

/// (φ̇, θ̇, ψ̇) from ν = [u v w p q r] (Fossen 2011, eq. 2.29):
/// ψ̇ = (q sin φ + r cos φ)/cos θ.
fn euler_rate((phi, theta, _): Euler, nu: &DVector<f64>) -> Euler {
    let (dphi, dtheta) = euler_rates(phi, theta, nu[3], nu[4], nu[5]);
    let (s, c) = phi.sin_cos();
    (dphi, dtheta, (nu[4] * s + nu[5] * c) / theta.cos())
}

/// (φ̇, θ̇) at attitude (φ, θ) and body rates (p, q, r) (Fossen 2011,
/// eq. 2.29): φ̇ = p + (q sin φ + r cos φ) tan θ, θ̇ = q cos φ − r sin φ.
pub(crate) fn euler_rates(phi: f64, theta: f64, p: f64, q: f64, r: f64) -> (f64, f64) {
    let (s, c) = phi.sin_cos();
    (p + (q * s + r * c) * theta.tan(), q * c - r * s)
}

impl Predictor for AttitudeLoop {
    fn output_names(&self) -> Vec<String> {
        self.lpv.output_names()
    }

    fn predict_k_step(&self, rec: &ValidationRecord<'_>, k: usize) -> DMatrix<f64> {
        let (Some((tau, att)), Ok(lpv)) = (self.parts(rec), self.lpv.discretize(rec.h)) else {
            return no_prediction(rec, 6);
        };
        let n = rec.y.nrows();
        let mut out = no_prediction(rec, 6);
        if k == 0 {
            return out;
        }
        for t in k..n {
            let mut nu = rec.y.row(t - k).transpose();
            let mut a = att[t - k];
            for i in t - k..t {
                (nu, a) = self.step(&lpv, rec.h, &nu, a, &tau.row(i).transpose());
            }
            out.row_mut(t).copy_from(&nu.transpose());
        }
        out
    }

    fn simulate(&self, rec: &ValidationRecord<'_>) -> DMatrix<f64> {
        let (Some((tau, att)), Ok(lpv)) = (self.parts(rec), self.lpv.discretize(rec.h)) else {
            return no_prediction(rec, 6);
        };
        let n = rec.y.nrows();
        let mut out = DMatrix::zeros(n, 6);
        if n == 0 {
            return out;
        }
        let mut nu = rec.y.row(0).transpose();
        let mut a = att[0];
        out.row_mut(0).copy_from(&nu.transpose());
        for t in 1..n {
            (nu, a) = self.step(&lpv, rec.h, &nu, a, &tau.row(t - 1).transpose());
            out.row_mut(t).copy_from(&nu.transpose());
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::LinearVesselModel;
    use crate::simulation::integrate::rk4_step;

    const M: [f64; 6] = [100.0, 120.0, 140.0, 10.0, 20.0, 30.0];
    const D: [f64; 6] = [50.0, 60.0, 70.0, 3.0, 4.0, 9.0];
    const BGW: f64 = 40.0;

    fn model() -> AttitudeLoop {
        let point = LinearVesselModel::new(
            Dof::ALL.to_vec(),
            DMatrix::from_diagonal(&DVector::from_column_slice(&M)),
            DMatrix::from_diagonal(&DVector::from_column_slice(&D)),
        )
        .unwrap();
        let lpv = LpvModel::new(vec![0.0], vec![point]).unwrap();
        let g = RestoringParams {
            weight_minus_buoyancy_n: 0.0,
            zg_weight_minus_zb_buoyancy_nm: BGW,
            tether_pitch_moment_nm: 0.0,
        };
        AttitudeLoop::new(lpv, g).unwrap()
    }

    /// The unforced vehicle released at (φ, θ) = (0.1, 0.05) rad, integrated
    /// by RK4 at 1 ms on M ν̇ = −D ν − g(η) and the Euler-angle kinematics.
    fn released(n: usize, h: f64) -> (Vec<[f64; 6]>, Vec<Attitude>) {
        let mut f = |s: &[f64], _: &[f64], d: &mut [f64]| {
            let (phi, theta) = (s[6], s[7]);
            let g = [
                0.0,
                0.0,
                0.0,
                BGW * theta.cos() * phi.sin(),
                BGW * theta.sin(),
                0.0,
            ];
            for i in 0..6 {
                d[i] = (-D[i] * s[i] - g[i]) / M[i];
            }
            let (dphi, dtheta) = euler_rates(phi, theta, s[3], s[4], s[5]);
            d[6] = dphi;
            d[7] = dtheta;
        };
        let mut s = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.1, 0.05];
        let fine = 1e-3;
        let per = (h / fine).round() as usize;
        let (mut nu, mut att) = (Vec::new(), Vec::new());
        for _ in 0..n {
            nu.push([s[0], s[1], s[2], s[3], s[4], s[5]]);
            att.push((s[6], s[7]));
            for _ in 0..per {
                rk4_step(&mut f, &mut s, &[], fine);
            }
        }
        (nu, att)
    }

    fn record(nu: &[[f64; 6]], att: &[Attitude]) -> (DMatrix<f64>, DMatrix<f64>) {
        let n = nu.len();
        let y = DMatrix::from_fn(n, 6, |k, j| nu[k][j]);
        let u = DMatrix::from_fn(n, 12, |k, j| match j {
            9 => att[k].0,
            10 => att[k].1,
            _ => 0.0,
        });
        (u, y)
    }

    #[test]
    fn a_released_vehicle_swings_on_its_own_restoring_moment() {
        let h = 0.1;
        let (nu, att) = released(300, h);
        let (u, y) = record(&nu, &att);
        let sim = model().simulate(&ValidationRecord { h, u: &u, y: &y });
        // Roll: ω = √(40/10) = 2 rad/s, ζ = 3/(2·√(40·10)) = 0.075; the roll
        // rate changes sign every half period and the simulation follows it.
        let peak = nu.iter().map(|v| v[3].abs()).fold(0.0, f64::max);
        assert!(peak > 0.1, "the release swings roll ({peak} rad/s)");
        for (j, name) in [(3, "p"), (4, "q")] {
            let worst = (0..nu.len())
                .map(|k| (sim[(k, j)] - nu[k][j]).abs())
                .fold(0.0, f64::max);
            let scale = nu.iter().map(|v| v[j].abs()).fold(0.0, f64::max);
            assert!(worst < 0.03 * scale, "{name}: {worst} against {scale}");
        }
        let steps = model().predict_k_step(&ValidationRecord { h, u: &u, y: &y }, 5);
        for k in 5..nu.len() {
            for j in 3..5 {
                let scale = nu.iter().map(|v| v[j].abs()).fold(0.0, f64::max);
                assert!(
                    (steps[(k, j)] - nu[k][j]).abs() < 0.01 * scale,
                    "k-step {k}, {j}"
                );
            }
        }
        // The measured attitude enters only at the start of a prediction: a
        // record whose later attitudes are frozen simulates the same.
        let mut u_held = u.clone();
        for k in 0..nu.len() {
            u_held[(k, 9)] = att[0].0;
            u_held[(k, 10)] = att[0].1;
        }
        let open = model().simulate(&ValidationRecord {
            h,
            u: &u_held,
            y: &y,
        });
        assert!((open - &sim).abs().max() < 1e-12);
    }

    /// A vehicle turning at a steady yaw rate in a current fixed in NED,
    /// V = (0.3, 0.1) m/s, level: M ν̇ = τ − D(ν − ν_c(ψ)) + M ν̇_c with
    /// ν_c(ψ) = [V_N cψ + V_E sψ, −V_N sψ + V_E cψ, 0, 0, 0, 0] and
    /// ψ̇ = r, integrated by RK4 at 1 ms. The model's own heading turns the
    /// current's force: surge and sway follow the current round the turn.
    #[test]
    fn a_vehicle_turning_in_a_current_drifts_with_it() {
        let v = nalgebra::Vector2::new(0.3, 0.1);
        let tau_n = 0.9;
        let (h, n) = (0.1, 800);
        let nu_c = |psi: f64| {
            let (s, c) = psi.sin_cos();
            [v[0] * c + v[1] * s, -v[0] * s + v[1] * c]
        };
        let mut f = |x: &[f64], _: &[f64], d: &mut [f64]| {
            let (psi, r) = (x[6], x[5]);
            let [uc, vc] = nu_c(psi);
            for i in 0..6 {
                let rel = x[i]
                    - match i {
                        0 => uc,
                        1 => vc,
                        _ => 0.0,
                    };
                d[i] = -D[i] * rel / M[i];
            }
            d[0] += r * vc;
            d[1] -= r * uc;
            d[5] += tau_n / M[5];
            d[6] = r;
        };
        let mut x = [0.0; 7];
        let mut truth = Vec::new();
        for _ in 0..n {
            truth.push(x);
            for _ in 0..100 {
                rk4_step(&mut f, &mut x, &[], 1e-3);
            }
        }
        let base = model();
        let drifting = AttitudeLoop::with_current(base.lpv.clone(), base.restoring, v).unwrap();
        let y = DMatrix::from_fn(n, 6, |k, j| truth[k][j]);
        let u = DMatrix::from_fn(n, 12, |k, j| match j {
            5 => tau_n,
            11 => truth[k][6],
            _ => 0.0,
        });
        let rec = ValidationRecord { h, u: &u, y: &y };
        let sim = drifting.simulate(&rec);
        // The turn covers more than a revolution, and the drift follows it.
        assert!(truth[n - 1][6] > 7.0, "ψ = {}", truth[n - 1][6]);
        for k in 0..n {
            for j in [0, 1, 5] {
                assert!(
                    (sim[(k, j)] - truth[k][j]).abs() < 0.005,
                    "t = {} s, channel {j}: {} against {}",
                    k as f64 * h,
                    sim[(k, j)],
                    truth[k][j]
                );
            }
        }
        // Without the current the same vehicle only turns.
        let still = base.simulate(&rec);
        let off = (0..n).map(|k| still[(k, 0)].abs()).fold(0.0, f64::max);
        assert!(off < 1e-9, "{off}");
        let swing = (0..n).map(|k| truth[k][0]).fold(f64::MIN, f64::max)
            - (0..n).map(|k| truth[k][0]).fold(f64::MAX, f64::min);
        assert!(swing > 0.4, "the current swings surge by {swing} m/s");
    }

    #[test]
    fn records_that_do_not_fit_give_no_prediction() {
        let (nu, att) = released(20, 0.1);
        let (u, y) = record(&nu, &att);
        let short = u.columns(0, 6).into_owned();
        let sim = model().simulate(&ValidationRecord {
            h: 0.1,
            u: &short,
            y: &y,
        });
        assert!(sim.iter().all(|v| v.is_nan()));
        let mut bad = u.clone();
        bad[(3, 9)] = f64::NAN;
        let sim = model().predict_k_step(
            &ValidationRecord {
                h: 0.1,
                u: &bad,
                y: &y,
            },
            1,
        );
        assert!(sim.iter().all(|v| v.is_nan()));
        let lpv3 = LpvModel::new(
            vec![0.0],
            vec![
                LinearVesselModel::new(
                    Dof::HORIZONTAL.to_vec(),
                    DMatrix::identity(3, 3),
                    DMatrix::identity(3, 3),
                )
                .unwrap(),
            ],
        )
        .unwrap();
        assert!(
            AttitudeLoop::new(
                lpv3,
                RestoringParams {
                    weight_minus_buoyancy_n: 0.0,
                    zg_weight_minus_zb_buoyancy_nm: BGW,
                    tether_pitch_moment_nm: 0.0,
                }
            )
            .is_none()
        );
    }
}
