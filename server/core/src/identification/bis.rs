//! The Bis system of a DP ship (Fossen et al. 1995, sec. 4.1; Fossen 1994
//! p. 178) and the SI face of a Bis model: logs are SI (t in s, x, y in m,
//! ψ in rad, normalized thruster commands); the parallel EKF and the stored
//! M, T, A_h, K are non-dimensional with length L, time √(L/g) and mass m.
//!
//! x″ = x/L, y″ = y/L, ψ″ = ψ, t″ = t/√(L/g), u″ = u/√(L·g), r″ = r·√(L/g).

use nalgebra::{DMatrix, Matrix3, Vector3};

use crate::estimation::ekf::IdentifiedDpShip;
use crate::planning::vessel::DpPrior;
use crate::simulation::dp_ship::model::rotation;
use crate::simulation::integrate::rk4_step;
use crate::validation::{Predictor, ValidationRecord, restart_windows};

/// Length and time units of a ship's Bis system.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BisScale {
    /// L (m).
    pub length_m: f64,
    /// √(L/g) (s).
    pub time_unit_s: f64,
}

impl BisScale {
    /// The scale of a vessel's DP prior.
    pub fn of(prior: &DpPrior) -> Self {
        BisScale {
            length_m: prior.length_m,
            time_unit_s: prior.time_unit_s(),
        }
    }

    /// Velocity units of ν = (u, v, r): L/T, L/T, 1/T.
    fn velocity_units(&self) -> [f64; 3] {
        let v = self.length_m / self.time_unit_s;
        [v, v, 1.0 / self.time_unit_s]
    }

    /// A (1/s) of ν̇ = A·ν for ν in m/s, m/s, rad/s, from the Bis A″.
    pub fn a_si(&self, a: &Matrix3<f64>) -> Matrix3<f64> {
        let s = self.velocity_units();
        Matrix3::from_fn(|i, j| a[(i, j)] * s[i] / s[j] / self.time_unit_s)
    }

    /// B (SI per unit input, 3 × r) from the Bis B″.
    pub fn b_si(&self, b: &DMatrix<f64>) -> DMatrix<f64> {
        let s = self.velocity_units();
        DMatrix::from_fn(3, b.ncols(), |i, j| b[(i, j)] * s[i] / self.time_unit_s)
    }

    /// Measured pose (N × 3: x, y in m, ψ in rad) in Bis.
    pub fn pose_to_bis(&self, y: &DMatrix<f64>) -> DMatrix<f64> {
        let mut out = y.clone();
        for c in 0..2.min(out.ncols()) {
            out.column_mut(c).unscale_mut(self.length_m);
        }
        out
    }

    /// A Bis pose (N × 3) in m and rad.
    pub fn pose_to_si(&self, y: &DMatrix<f64>) -> DMatrix<f64> {
        let mut out = y.clone();
        for c in 0..2.min(out.ncols()) {
            out.column_mut(c).scale_mut(self.length_m);
        }
        out
    }
}

/// Unwraps a heading column in place (no jump above π between samples), so
/// a compass's wrapped (−π, π] heading becomes continuous.
pub fn unwrap_heading(psi: &mut [f64]) {
    let tau = std::f64::consts::TAU;
    let mut offset = 0.0;
    for k in 1..psi.len() {
        let raw = psi[k] + offset;
        let jump = raw - psi[k - 1];
        offset -= tau * (jump / tau).round();
        psi[k] += offset;
    }
}

/// An identified Bis DP ship that validates on SI records (h in s, x, y in
/// m, ψ in rad); predictions come back in m and rad.
#[derive(Debug, Clone, PartialEq)]
pub struct SiDpShip {
    /// The Bis model with its state-estimator noise.
    pub model: IdentifiedDpShip,
    /// The Bis scale.
    pub scale: BisScale,
}

