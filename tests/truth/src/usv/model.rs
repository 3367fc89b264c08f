//! The 3-DOF (surge, sway, yaw) maneuvering model of a surface vessel
//! (Fossen 2021, *Handbook of Marine Craft Hydrodynamics and Motion
//! Control*, 2nd ed., ch. 6–7; the relative-velocity form of eqs.
//! 6.111–6.116 as cited in MSS `CRAFT/SHIP/models/osv.m`), reduced to the
//! horizontal plane:
//!
//!   M_RB ν̇ + M_A ν̇_r + C_RB(ν)ν + C_A(ν_r)ν_r + D_L ν_r + d_NL(ν_r) = τ,
//!   η̇ = R(ψ)ν,
//!
//! ν = [u, v, r]ᵀ over ground in the body frame, ν_r = ν − ν_c the velocity
//! through the water ([`crate::usv::current`]), η = [x, y, ψ]ᵀ in NED, and
//! τ = [X, Y, N]ᵀ (N, N, N·m). With the coordinate origin CO on the
//! centreline and the CG at (x_g, 0):
//!
//! - M_RB = [[m, 0, 0], [0, m, m x_g], [0, m x_g, I_z]] (I_z about the CO),
//! - M_A = −[[X_u̇, 0, 0], [0, Y_v̇, Y_ṙ], [0, N_v̇, N_ṙ]] with N_v̇ = Y_ṙ,
//! - C_RB(ν) = [[0, 0, −m(x_g r + v)], [0, 0, m u], [m(x_g r + v), −m u, 0]]
//!   and C_A(ν_r) = [[0, 0, Y_v̇ v_r + Y_ṙ r], [0, 0, −X_u̇ u_r],
//!   [−Y_v̇ v_r − Y_ṙ r, X_u̇ u_r, 0]]: the skew-symmetric forms from M_RB and
//!   M_A (Fossen 2021, Theorem 3.2, 3-DOF case as in MSS `m2c.m`), so they do
//!   no work. C_A's yaw entry −(Y_v̇ − X_u̇) u_r v_r is the Munk moment: the
//!   moment on the vessel is N_Munk = (Y_v̇ − X_u̇) u_r v_r, which turns a
//!   drifting hull broadside and makes fast hulls directionally unstable
//!   ([`SurfaceVessel::critical_speed`]).
//! - D_L = −[[X_u, 0, 0], [0, Y_v, Y_r], [0, N_v, N_r]],
//! - d_NL(ν_r) = [−X_|u|u |u_r| u_r, −Y_cf, −N_cf]ᵀ: quadratic surge damping
//!   and strip-theory cross-flow drag ([`crate::usv::cross_flow`]).
//!
//! Solved for ν̇ (ν̇_r = ν̇ − ν̇_c):
//!
//!   (M_RB + M_A) ν̇ = τ + M_A ν̇_c − C_RB(ν)ν − C_A(ν_r)ν_r − D_L ν_r − d_NL(ν_r),
//!
//! integrated by classical RK4 with τ held over each log sample.

use nalgebra::{Matrix2, Matrix3, Vector3};

use super::cross_flow::CrossFlow;
use super::current::{Current, CurrentNow, CurrentTrack};

/// Parameters of the 3-DOF model (SI: kg, m, s, rad). Hydrodynamic
/// derivatives in SNAME notation, negative for damping and added mass.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceVessel {
    /// Which vessel.
    pub name: &'static str,
    /// Length L (m).
    pub length_m: f64,
    /// m (kg).
    pub mass_kg: f64,
    /// x_g: CG ahead of the CO (m).
    pub x_g_m: f64,
    /// I_z about the CO (kg·m²).
    pub i_z: f64,
    /// X_u̇ (kg).
    pub x_udot: f64,
    /// Y_v̇ (kg).
    pub y_vdot: f64,
    /// Y_ṙ = N_v̇ (kg·m).
    pub y_rdot: f64,
    /// N_ṙ (kg·m²).
    pub n_rdot: f64,
    /// X_u (N·s/m).
    pub x_u: f64,
    /// Y_v (N·s/m).
    pub y_v: f64,
    /// Y_r (N·s).
    pub y_r: f64,
    /// N_v (N·s).
    pub n_v: f64,
    /// N_r (N·m·s).
    pub n_r: f64,
    /// X_|u|u (N·s²/m²).
    pub x_uu: f64,
    /// Cross-flow drag hull.
    pub cross_flow: CrossFlow,
    /// [`SurfaceVessel::draw`] keeps only draws straight-line stable with
    /// C_A on up to this speed through the water (m/s).
    pub stable_to_mps: f64,
}

