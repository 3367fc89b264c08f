//! Hydrodynamic damping D(ν_r)ν_r = D_l(u_r) ν_r + D_q(ν_r) ν_r acting on
//! the velocity relative to the water ν_r = ν − ν_c.
//!
//! D_l may be coupled and may change with the forward speed through the
//! water u_r (lift and cross-flow terms grow with speed — the reason the
//! thesis schedules its LPV model on forward speed): it is a table of 6×6
//! matrices over a speed grid, linearly interpolated in u_r and held
//! constant outside the grid. D_q(ν_r) = diag(d_q,i |ν_r,i|) is the diagonal
//! quadratic (cross-flow drag) term.

use nalgebra::{Matrix6, Vector6};

use super::error::{SimError, finite, non_negative};
use crate::planning::dof::Dof;

/// D_l over a forward-speed grid (m/s).
#[derive(Debug, Clone, PartialEq)]
pub struct LinearDamping {
    /// Forward speeds u_r (m/s), strictly increasing.
    pub speeds: Vec<f64>,
    /// D_l at each speed (kg/s, kg·m²/s, …).
    pub tables: Vec<Matrix6<f64>>,
}

impl LinearDamping {
    /// The same D_l at every speed.
    pub fn constant(d: Matrix6<f64>) -> Self {
        LinearDamping {
            speeds: vec![0.0],
            tables: vec![d],
        }
    }

    /// D_l(u) = D₀ + u D₁ tabulated at `speeds` (exact under the linear
    /// interpolation inside the grid).
    pub fn affine(d0: Matrix6<f64>, d1: Matrix6<f64>, speeds: Vec<f64>) -> Self {
        let tables = speeds.iter().map(|&u| d0 + d1 * u).collect();
        LinearDamping { speeds, tables }
    }

    /// Checks the grid: non-empty, one table per speed, strictly increasing
    /// finite speeds, finite tables.
    pub fn validate(&self) -> Result<(), SimError> {
        if self.speeds.is_empty() || self.speeds.len() != self.tables.len() {
            return Err(SimError::DampingTable {
                reason: format!(
                    "{} speeds and {} tables; need one table per speed and at least one",
                    self.speeds.len(),
                    self.tables.len()
                ),
            });
        }
        finite("damping.speeds", self.speeds.iter())?;
        for (i, w) in self.speeds.windows(2).enumerate() {
            if w[1] <= w[0] {
                return Err(SimError::DampingTable {
                    reason: format!(
                        "speeds must be strictly increasing, but speeds[{}] = {} follows {}",
                        i + 1,
                        w[1],
                        w[0]
                    ),
                });
            }
        }
        for (i, t) in self.tables.iter().enumerate() {
            finite(&format!("damping.tables[{i}]"), t.iter())?;
        }
        Ok(())
    }

    /// D_l at forward speed `u` (m/s): linear between grid speeds, the end
    /// table outside the grid.
    pub fn at(&self, u: f64) -> Matrix6<f64> {
        let n = self.speeds.len();
        if n == 1 || u <= self.speeds[0] || u.is_nan() {
            return self.tables[0];
        }
        if u >= self.speeds[n - 1] {
            return self.tables[n - 1];
        }
        let i = self.speeds.partition_point(|s| *s <= u) - 1;
        let w = (u - self.speeds[i]) / (self.speeds[i + 1] - self.speeds[i]);
        self.tables[i] * (1.0 - w) + self.tables[i + 1] * w
    }
}

/// Checks quadratic-damping coefficients d_q,i ≥ 0.
pub(crate) fn validate_quadratic(dq: &[f64; 6]) -> Result<(), SimError> {
    for d in Dof::ALL {
        non_negative(
            format!("quadratic_damping[{}]", d.name()),
            dq[d.index()],
            false,
        )?;
    }
    Ok(())
}

/// D(ν_r)ν_r = D_l(u_r)ν_r + diag(d_q |ν_r|)ν_r.
pub(crate) fn damping_force(
    linear: &LinearDamping,
    quadratic: &[f64; 6],
    nu_r: &Vector6<f64>,
) -> Vector6<f64> {
    let mut f = linear.at(nu_r[0]) * nu_r;
    for i in 0..6 {
        f[i] += quadratic[i] * nu_r[i].abs() * nu_r[i];
    }
    f
}

