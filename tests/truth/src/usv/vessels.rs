//! The two vessels, built from their published data by the published
//! formulas (nothing copied but numbers), and seeded ±20 % draws.
//!
//! **Otter USV** (Maritime Robotics; Fossen's PythonVehicleSimulator
//! `vehicles/otter.py` and MSS `CRAFT/USV/models/otter.m`): a 2.0 m
//! catamaran of 55 kg with a 25 kg payload, two fixed stern propellers at
//! y = ∓0.395 m. It has no lateral actuator: τ_Y = 0 always, and sway is
//! excited only through yaw, by C_RB's m u r, C_A's −X_u̇ u_r r and the
//! sway–yaw inertia coupling m x_g.
//!
//! **Supply vessel** (Fossen, Sagatun & Sørensen 1996, the hull of
//! [`crate::dp_ship`]): M″ and A″_h in Bis units converted to SI with
//! L = 76.2 m and m = 6.0e6 kg as MSS `CRAFT/SHIP/models/supply.m` does,
//! D″ = −A″_h M″ (which reproduces supply.m's D″).

use super::cross_flow::{CrossFlow, hoerner_cd};
use super::model::SurfaceVessel;
use crate::dp_ship;
use crate::rng::Rng;

/// Water density ρ (kg/m³), as MSS.
pub const RHO: f64 = 1025.0;
/// Gravity g (m/s²).
pub const G: f64 = 9.81;

/// Otter length L (m).
pub const OTTER_LENGTH_M: f64 = 2.0;
/// Otter hull mass (kg).
pub const OTTER_HULL_KG: f64 = 55.0;
/// Otter payload mass m_p (kg), otter.py's default.
pub const OTTER_PAYLOAD_KG: f64 = 25.0;
/// Thrust of one Otter propeller at command 1 (N): otter.py's positive
/// bollard pull k_pos·n_max² = ½·24.4 kgf = ½·24.4·g.
pub const OTTER_THRUST_N: f64 = 0.5 * 24.4 * G;
/// Lateral position of the propellers, ∓y_pont (m): port (thr_1) at
/// y = −0.395, starboard (thr_2) at y = +0.395.
pub const OTTER_PROPELLER_Y_M: f64 = 0.395;
/// Otter configuration matrix T (3 × 2), τ = T · [`OTTER_THRUST_N`] ·
/// [thr_1, thr_2]ᵀ: a propeller at (x, y) pushing ahead gives
/// (1, 0, −y). Row 2 (sway) is zero: the Otter cannot push sideways.
pub const OTTER_T: [[f64; 2]; 3] = [
    [1.0, 1.0],
    [0.0, 0.0],
    [OTTER_PROPELLER_Y_M, -OTTER_PROPELLER_Y_M],
];
/// Otter top speed U_max = 6 kn (m/s), otter.py.
pub const OTTER_U_MAX_MPS: f64 = 6.0 * 0.5144;

/// Supply vessel displacement mass (kg), MSS supply.m.
pub const SUPPLY_MASS_KG: f64 = 6.0e6;
/// Supply vessel beam (m) for cross-flow drag: MSS's ShipX look-alike
/// supply vessel (`HYDRO/vessels_shipx/supply`, B = 19.2 m, T = 6.0 m);
/// with L = 76.2 m and m = 6.0e6 kg its block coefficient is 0.67.
pub const SUPPLY_BEAM_M: f64 = 19.2;
/// Supply vessel draft (m), as [`SUPPLY_BEAM_M`].
pub const SUPPLY_DRAFT_M: f64 = 6.0;
/// Supply vessel top speed (m/s) used to calibrate X_|u|u: MSS `osv.m`'s
/// U_max for its 83 m offshore supply vessel.
pub const SUPPLY_U_MAX_MPS: f64 = 7.7;

/// The Otter with its 25 kg payload at r_p = (0.05, 0, −0.35) m:
///
/// - m = 80 kg; x_g = (55·0.2 + 25·0.05)/80 = 0.153 m;
/// - I_z = I_g + m x_g² = 16.01 kg·m², where I_g about the joint CG is the
///   hull's 55·(0.25 L)² plus both parallel-axis terms (MSS otter.m,
///   2026-04-20 revision; otter.py's older formula gives 16.98);
/// - X_u̇ = −0.1·55, Y_v̇ = −1.5·55, N_ṙ = −1.7 I_g ("best practice", otter.py);
/// - X_u = −24.4 g/U_max (full thrust at top speed), Y_v = −M₂₂/T_sway,
///   N_r = −M₃₃/T_yaw with T_sway = T_yaw = 1 s (otter.py);
/// - X_|u|u = −24.4 g/U_max² (MSS `forceSurgeDamping.m`'s calibration
///   −X_|u|u U_max² = thrust_max; with both X_u and X_|u|u the top speed is
///   1.9 m/s instead of 3.1);
/// - cross-flow as otter.py calls it: one pontoon beam 0.25 m, draft
///   T = ∇/(2·0.4·0.25·L) = 0.195 m, C_d^2D = Hoerner(0.25/2T) = 1.005
///   (the lee pontoon is not counted, as in otter.py).
///
/// Straight-line stable with C_A on below 1.16 m/s (the Munk moment).
pub fn otter() -> SurfaceVessel {
    let (mh, mp, l) = (OTTER_HULL_KG, OTTER_PAYLOAD_KG, OTTER_LENGTH_M);
    let m = mh + mp;
    let (xg_hull, xg_payload) = (0.2, 0.05);
    let x_g = (mh * xg_hull + mp * xg_payload) / m;
    let i_g =
        mh * (0.25 * l).powi(2) + mh * (xg_hull - x_g).powi(2) + mp * (xg_payload - x_g).powi(2);
    let i_z = i_g + m * x_g * x_g;
    let (x_udot, y_vdot, n_rdot) = (-0.1 * mh, -1.5 * mh, -1.7 * i_g);
    let (t_sway, t_yaw) = (1.0, 1.0);
    let thrust_max = 2.0 * OTTER_THRUST_N;
    let draft = (m / RHO) / (2.0 * 0.4 * 0.25 * l);
    SurfaceVessel {
        name: "otter",
        length_m: l,
        mass_kg: m,
        x_g_m: x_g,
        i_z,
        x_udot,
        y_vdot,
        y_rdot: 0.0,
        n_rdot,
        x_u: -thrust_max / OTTER_U_MAX_MPS,
        y_v: -(m - y_vdot) / t_sway,
        y_r: 0.0,
        n_v: 0.0,
        n_r: -(i_z - n_rdot) / t_yaw,
        x_uu: -thrust_max / OTTER_U_MAX_MPS.powi(2),
        cross_flow: CrossFlow {
            length_m: l,
            draft_m: draft,
            cd: hoerner_cd(0.25, draft),
            rho: RHO,
        },
        stable_to_mps: 1.0,
    }
}