/// Which physics a truth flies. [`Effects::CLEAN`] is D_L only with C_RB:
/// no current, no C_A, no quadratic or cross-flow damping.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Effects {
    /// The current campaigns draw for each run ([`Current::None`]: ν_r = ν).
    /// [`Simulator`] itself takes the realised current.
    pub current: Current,
    /// −X_|u|u |u_r| u_r in surge.
    pub quadratic_surge: bool,
    /// Cross-flow drag Y_cf, N_cf in sway and yaw.
    pub cross_flow: bool,
    /// C_A(ν_r)ν_r (added-mass Coriolis and centripetal terms, whose yaw
    /// entry is the Munk moment). Off: the term is dropped entirely.
    pub munk: bool,
    /// C_RB(ν)ν. On in every configuration a campaign should fly (it is
    /// rigid-body physics, not a hydrodynamic effect); off only to show
    /// that it is the clean model's one nonlinearity.
    pub rigid_body_coriolis: bool,
}

impl Effects {
    /// Linear D_L only, no current, C_A off, C_RB kept.
    pub const CLEAN: Effects = Effects {
        current: Current::None,
        quadratic_surge: false,
        cross_flow: false,
        munk: false,
        rigid_body_coriolis: true,
    };

    /// Every effect on, in `current`.
    pub const fn all(current: Current) -> Effects {
        Effects {
            current,
            quadratic_surge: true,
            cross_flow: true,
            munk: true,
            rigid_body_coriolis: true,
        }
    }
}

impl SurfaceVessel {
    /// M_RB.
    pub fn m_rb(&self) -> Matrix3<f64> {
        let (m, mx) = (self.mass_kg, self.mass_kg * self.x_g_m);
        Matrix3::new(m, 0.0, 0.0, 0.0, m, mx, 0.0, mx, self.i_z)
    }

    /// M_A = −[[X_u̇, 0, 0], [0, Y_v̇, Y_ṙ], [0, Y_ṙ, N_ṙ]].
    pub fn m_a(&self) -> Matrix3<f64> {
        -Matrix3::new(
            self.x_udot,
            0.0,
            0.0,
            0.0,
            self.y_vdot,
            self.y_rdot,
            0.0,
            self.y_rdot,
            self.n_rdot,
        )
    }

    /// M = M_RB + M_A.
    pub fn mass_matrix(&self) -> Matrix3<f64> {
        self.m_rb() + self.m_a()
    }

    /// D_L = −[[X_u, 0, 0], [0, Y_v, Y_r], [0, N_v, N_r]].
    pub fn d_l(&self) -> Matrix3<f64> {
        -Matrix3::new(
            self.x_u, 0.0, 0.0, 0.0, self.y_v, self.y_r, 0.0, self.n_v, self.n_r,
        )
    }

    /// C_RB(ν).
    pub fn c_rb(&self, nu: &Vector3<f64>) -> Matrix3<f64> {
        let m = self.mass_kg;
        let a = m * (self.x_g_m * nu[2] + nu[1]);
        let b = m * nu[0];
        Matrix3::new(0.0, 0.0, -a, 0.0, 0.0, b, a, -b, 0.0)
    }

    /// C_A(ν_r).
    pub fn c_a(&self, nu_r: &Vector3<f64>) -> Matrix3<f64> {
        let a = self.y_vdot * nu_r[1] + self.y_rdot * nu_r[2];
        let b = -self.x_udot * nu_r[0];
        Matrix3::new(0.0, 0.0, a, 0.0, 0.0, b, -a, -b, 0.0)
    }

