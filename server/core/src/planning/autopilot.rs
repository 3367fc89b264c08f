//! The vessel's own autopilot, as its team tuned it: SISO loops per DOF
//! (thesis §1.4: PID loops per degree of freedom, automatic roll and pitch)
//! and an optional restoring feed-forward ĝ(η) (thesis eq. 4.6).
//!
//! Declared in a vessel profile, it replaces the generic loops the
//! project's simulator otherwise designs from the profile's limits, so a
//! predicted precision flies the plan through the loop that will fly it at
//! sea: how stiffly a loop holds a DOF decides how much sensor noise it
//! turns into thrust and motion, and with it the spread of the estimates.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::dof::Dof;
use super::error::PlanError;

/// The gains of one DOF's loop, on the measured state at the controller
/// rate: τᵢ = K_p eᵢ + K_i ∫eᵢ dt (+ K_d on the rate error for an attitude
/// loop), clipped at the DOF's `max_force`, with conditional integration.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct AutopilotLoop {
    /// Proportional gain, ≥ 0: on the velocity error e = ν_ref − ν (N per
    /// m/s, N·m per rad/s), or for a roll/pitch attitude loop on the attitude
    /// error η_ref − η (N·m per rad).
    pub kp: f64,
    /// Integral gain, ≥ 0 (N per m, N·m per rad; attitude loops N·m per
    /// rad·s); default 0.
    #[serde(default)]
    pub ki: f64,
    /// Roll and pitch only: the rate gain K_d (N·m per rad/s), ≥ 0. Given,
    /// the loop holds attitude: τ = K_p (η_ref − η) + K_d (ω_ref − ω) +
    /// K_i ∫(η_ref − η) dt, where a rate schedule sets ω_ref and η_ref = ∫ω_ref
    /// dt from the run's start, and an attitude schedule sets η_ref with
    /// ω_ref = 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kd: Option<f64>,
}

impl AutopilotLoop {
    /// Whether the loop holds attitude (roll or pitch with a rate gain).
    pub fn holds_attitude(&self) -> bool {
        self.kd.is_some()
    }
}

/// The lumped restoring terms of the team's nominal ĝ(η) (thesis eq. 4.6),
/// fed forward as τ += ĝ(η_measured).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct RestoringFeedForward {
    /// W − B (N): weight minus buoyancy, positive when the vehicle sinks.
    pub w_minus_b: f64,
    /// z_G W − z_B B (N·m): the righting moment per unit sin of the tilt,
    /// positive for a stable vehicle (G below B, z down).
    pub zg_w_minus_zb_b: f64,
}

impl RestoringFeedForward {
    /// ĝ(η) at roll `phi`, pitch `theta` (surge … yaw): the lumped g(η) the
    /// identification estimates, without a tether moment.
    pub fn force(&self, phi: f64, theta: f64) -> [f64; 6] {
        crate::estimation::restoring::RestoringParams {
            weight_minus_buoyancy_n: self.w_minus_b,
            zg_weight_minus_zb_buoyancy_nm: self.zg_w_minus_zb_b,
            tether_pitch_moment_nm: 0.0,
        }
        .g(&[0.0, 0.0, 0.0, phi, theta, 0.0])
    }
}

/// A vessel's autopilot: the loop of every DOF it flies, and its
/// restoring feed-forward.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct Autopilot {
    /// One loop per modeled DOF, keyed by DOF name (surge … yaw).
    #[serde(deserialize_with = "super::dof::deserialize_dof_map")]
    pub loops: BTreeMap<Dof, AutopilotLoop>,
    /// The nominal ĝ(η) the autopilot feeds forward, if it does.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub restoring_feed_forward: Option<RestoringFeedForward>,
}

/// Largest gain accepted (any unit): beyond it a typo, not a tuning.
const MAX_GAIN: f64 = 1e12;

