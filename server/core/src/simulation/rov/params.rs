//! Physical parameters of the ROV truth: what the simulated vehicle really
//! is, as opposed to what an estimator will believe.

use nalgebra::{Matrix6, Vector6};

use super::actuators::Actuators;
use super::current::Current;
use super::damping::{LinearDamping, validate_nonlinear, validate_quadratic};
use super::error::{SimError, finite};
use super::restoring::Restoring;
use crate::planning::dof::KNOT;

/// A constant load from the tether, added to τ on the right-hand side
/// (M ν̇ + … = τ + τ_t). The thesis models it as a pitch moment τ_θ inside
/// g(η) (eq. 1.6), i.e. τ_θ = −τ_t,pitch; its estimate was −1.57·10⁴ N·m
/// (Table 4.1).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Tether {
    /// Constant pitch moment (N·m).
    pub pitch_moment: f64,
    /// Constant force [X Y Z] in the body frame (N).
    pub body_force: [f64; 3],
}

impl Tether {
    /// τ_t as a generalized force.
    pub(crate) fn load(&self) -> Vector6<f64> {
        let [x, y, z] = self.body_force;
        Vector6::new(x, y, z, 0.0, self.pitch_moment, 0.0)
    }
}

/// The 6-DOF ROV
///
/// M ν̇_r + C(ν_r)ν_r + D_l(u_r)ν_r + D_q(ν_r)ν_r + D_c(ν_r)ν_r + g(η) = τ_a + τ_t,
/// η̇ = J(η)ν, ν = ν_r + ν_c,
///
/// the relative-velocity form for an irrotational current (Fossen 2011,
/// sec. 10.3). D_c(ν_r)ν_r holds the optional cubic and cross-flow
/// damping (off by default). τ_a is the applied τ after [`Actuators`], τ_t the [`Tether`].
/// Every optional effect is off by default, leaving the base case
/// M ν̇ + D_l ν + g(η) = τ.
#[derive(Debug, Clone, PartialEq)]
pub struct RovTruth {
    /// M = M_RB + M_A (kg, kg·m), symmetric positive definite; may be
    /// coupled.
    pub m: Matrix6<f64>,
    /// Linear damping D_l, possibly coupled and scheduled on u_r.
    pub damping: LinearDamping,
    /// Diagonal quadratic damping d_q,i (kg/m, kg·m²): D_q = diag(d_q,i |ν_r,i|).
    pub quadratic_damping: [f64; 6],
    /// Diagonal cubic damping d_c,i (kg·s/m², kg·m²·s): d_c,i ν_r,i³ in DOF i.
    pub cubic_damping: [f64; 6],
    /// Cross-flow damping: entry [i][j] (j ≠ i) adds d_ij |ν_r,j| ν_r,i to
    /// DOF i (e.g. sway damping growing with |r|); the diagonal must be 0
    /// (it would be [`Self::quadratic_damping`]).
    pub cross_damping: [[f64; 6]; 6],
    /// Include C(ν_r)ν_r with C from M (Fossen 2011, eq. 6.43).
    pub coriolis: bool,
    /// W, B, r_G, r_B for g(η).
    pub restoring: Restoring,
    /// Tether load.
    pub tether: Tether,
    /// Ocean current.
    pub current: Current,
    /// Actuator lag, delay, saturation and dead zone.
    pub actuators: Actuators,
}

impl RovTruth {
    /// The base case M ν̇ + D_l ν = τ with everything else off.
    pub fn new(m: Matrix6<f64>, damping: LinearDamping) -> Self {
        RovTruth {
            m,
            damping,
            quadratic_damping: [0.0; 6],
            cubic_damping: [0.0; 6],
            cross_damping: [[0.0; 6]; 6],
            coriolis: false,
            restoring: Restoring::default(),
            tether: Tether::default(),
            current: Current::None,
            actuators: Actuators::default(),
        }
    }