/// The supply vessel in SI: with Bis scales m, L, √(L/g) (supply.m),
/// M = m·[[M″₁₁, 0, 0], [0, M″₂₂, M″₂₃ L], [0, M″₃₂ L, M″₃₃ L²]] and
/// D = m √(g/L)·(same pattern of D″ = −A″_h M″). The split M = M_RB + M_A
/// is not in the paper; assumed here: the sway–yaw coupling M″₂₃ is all
/// rigid body, x_g = M″₂₃ L = −5.67 m (the ShipX look-alike has its LCG
/// 5.4 m aft of midships), Y_ṙ = 0, I_z = m (R₆₆² + x_g²) with
/// R₆₆ = 0.25 L (the look-alike's r66/Lpp); the rest of M″ is added mass.
/// X_|u|u = −thrust_max/U_max² with thrust_max = both mains at full
/// command, 2·K″₁·m g = 1.09 MN, and U_max = [`SUPPLY_U_MAX_MPS`].
/// Cross-flow: L = 76.2 m, T = 6.0 m, C_d^2D = Hoerner(19.2/12) = 0.70.
///
/// Straight-line stable with C_A on below 1.85 m/s (the Munk moment).
pub fn supply() -> SurfaceVessel {
    let (m, l, g) = (SUPPLY_MASS_KG, dp_ship::LENGTH_M, dp_ship::GRAVITY);
    let mb = dp_ship::M;
    let ah = dp_ship::A_H;
    // D″ = −A″_h M″.
    let d = |i: usize, j: usize| -> f64 { -(0..3).map(|k| ah[i][k] * mb[k][j]).sum::<f64>() };
    let dscale = m * (g / l).sqrt();
    let x_g = mb[1][2] * l;
    let i_z = m * ((0.25 * l).powi(2) + x_g * x_g);
    let thrust_max = 2.0 * dp_ship::K[0] * m * g;
    SurfaceVessel {
        name: "supply",
        length_m: l,
        mass_kg: m,
        x_g_m: x_g,
        i_z,
        x_udot: -(mb[0][0] - 1.0) * m,
        y_vdot: -(mb[1][1] - 1.0) * m,
        y_rdot: 0.0,
        n_rdot: -(mb[2][2] * m * l * l - i_z),
        x_u: -d(0, 0) * dscale,
        y_v: -d(1, 1) * dscale,
        y_r: -d(1, 2) * dscale * l,
        n_v: -d(2, 1) * dscale * l,
        n_r: -d(2, 2) * dscale * l * l,
        x_uu: -thrust_max / SUPPLY_U_MAX_MPS.powi(2),
        cross_flow: CrossFlow {
            length_m: l,
            draft_m: SUPPLY_DRAFT_M,
            cd: hoerner_cd(SUPPLY_BEAM_M, SUPPLY_DRAFT_M),
            rho: RHO,
        },
        stable_to_mps: 1.5,
    }
}

impl SurfaceVessel {
    /// A vessel like this one: every inertial and hydrodynamic parameter
    /// (m, x_g, I_z, X_u̇, Y_v̇, Y_ṙ, N_ṙ, X_u, Y_v, Y_r, N_v, N_r, X_|u|u,
    /// C_d^2D) scaled by its own factor uniform in [0.8, 1.2); geometry (L,
    /// draft) and ρ kept. Draws whose M is not positive definite or whose
    /// straight course is unstable (C_A on or off) below `stable_to_mps`
    /// are drawn again. Same seed, same vessel.
    pub fn draw(&self, seed: u64) -> SurfaceVessel {
        let mut rng = Rng::new(seed);
        loop {
            let mut f = || rng.range(0.8, 1.2);
            let v = SurfaceVessel {
                mass_kg: self.mass_kg * f(),
                x_g_m: self.x_g_m * f(),
                i_z: self.i_z * f(),
                x_udot: self.x_udot * f(),
                y_vdot: self.y_vdot * f(),
                y_rdot: self.y_rdot * f(),
                n_rdot: self.n_rdot * f(),
                x_u: self.x_u * f(),
                y_v: self.y_v * f(),
                y_r: self.y_r * f(),
                n_v: self.n_v * f(),
                n_r: self.n_r * f(),
                x_uu: self.x_uu * f(),
                cross_flow: CrossFlow {
                    cd: self.cross_flow.cd * f(),
                    ..self.cross_flow
                },
                ..self.clone()
            };
            let stable = |munk| v.critical_speed(munk).is_none_or(|c| c > v.stable_to_mps);
            if v.mass_matrix().cholesky().is_some() && stable(true) && stable(false) {
                return v;
            }
        }
    }
}