impl Autopilot {
    /// Checks the autopilot against the profile's modeled DOFs; errors
    /// name the field (`autopilot.loops.roll.kd`).
    pub fn validate(&self, dofs: &[Dof]) -> Result<(), PlanError> {
        for d in dofs {
            if !self.loops.contains_key(d) {
                return Err(PlanError::invalid(
                    format!("autopilot.loops.{}", d.name()),
                    format!(
                        "the profile models {} but the autopilot has no loop for it",
                        d.name()
                    ),
                ));
            }
        }
        for (d, l) in &self.loops {
            let field = |g: &str| format!("autopilot.loops.{}.{g}", d.name());
            if !dofs.contains(d) {
                return Err(PlanError::invalid(
                    format!("autopilot.loops.{}", d.name()),
                    format!("{} is not a modeled DOF of the profile", d.name()),
                ));
            }
            for (g, v) in [("kp", Some(l.kp)), ("ki", Some(l.ki)), ("kd", l.kd)] {
                if let Some(v) = v
                    && !(v.is_finite() && (0.0..=MAX_GAIN).contains(&v))
                {
                    return Err(PlanError::invalid(
                        field(g),
                        format!("must be a gain between 0 and {MAX_GAIN:e} (got {v:.6e})"),
                    ));
                }
            }
            if l.kd.is_some() && !matches!(d, Dof::Roll | Dof::Pitch) {
                return Err(PlanError::invalid(
                    field("kd"),
                    "only roll and pitch have attitude loops (a rate gain); the other DOFs fly velocity references",
                ));
            }
            if l.kp == 0.0 && l.ki == 0.0 && l.kd.is_none_or(|k| k == 0.0) {
                return Err(PlanError::invalid(
                    format!("autopilot.loops.{}", d.name()),
                    "every gain is zero: the loop would not fly its references",
                ));
            }
        }
        if let Some(g) = &self.restoring_feed_forward {
            for (f, v) in [
                ("w_minus_b", g.w_minus_b),
                ("zg_w_minus_zb_b", g.zg_w_minus_zb_b),
            ] {
                if !(v.is_finite() && v.abs() <= MAX_GAIN) {
                    return Err(PlanError::invalid(
                        format!("autopilot.restoring_feed_forward.{f}"),
                        format!("must be a finite force below {MAX_GAIN:e} (got {v:.6e})"),
                    ));
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn roll_pitch_yaw() -> Autopilot {
        let mut loops = BTreeMap::new();
        loops.insert(
            Dof::Roll,
            AutopilotLoop {
                kp: 400.0,
                ki: 0.0,
                kd: Some(300.0),
            },
        );
        loops.insert(
            Dof::Yaw,
            AutopilotLoop {
                kp: 200.0,
                ki: 50.0,
                kd: None,
            },
        );
        Autopilot {
            loops,
            restoring_feed_forward: Some(RestoringFeedForward {
                w_minus_b: 10.0,
                zg_w_minus_zb_b: 300.0,
            }),
        }
    }

    #[test]
    fn validation_names_the_field() {
        let a = roll_pitch_yaw();
        assert!(a.validate(&[Dof::Roll, Dof::Yaw]).is_ok());
        assert_eq!(
            a.validate(&[Dof::Roll, Dof::Yaw, Dof::Surge])
                .unwrap_err()
                .field,
            "autopilot.loops.surge"
        );
        assert_eq!(
            a.validate(&[Dof::Roll]).unwrap_err().field,
            "autopilot.loops.yaw"
        );
        let mut b = a.clone();
        b.loops.get_mut(&Dof::Yaw).unwrap().kd = Some(1.0);
        assert_eq!(
            b.validate(&[Dof::Roll, Dof::Yaw]).unwrap_err().field,
            "autopilot.loops.yaw.kd"
        );
        let mut c = a.clone();
        c.loops.get_mut(&Dof::Roll).unwrap().kp = f64::NAN;
        assert_eq!(
            c.validate(&[Dof::Roll, Dof::Yaw]).unwrap_err().field,
            "autopilot.loops.roll.kp"
        );
        let mut z = a.clone();
        z.loops.insert(
            Dof::Roll,
            AutopilotLoop {
                kp: 0.0,
                ki: 0.0,
                kd: None,
            },
        );
        assert_eq!(
            z.validate(&[Dof::Roll, Dof::Yaw]).unwrap_err().field,
            "autopilot.loops.roll"
        );
    }

    #[test]
    fn feed_forward_is_the_restoring_force_of_w_b_and_centres() {
        // The vessel's g(η) from W, B, r_G = (0, 0, z_G), r_B = (0, 0, z_B)
        // (Fossen 2011 eq. 4.6) equals the lumped form with W − B and
        // z_G W − z_B B.
        let r = crate::simulation::rov::Restoring {
            weight: 25_000.0,
            buoyancy: 24_800.0,
            r_g: [0.0, 0.0, 0.12],
            r_b: [0.0, 0.0, -0.05],
        };
        let ff = RestoringFeedForward {
            w_minus_b: 200.0,
            zg_w_minus_zb_b: 0.12 * 25_000.0 + 0.05 * 24_800.0,
        };
        for (phi, theta) in [(0.1, -0.2), (-0.6, 0.3), (0.0, 0.0)] {
            let want = r.g(phi, theta);
            let got = ff.force(phi, theta);
            for i in 0..6 {
                assert!(
                    (got[i] - want[i]).abs() < 1e-9,
                    "{i}: {} vs {}",
                    got[i],
                    want[i]
                );
            }
        }
        let json = serde_json::to_string(&roll_pitch_yaw()).unwrap();
        let back: Autopilot = serde_json::from_str(&json).unwrap();
        assert_eq!(back, roll_pitch_yaw());
        let bad = r#"{"loops": {"rol": {"kp": 1}}}"#;
        let e = serde_json::from_str::<Autopilot>(bad)
            .unwrap_err()
            .to_string();
        assert!(e.contains("unknown DOF 'rol'"), "{e}");
    }
}
