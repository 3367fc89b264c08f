//! What stands between the commanded τ the logger records and the τ that
//! acts on the hull: a pure delay (whole record samples), a dead zone, a
//! saturation and a first-order lag T τ̇_a + τ_a = τ per DOF, in that order
//! (command → transport delay → thruster dead band → force limit → thrust
//! build-up). All off by default: τ_applied = τ_commanded.

use nalgebra::DMatrix;

use super::error::{SimError, non_negative};
use crate::planning::dof::Dof;

/// Actuator effects per DOF (index = `Dof::index()`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Actuators {
    /// First-order lag time constant T (s); 0 = no lag.
    pub time_constants: [f64; 6],
    /// Pure input delay in record samples: τ(t_k) = τ_commanded(t_{k−d});
    /// commands before the record are zero.
    pub delay_samples: usize,
    /// |τ| ≤ limit (N or N·m); +∞ = no limit.
    pub saturation: [f64; 6],
    /// |τ| < width gives τ = 0, larger commands pass unchanged (N or N·m);
    /// 0 = no dead zone.
    pub dead_zone: [f64; 6],
}

impl Default for Actuators {
    fn default() -> Self {
        Actuators {
            time_constants: [0.0; 6],
            delay_samples: 0,
            saturation: [f64::INFINITY; 6],
            dead_zone: [0.0; 6],
        }
    }
}

impl Actuators {
    /// Checks T ≥ 0, limits > 0 (or +∞), dead zones ≥ 0.
    pub fn validate(&self) -> Result<(), SimError> {
        for d in Dof::ALL {
            let i = d.index();
            non_negative(
                format!("actuators.time_constants[{}]", d.name()),
                self.time_constants[i],
                false,
            )?;
            non_negative(
                format!("actuators.dead_zone[{}]", d.name()),
                self.dead_zone[i],
                false,
            )?;
            let s = self.saturation[i];
            if s.is_nan() || s <= 0.0 {
                return Err(SimError::InvalidParameter {
                    name: format!("actuators.saturation[{}]", d.name()),
                    value: s,
                    requirement: "> 0 (or +∞ for no limit)",
                });
            }
        }
        Ok(())
    }

    /// The static part (delay, dead zone, saturation) at record sample `k`
    /// for the commands `tau` (N × 6).
    pub(crate) fn shaped(&self, tau: &DMatrix<f64>, k: usize) -> [f64; 6] {
        let mut out = [0.0; 6];
        if k < self.delay_samples {
            return out;
        }
        let row = k - self.delay_samples;
        for (i, o) in out.iter_mut().enumerate() {
            let t = tau[(row, i)];
            let t = if t.abs() < self.dead_zone[i] { 0.0 } else { t };
            *o = t.clamp(-self.saturation[i], self.saturation[i]);
        }
        out
    }

    /// DOF `i` has a lag.
    pub(crate) fn lagged(&self, i: usize) -> bool {
        self.time_constants[i] > 0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn delay_dead_zone_and_saturation_in_order() {
        let a = Actuators {
            delay_samples: 2,
            saturation: [100.0, f64::INFINITY, 5.0, 5.0, 5.0, 5.0],
            dead_zone: [10.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            ..Actuators::default()
        };
        a.validate().unwrap();
        let tau = DMatrix::from_row_slice(
            4,
            6,
            &[
                5.0, 1.0, 0.0, 0.0, 0.0, 0.0, -9.9, -1e6, 0.0, 0.0, 0.0, 0.0, 150.0, 3.0, -7.0,
                0.0, 0.0, 0.0, -10.0, 4.0, 0.0, 0.0, 0.0, 0.0,
            ],
        );
        assert_eq!(a.shaped(&tau, 0), [0.0; 6]);
        assert_eq!(a.shaped(&tau, 1), [0.0; 6]);
        // Row 0: 5 < dead zone 10 → 0.
        assert_eq!(a.shaped(&tau, 2)[..2], [0.0, 1.0]);
        // Row 1: −9.9 inside the dead zone; sway unlimited.
        assert_eq!(a.shaped(&tau, 3)[..2], [0.0, -1e6]);
        let row2 = Actuators {
            delay_samples: 0,
            ..a
        }
        .shaped(&tau, 2);
        assert_eq!(row2[..3], [100.0, 3.0, -5.0]);
        // Exactly at the dead-zone width passes.
        assert_eq!(
            Actuators {
                delay_samples: 0,
                ..a
            }
            .shaped(&tau, 3)[0],
            -10.0
        );
    }

    #[test]
    fn bad_parameters_name_the_dof() {
        let mut a = Actuators::default();
        a.saturation[4] = 0.0;
        assert_eq!(
            a.validate().unwrap_err().to_string(),
            "actuators.saturation[pitch] = 0 must be > 0 (or +∞ for no limit)"
        );
        let mut a = Actuators::default();
        a.time_constants[0] = f64::NAN;
        assert!(
            a.validate()
                .unwrap_err()
                .to_string()
                .starts_with("actuators.time_constants[surge] = NaN")
        );
    }
}