    /// The Munk moment on the vessel, N_Munk = (Y_v̇ − X_u̇) u_r v_r (N·m).
    pub fn munk_moment(&self, u_r: f64, v_r: f64) -> f64 {
        (self.y_vdot - self.x_udot) * u_r * v_r
    }

    /// d_NL(ν_r) of the switched-on terms (left-hand side: the negative of
    /// the force on the vessel).
    pub fn nonlinear_damping(&self, nu_r: &Vector3<f64>, effects: &Effects) -> Vector3<f64> {
        let mut d = Vector3::zeros();
        if effects.quadratic_surge {
            d[0] = -self.x_uu * nu_r[0].abs() * nu_r[0];
        }
        if effects.cross_flow {
            let (y, n) = self.cross_flow.force(nu_r[1], nu_r[2]);
            d[1] = -y;
            d[2] = -n;
        }
        d
    }

    /// Steady surge speed through the water (m/s) under a constant τ_X (N)
    /// on a straight course: X_u u + X_|u|u |u| u + τ_X = 0, with or without
    /// the quadratic term.
    pub fn steady_surge_speed(&self, tau_x: f64, quadratic: bool) -> f64 {
        let (a, b) = (if quadratic { -self.x_uu } else { 0.0 }, -self.x_u);
        let t = tau_x.abs();
        let u = if a == 0.0 {
            t / b
        } else {
            2.0 * t / (b + (b * b + 4.0 * a * t).sqrt())
        };
        u.copysign(tau_x)
    }

    /// Sway–yaw linearised about a straight course at u_r = `u0` in still
    /// water: (M_sy, N_sy) with M_sy [v̇, ṙ] + N_sy [v, r] = 0 and
    /// N_sy = D_L,sy + u0 [[0, m − X_u̇], [X_u̇ − Y_v̇, m x_g − Y_ṙ]] (C_A on)
    /// or u0 [[0, m], [0, m x_g]] (C_A off).
    pub fn sway_yaw_linearisation(&self, u0: f64, munk: bool) -> (Matrix2<f64>, Matrix2<f64>) {
        let m = self.mass_matrix();
        let d = self.d_l();
        let ms = Matrix2::new(m[(1, 1)], m[(1, 2)], m[(2, 1)], m[(2, 2)]);
        let mut n = Matrix2::new(d[(1, 1)], d[(1, 2)], d[(2, 1)], d[(2, 2)]);
        let mass = self.mass_kg;
        n[(0, 1)] += mass * u0;
        n[(1, 1)] += mass * self.x_g_m * u0;
        if munk {
            n[(0, 1)] -= self.x_udot * u0;
            n[(1, 0)] += (self.x_udot - self.y_vdot) * u0;
            n[(1, 1)] -= self.y_rdot * u0;
        }
        (ms, n)
    }

    /// Whether a straight course at u_r = `u0` is stable in sway–yaw
    /// (both eigenvalues of −M_sy⁻¹N_sy in the open left half-plane).
    pub fn straight_line_stable(&self, u0: f64, munk: bool) -> bool {
        let (ms, n) = self.sway_yaw_linearisation(u0, munk);
        let a = ms.try_inverse().expect("M is invertible") * n;
        a.determinant() > 0.0 && a.trace() > 0.0
    }

    /// The lowest forward speed through the water (m/s) at which the
    /// straight course loses stability, searched up to 100 m/s (None:
    /// stable throughout).
    pub fn critical_speed(&self, munk: bool) -> Option<f64> {
        let step = 0.005;
        let mut lo = 0.0;
        while lo < 100.0 {
            let hi = lo + step;
            if !self.straight_line_stable(hi, munk) {
                let (mut a, mut b) = (lo, hi);
                for _ in 0..60 {
                    let c = 0.5 * (a + b);
                    if self.straight_line_stable(c, munk) {
                        a = c;
                    } else {
                        b = c;
                    }
                }
                return Some(0.5 * (a + b));
            }
            lo = hi;
        }
        None
    }
}