    /// A Surveyor-like work-class ROV: about 5 t, 5 × 2 × 1.4 m (thesis
    /// sec. 1.1), origin at the centre of gravity, centre of buoyancy 0.2 m
    /// above it, 250 N positively buoyant.
    ///
    /// M: rigid body (m = 5000 kg; I_xx, I_yy, I_zz of a 5 × 2 × 1.4 m body
    /// with its mass towards the centre) plus added mass of a streamlined
    /// hull (small in surge, large in heave), with sway–yaw, heave–pitch
    /// and surge–pitch couplings. D_l = D₀ + u_r D₁ on 0–2 m/s (≈ 0–4 kn,
    /// the thesis grid): surge time constant M₁₁/D₁₁ ≈ 3.9 s (cf. the 4 s of
    /// `planning::examples::surveyor_rov`), with sway, heave, pitch and yaw
    /// damping and the asymmetric lift-like couplings growing with speed.
    /// The effects stay off; [`Self::SURVEYOR_QUADRATIC_DAMPING`] holds
    /// matching quadratic coefficients.
    ///
    /// The thesis's own estimates are no guide to magnitudes: its M ranges
    /// 10⁴–10⁹ and its W − B = 3.55·10⁴ N (Table 4.1) would be 70 % of the
    /// weight; the values here are engineering numbers for a vehicle of that
    /// size.
    pub fn surveyor_like() -> Self {
        let mut m = Matrix6::from_diagonal(&Vector6::new(
            5000.0 + 800.0,   // m − X_u̇
            5000.0 + 4000.0,  // m − Y_v̇
            5000.0 + 6000.0,  // m − Z_ẇ
            2000.0 + 800.0,   // I_xx − K_ṗ
            9000.0 + 6000.0,  // I_yy − M_q̇
            10000.0 + 5000.0, // I_zz − N_ṙ
        ));
        for (i, j, v) in [(1, 5, 400.0), (2, 4, -600.0), (0, 4, 200.0), (1, 3, -300.0)] {
            m[(i, j)] = v;
            m[(j, i)] = v;
        }
        let d0 = Matrix6::from_diagonal(&Vector6::new(
            1500.0, 3000.0, 4000.0, 2000.0, 6000.0, 5000.0,
        ));
        let mut d1 = Matrix6::from_diagonal(&Vector6::new(0.0, 800.0, 1000.0, 0.0, 2500.0, 2000.0));
        for (i, j, v) in [(1, 5, 600.0), (5, 1, -300.0), (2, 4, -900.0), (4, 2, 700.0)] {
            d1[(i, j)] = v;
        }
        let speeds = [0.0, 0.5, 1.0, 1.5, 2.0].to_vec();
        let weight = 5000.0 * 9.81;
        let mut truth = RovTruth::new(m, LinearDamping::affine(d0, d1, speeds));
        truth.restoring = Restoring {
            weight,
            buoyancy: weight + 250.0,
            r_g: [0.0; 3],
            r_b: [0.0, 0.0, -0.2],
        };
        truth
    }

    /// Quadratic damping matching [`Self::surveyor_like`]: surge drag
    /// 1500·u + 1400·u² reaches the 10 kN force limit of
    /// `planning::examples::surveyor_rov` at ≈ 2.2 m/s = 4.3 kn.
    pub const SURVEYOR_QUADRATIC_DAMPING: [f64; 6] =
        [1400.0, 3000.0, 3500.0, 800.0, 4000.0, 3500.0];

    /// Top speed (m/s) the Surveyor grid covers, 4.3 kn.
    pub const SURVEYOR_TOP_SPEED: f64 = 4.3 * KNOT;

    /// Checks every parameter; errors name the field.
    pub fn validate(&self) -> Result<(), SimError> {
        finite("M", self.m.iter())?;
        let asym = (self.m - self.m.transpose()).norm() / self.m.norm().max(f64::MIN_POSITIVE);
        if asym > 1e-9 {
            return Err(SimError::InertiaNotSpd {
                reason: format!("‖M − Mᵀ‖/‖M‖ = {asym:.3e}"),
            });
        }
        if self.m.cholesky().is_none() {
            return Err(SimError::InertiaNotSpd {
                reason: format!(
                    "the smallest eigenvalue is {:.4e}",
                    self.m.symmetric_eigenvalues().min()
                ),
            });
        }
        self.damping.validate()?;
        validate_quadratic(&self.quadratic_damping)?;
        validate_nonlinear(&self.cubic_damping, &self.cross_damping)?;
        let r = &self.restoring;
        finite(
            "restoring",
            [r.weight, r.buoyancy]
                .iter()
                .chain(r.r_g.iter())
                .chain(r.r_b.iter()),
        )?;
        finite(
            "tether",
            std::iter::once(&self.tether.pitch_moment).chain(self.tether.body_force.iter()),
        )?;
        self.current.validate()?;
        self.actuators.validate()
    }
}