/// Checks cubic d_c,i ≥ 0 and cross-flow d_ij ≥ 0 (dissipative) with a
/// zero diagonal.
pub(crate) fn validate_nonlinear(cubic: &[f64; 6], cross: &[[f64; 6]; 6]) -> Result<(), SimError> {
    for d in Dof::ALL {
        non_negative(
            format!("cubic_damping[{}]", d.name()),
            cubic[d.index()],
            false,
        )?;
        for e in Dof::ALL {
            let v = cross[d.index()][e.index()];
            let name = format!("cross_damping[{}][{}]", d.name(), e.name());
            if d == e && v != 0.0 {
                return Err(SimError::DampingTable {
                    reason: format!(
                        "{name} = {v}; the diagonal is quadratic_damping and must be 0 here"
                    ),
                });
            }
            non_negative(name, v, false)?;
        }
    }
    Ok(())
}

/// D_c(ν_r)ν_r: d_c,i ν_r,i³ + Σ_j d_ij |ν_r,j| ν_r,i per DOF i.
pub(crate) fn nonlinear_damping_force(
    cubic: &[f64; 6],
    cross: &[[f64; 6]; 6],
    nu_r: &Vector6<f64>,
) -> Vector6<f64> {
    Vector6::from_fn(|i, _| {
        let x = nu_r[i];
        let c: f64 = (0..6).map(|j| cross[i][j] * nu_r[j].abs()).sum();
        cubic[i] * x * x * x + c * x
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cubic_and_cross_terms_are_odd_in_their_own_velocity_and_even_in_the_other() {
        let mut cross = [[0.0; 6]; 6];
        cross[1][5] = 50.0;
        let cubic = [4.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        for (sv, sr) in [(1.0, 1.0), (-1.0, 1.0), (1.0, -1.0), (-1.0, -1.0)] {
            let nu = Vector6::new(-2.0, sv * 0.5, 0.0, 0.0, 0.0, sr * 0.2);
            let f = nonlinear_damping_force(&cubic, &cross, &nu);
            assert_eq!(f[0], -32.0);
            assert!((f[1] - sv * 50.0 * 0.2 * 0.5).abs() < 1e-12);
            assert_eq!(f[5], 0.0);
        }
        let mut bad = [[0.0; 6]; 6];
        bad[2][2] = 1.0;
        assert!(validate_nonlinear(&cubic, &bad).is_err());
        bad[2][2] = 0.0;
        bad[0][1] = -1.0;
        assert!(validate_nonlinear(&cubic, &bad).is_err());
    }

    #[test]
    fn table_interpolates_linearly_and_holds_outside() {
        let d0 = Matrix6::from_diagonal_element(100.0);
        let mut d1 = Matrix6::zeros();
        d1[(1, 5)] = 40.0;
        d1[(0, 0)] = 10.0;
        let dl = LinearDamping::affine(d0, d1, vec![0.0, 1.0, 2.0]);
        dl.validate().unwrap();
        // Inside the grid the affine law is reproduced exactly.
        for u in [0.0, 0.25, 1.0, 1.7, 2.0] {
            assert!((dl.at(u) - (d0 + d1 * u)).amax() < 1e-12, "u = {u}");
        }
        // Outside: held at the ends.
        assert_eq!(dl.at(-1.0), d0);
        assert_eq!(dl.at(5.0), d0 + d1 * 2.0);
        let bad = LinearDamping {
            speeds: vec![1.0, 0.5],
            tables: vec![d0, d0],
        };
        assert_eq!(
            bad.validate().unwrap_err().to_string(),
            "damping: speeds must be strictly increasing, but speeds[1] = 0.5 follows 1"
        );
    }

    #[test]
    fn quadratic_term_is_signed_square() {
        let dl = LinearDamping::constant(Matrix6::zeros());
        let dq = [10.0, 0.0, 0.0, 0.0, 0.0, 2.0];
        let f = damping_force(&dl, &dq, &Vector6::new(-2.0, 1.0, 0.0, 0.0, 0.0, 3.0));
        assert_eq!(f, Vector6::new(-40.0, 0.0, 0.0, 0.0, 0.0, 18.0));
        assert!(
            validate_quadratic(&[0.0, -1.0, 0.0, 0.0, 0.0, 0.0])
                .unwrap_err()
                .to_string()
                .starts_with("quadratic_damping[sway] = -1")
        );
    }
}