impl SiDpShip {
    fn in_bis(
        &self,
        rec: &ValidationRecord<'_>,
        f: impl FnOnce(&ValidationRecord<'_>) -> DMatrix<f64>,
    ) -> DMatrix<f64> {
        let y = self.scale.pose_to_bis(rec.y);
        let bis = ValidationRecord {
            h: rec.h / self.scale.time_unit_s,
            u: rec.u,
            y: &y,
        };
        self.scale.pose_to_si(&f(&bis))
    }
}

impl Predictor for SiDpShip {
    fn output_names(&self) -> Vec<String> {
        self.model.output_names()
    }

    fn predict_k_step(&self, rec: &ValidationRecord<'_>, k: usize) -> DMatrix<f64> {
        self.in_bis(rec, |r| self.model.predict_k_step(r, k))
    }

    fn simulate(&self, rec: &ValidationRecord<'_>) -> DMatrix<f64> {
        self.in_bis(rec, |r| self.model.simulate(r))
    }

    /// Each window starts from the state estimator's x̂(s|s) = [ĥ, η̂, b̂_h]
    /// (momentum and bias are not measured; the same estimate the k-step
    /// prediction starts from) and runs on the recorded commands with b̂_h
    /// held.
    fn simulate_restarted(&self, rec: &ValidationRecord<'_>, every: usize) -> DMatrix<f64> {
        self.in_bis(rec, |r| restarted_free_runs(&self.model, r, every))
    }
}

/// [`Predictor::simulate_restarted`] of a Bis DP ship (Bis units).
fn restarted_free_runs(
    model: &IdentifiedDpShip,
    rec: &ValidationRecord<'_>,
    every: usize,
) -> DMatrix<f64> {
    let n = rec.y.nrows();
    let mut out = DMatrix::from_element(n, 3, f64::NAN);
    let r = model.ship.k.len();
    if rec.u.ncols() != r || rec.u.nrows() != n {
        return out;
    }
    let Some(states) = model.estimate_states(rec) else {
        return out;
    };
    let ship = &model.ship;
    let m_inv = ship.m_inv();
    let mut w = vec![0.0; r];
    for (s, e) in restart_windows(n, every) {
        let b = Vector3::new(states[(s, 6)], states[(s, 7)], states[(s, 8)]);
        let mut x: [f64; 6] = std::array::from_fn(|j| states[(s, j)]);
        let mut f = |x: &[f64], u: &[f64], dx: &mut [f64]| {
            let hm = Vector3::new(x[0], x[1], x[2]);
            let eta_dot = rotation(x[5]) * (m_inv * hm);
            dx[..3].copy_from_slice(ship.h_dot(&m_inv, &hm, u, &b).as_slice());
            dx[3..].copy_from_slice(eta_dot.as_slice());
        };
        for t in s..e {
            for j in 0..3 {
                out[(t, j)] = x[3 + j];
            }
            for (j, v) in w.iter_mut().enumerate() {
                *v = rec.u[(t, j)];
            }
            rk4_step(&mut f, &mut x, &w, rec.h);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simulation::dp_ship::{DpShip, paper};

    #[test]
    fn si_matrices_scale_by_the_bis_units() {
        let scale = BisScale {
            length_m: paper::LENGTH_M,
            time_unit_s: paper::bis_time_unit_s(),
        };
        let ship = DpShip::supply_vessel();
        let a = scale.a_si(&ship.state_space_a());
        // Surge: a pure rate, 1/T.
        assert!((a[(0, 0)] - ship.state_space_a()[(0, 0)] / scale.time_unit_s).abs() < 1e-15);
        // Sway from yaw rate: (L/T)/(1/T)/T = L/T.
        let want = ship.state_space_a()[(1, 2)] * scale.length_m / scale.time_unit_s;
        assert!((a[(1, 2)] - want).abs() < 1e-12);
        let b = scale.b_si(&ship.state_space_b());
        let v = scale.length_m / scale.time_unit_s;
        assert!((b[(0, 0)] - ship.state_space_b()[(0, 0)] * v / scale.time_unit_s).abs() < 1e-15);
        let mut psi = [3.0, -3.1, -2.9, 3.1];
        unwrap_heading(&mut psi);
        assert!((psi[1] - (-3.1 + std::f64::consts::TAU)).abs() < 1e-12);
        assert!((psi[3] - 3.1).abs() < 1e-12);
    }
}