/// The model of one vessel under one set of [`Effects`], with M⁻¹ cached.
/// State s = [u, v, r, x, y, ψ] (m/s, rad/s, m, rad), ν over ground.
#[derive(Debug, Clone)]
pub struct Simulator {
    vessel: SurfaceVessel,
    effects: Effects,
    m_inv: Matrix3<f64>,
    m_a: Matrix3<f64>,
    d_l: Matrix3<f64>,
}

impl Simulator {
    /// The model of `vessel` with `effects` (its `current` is not used: the
    /// realised current is passed to each call).
    pub fn new(vessel: &SurfaceVessel, effects: Effects) -> Self {
        Simulator {
            vessel: vessel.clone(),
            effects,
            m_inv: vessel
                .mass_matrix()
                .try_inverse()
                .expect("M_RB + M_A is invertible"),
            m_a: vessel.m_a(),
            d_l: vessel.d_l(),
        }
    }

    /// ν̇ at velocity `nu` over ground, heading `psi`, force `tau` and
    /// current `cur`.
    pub fn nu_dot(
        &self,
        nu: &Vector3<f64>,
        psi: f64,
        tau: &Vector3<f64>,
        cur: &CurrentNow,
    ) -> Vector3<f64> {
        let v = &self.vessel;
        let [u_c, v_c] = cur.body(psi);
        let [du_c, dv_c] = cur.body_rate(psi, nu[2]);
        let nu_r = nu - Vector3::new(u_c, v_c, 0.0);
        let mut f = tau + self.m_a * Vector3::new(du_c, dv_c, 0.0)
            - self.d_l * nu_r
            - v.nonlinear_damping(&nu_r, &self.effects);
        if self.effects.rigid_body_coriolis {
            f -= v.c_rb(nu) * nu;
        }
        if self.effects.munk {
            f -= v.c_a(&nu_r) * nu_r;
        }
        self.m_inv * f
    }

    /// ṡ = [ν̇, R(ψ)ν].
    pub fn derivative(&self, s: &[f64; 6], tau: &Vector3<f64>, cur: &CurrentNow) -> [f64; 6] {
        let nu = Vector3::new(s[0], s[1], s[2]);
        let a = self.nu_dot(&nu, s[5], tau, cur);
        let (sn, cs) = s[5].sin_cos();
        [
            a[0],
            a[1],
            a[2],
            cs * nu[0] - sn * nu[1],
            sn * nu[0] + cs * nu[1],
            nu[2],
        ]
    }

    /// One RK4 step of length `dt` from `s`, τ held, the current `cur` at the
    /// start of the step (moving at its V̇_c).
    pub fn step(&self, s: &[f64; 6], tau: &Vector3<f64>, cur: &CurrentNow, dt: f64) -> [f64; 6] {
        let at =
            |k: &[f64; 6], c: f64| -> [f64; 6] { std::array::from_fn(|i| s[i] + c * dt * k[i]) };
        let mid = cur.advanced(0.5 * dt);
        let k1 = self.derivative(s, tau, cur);
        let k2 = self.derivative(&at(&k1, 0.5), tau, &mid);
        let k3 = self.derivative(&at(&k2, 0.5), tau, &mid);
        let k4 = self.derivative(&at(&k3, 1.0), tau, &cur.advanced(dt));
        std::array::from_fn(|i| s[i] + dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
    }

    /// Flies τ_k (held over [k·h, (k+1)·h)) from `s0` in the realised
    /// current `track` (at least as many samples as `taus`), `substeps` RK4
    /// steps per sample. Returns the state at each t = k·h, k = 0 … n − 1
    /// (before τ_k acts).
    pub fn fly(
        &self,
        s0: [f64; 6],
        taus: &[Vector3<f64>],
        track: &CurrentTrack,
        h: f64,
        substeps: usize,
    ) -> Vec<[f64; 6]> {
        let dt = h / substeps as f64;
        let mut s = s0;
        let mut out = Vec::with_capacity(taus.len());
        for (k, tau) in taus.iter().enumerate() {
            out.push(s);
            let seg = track.segment(k, h);
            for j in 0..substeps {
                s = self.step(&s, tau, &seg.advanced(j as f64 * dt), dt);
            }
        }
        out
    }
}
