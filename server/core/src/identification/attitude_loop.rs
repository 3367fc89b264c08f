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

use nalgebra::{DMatrix, DVector};

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
}

/// (φ, θ) in rad.
type Attitude = (f64, f64);

impl AttitudeLoop {
    /// `None` unless the model covers the six DOFs in [`Dof::ALL`] order
    /// (φ̇ and θ̇ need p, q and r).
    pub fn new(lpv: LpvModel, restoring: RestoringParams) -> Option<Self> {
        (lpv.dofs() == Dof::ALL).then_some(AttitudeLoop { lpv, restoring })
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

    /// ν(k+1) and the attitude at k+1 from ν(k), the attitude at k and τ(k).
    fn step(
        &self,
        lpv: &DiscreteLpv,
        h: f64,
        nu: &DVector<f64>,
        att: Attitude,
        tau: &DVector<f64>,
    ) -> (DVector<f64>, Attitude) {
        let scheduling = self.lpv.scheduling();
        let g0 = self.g(att);
        let rate0 = attitude_rate(att, nu);
        let nu_p = lpv.step(nu, &(tau - &g0), scheduling);
        let att_p = (att.0 + h * rate0.0, att.1 + h * rate0.1);
        let rate_p = attitude_rate(att_p, &nu_p);
        let att_mid = (
            att.0 + 0.5 * h * (rate0.0 + rate_p.0),
            att.1 + 0.5 * h * (rate0.1 + rate_p.1),
        );
        let g1 = self.g(att_mid);
        let next = lpv.step(nu, &(tau - (&g0 + &g1) * 0.5), scheduling);
        let rate1 = attitude_rate(att_mid, &next);
        (
            next,
            (
                att.0 + 0.5 * h * (rate0.0 + rate1.0),
                att.1 + 0.5 * h * (rate0.1 + rate1.1),
            ),
        )
    }

    /// The record's τ (first six columns) and measured attitude, or `None`
    /// when it does not fit the model.
    fn parts(&self, rec: &ValidationRecord<'_>) -> Option<(DMatrix<f64>, Vec<Attitude>)> {
        let n = rec.y.nrows();
        if rec.y.ncols() != 6 || rec.u.shape() != (n, 12) || rec.h.is_nan() || rec.h <= 0.0 {
            return None;
        }
        if rec.u.iter().chain(rec.y.iter()).any(|v| !v.is_finite()) {
            return None;
        }
        let tau = rec.u.columns(0, 6).into_owned();
        let att = (0..n).map(|k| (rec.u[(k, 9)], rec.u[(k, 10)])).collect();
        Some((tau, att))
    }
}

/// (φ̇, θ̇) from ν = [u v w p q r] (Fossen 2011, eq. 2.29).
fn attitude_rate((phi, theta): Attitude, nu: &DVector<f64>) -> Attitude {
    euler_rates(phi, theta, nu[3], nu[4], nu[5])
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
        let f = |s: &[f64; 8]| -> [f64; 8] {
            let (phi, theta) = (s[6], s[7]);
            let g = [
                0.0,
                0.0,
                0.0,
                BGW * theta.cos() * phi.sin(),
                BGW * theta.sin(),
                0.0,
            ];
            let mut d = [0.0; 8];
            for i in 0..6 {
                d[i] = (-D[i] * s[i] - g[i]) / M[i];
            }
            let nu = DVector::from_column_slice(&s[..6]);
            let (dphi, dtheta) = attitude_rate((phi, theta), &nu);
            d[6] = dphi;
            d[7] = dtheta;
            d
        };
        let mut s = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.1, 0.05];
        let fine = 1e-3;
        let per = (h / fine).round() as usize;
        let (mut nu, mut att) = (Vec::new(), Vec::new());
        for _ in 0..n {
            nu.push([s[0], s[1], s[2], s[3], s[4], s[5]]);
            att.push((s[6], s[7]));
            for _ in 0..per {
                let add = |a: &[f64; 8], b: &[f64; 8], c: f64| -> [f64; 8] {
                    std::array::from_fn(|i| a[i] + c * b[i])
                };
                let k1 = f(&s);
                let k2 = f(&add(&s, &k1, fine / 2.0));
                let k3 = f(&add(&s, &k2, fine / 2.0));
                let k4 = f(&add(&s, &k3, fine));
                s = std::array::from_fn(|i| {
                    s[i] + fine / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
                });
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
