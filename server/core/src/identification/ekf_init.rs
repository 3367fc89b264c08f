//! Initial values of the parallel EKF when the vessel profile gives no
//! inertia M″: a least-squares fit of the 3-DOF ship
//!
//!   M″ν̇ + D″ν = T″K″u + b,   D″ = −A″_h·M″   (Fossen et al. 1995, eq. 27, 48),
//!
//! on body velocities numerically differentiated from the measured pose and
//! rotated into the body frame (ν = R(ψ)ᵀη̇, a local linear fit over ±2
//! samples), each side passed through the state-variable filter
//! F(s) = 1/(1 + sT_f)² so that ν̇ is never differenced twice (s·F·ν is
//! exact from F's states). The equation is linear in M″, D″, K″ and b; C(ν)ν
//! is left out (second order in the small DP velocities).
//!
//! **What the data cannot tell.** Scaling M″, D″, K″ and b by one factor c
//! leaves the motion unchanged, separately for surge and for the coupled
//! sway–yaw block: their scale is not identifiable from commands and motion.
//! It is fixed at M″11 = M″22 = 1, the rigid-body mass (the Bis mass unit)
//! without added mass; A″_h, A″ = M″⁻¹A″_hM″ and B″ = M″⁻¹T″K″ do not depend
//! on it, while every K″ comes out as K″/M″ii of the true ship. The shape of
//! the sway–yaw inertia (M″23/M″22, M″33/M″22) is estimated here and then
//! held fixed by the EKF. It enters the data only through B″ (six sway–yaw
//! entries for five unknowns), through the small sway response to the
//! tunnels, so it is rough, and so are the couplings θ″3 = A″_h23 and
//! θ″4 = A″_h32 that A″_h = M″A″M″⁻¹ takes from it (a prediction-error
//! search over the shape with the staged EKF did not sharpen it on the
//! independent truth).

use nalgebra::{DMatrix, DVector, Matrix3};

use crate::logs::measurements::local_slope;
use crate::simulation::dp_ship::{Matrix3x6, N_THETA};

/// Samples each side of the local linear fit that differentiates the pose.
const SLOPE_HALF_WINDOW: usize = 2;
/// State-variable filter time constant, in samples.
const FILTER_SAMPLES: f64 = 4.0;

/// One gap-free block: commands u (N × 6) and the measured pose z (N × 3:
/// x″, y″, ψ unwrapped), Bis units.
pub struct InitBlock<'a> {
    /// Thruster commands.
    pub u: &'a DMatrix<f64>,
    /// Measured pose.
    pub z: &'a DMatrix<f64>,
}

/// The least-squares start of the EKF.
#[derive(Debug, Clone, PartialEq)]
pub struct LsStart {
    /// M″ with M″11 = M″22 = 1 and the estimated sway–yaw shape.
    pub m: Matrix3<f64>,
    /// θ″1 … θ″9 under that M″.
    pub theta: [f64; N_THETA],
}

/// `x` through F₁(s) = 1/(1 + sT) discretized for a held input, started at
/// its first value (a block starting at rest has no transient).
fn first_order(x: &[f64], a: f64) -> Vec<f64> {
    let mut y = Vec::with_capacity(x.len());
    let mut s = x.first().copied().unwrap_or(0.0);
    for &v in x {
        y.push(s);
        s = a * s + (1.0 - a) * v;
    }
    y
}

/// F·x and s·F·x for F = F₁² (s·F·x = (F₁x − F₁²x)/T).
fn svf(x: &[f64], a: f64, t_f: f64) -> (Vec<f64>, Vec<f64>) {
    let f1 = first_order(x, a);
    let f2 = first_order(&f1, a);
    let d = f1.iter().zip(&f2).map(|(p, q)| (p - q) / t_f).collect();
    (f2, d)
}

/// Filtered body velocities (F·ν, s·F·ν per DOF) and commands (F·u) of a block.
struct Filtered {
    nu: [Vec<f64>; 3],
    nu_dot: [Vec<f64>; 3],
    u: Vec<Vec<f64>>,
}

fn filtered(b: &InitBlock<'_>, h: f64) -> Filtered {
    let t_f = FILTER_SAMPLES * h;
    let a = (-h / t_f).exp();
    let col = |m: &DMatrix<f64>, j: usize| m.column(j).iter().copied().collect::<Vec<f64>>();
    let (x, y, psi) = (col(b.z, 0), col(b.z, 1), col(b.z, 2));
    let xd = local_slope(&x, h, SLOPE_HALF_WINDOW);
    let yd = local_slope(&y, h, SLOPE_HALF_WINDOW);
    let r = local_slope(&psi, h, SLOPE_HALF_WINDOW);
    let (mut u, mut v) = (Vec::new(), Vec::new());
    for k in 0..x.len() {
        let (s, c) = psi[k].sin_cos();
        u.push(c * xd[k] + s * yd[k]);
        v.push(-s * xd[k] + c * yd[k]);
    }
    let parts = [u, v, r].map(|n| svf(&n, a, t_f));
    Filtered {
        nu: std::array::from_fn(|i| parts[i].0.clone()),
        nu_dot: std::array::from_fn(|i| parts[i].1.clone()),
        u: (0..b.u.ncols())
            .map(|j| svf(&col(b.u, j), a, t_f).0)
            .collect(),
    }
}

fn solve(rows: &[Vec<f64>], y: &[f64]) -> Result<DVector<f64>, String> {
    let n = rows.first().map_or(0, Vec::len);
    if rows.len() < 2 * n {
        return Err(format!(
            "{} equations for {n} unknowns: the runs are too short",
            rows.len()
        ));
    }
    let x = DMatrix::from_fn(rows.len(), n, |i, j| rows[i][j]);
    let sol = x
        .svd(true, true)
        .solve(&DVector::from_column_slice(y), 1e-12)
        .map_err(|e| e.to_string())?;
    if sol.iter().all(|v| v.is_finite()) {
        Ok(sol)
    } else {
        Err("the least-squares fit is singular".into())
    }
}

/// The least-squares start from `blocks` (sample time `h`, Bis), thruster
/// configuration `t` and the K″ index of each thruster column (`groups[j]`
/// in 0..4: θ″6 … θ″9). Errors say why the data cannot give it (too short,
/// singular, an inertia shape that is not positive definite).
pub fn ls_start(
    blocks: &[InitBlock<'_>],
    h: f64,
    t: &Matrix3x6,
    groups: &[usize; 6],
) -> Result<LsStart, String> {
    let skip = (3.0 * FILTER_SAMPLES).ceil() as usize;
    let nb = blocks.len();
    // Surge: s·F·u = −d11·F·u + K1·Σ t1j F·u_j + b0 (main-propeller group 0).
    let (mut surge, mut y0) = (Vec::new(), Vec::new());
    // Sway–yaw, unknowns [m23, m33, d22, d23, d32, d33, K_g (g = 1..3),
    // b1 per block, b2 per block], M″22 = 1.
    let (mut sy, mut y12) = (Vec::new(), Vec::new());
    let w = |f: &Filtered, i: usize, g: usize, k: usize| -> f64 {
        (0..6)
            .filter(|&j| groups[j] == g)
            .map(|j| t[(i, j)] * f.u[j][k])
            .sum()
    };
    let filt: Vec<Filtered> = blocks.iter().map(|b| filtered(b, h)).collect();
    for (bi, f) in filt.iter().enumerate() {
        for k in skip..f.nu[0].len() {
            let mut row = vec![-f.nu[0][k], w(f, 0, 0, k)];
            row.extend((0..nb).map(|j| f64::from(u8::from(j == bi))));
            surge.push(row);
            y0.push(f.nu_dot[0][k]);
        }
    }
    let s0 = solve(&surge, &y0)?;
    let (d11, k1) = (s0[0], s0[1]);
    for (bi, f) in filt.iter().enumerate() {
        for k in skip..f.nu[0].len() {
            let (v, r, vd, rd) = (f.nu[1][k], f.nu[2][k], f.nu_dot[1][k], f.nu_dot[2][k]);
            let mut row1 = vec![-rd, 0.0, -v, -r, 0.0, 0.0];
            let mut row2 = vec![-vd, -rd, 0.0, 0.0, -v, -r];
            for g in 1..4 {
                row1.push(w(f, 1, g, k));
                row2.push(w(f, 2, g, k));
            }
            row1.extend((0..2 * nb).map(|j| f64::from(u8::from(j == bi))));
            row2.extend((0..2 * nb).map(|j| f64::from(u8::from(j == nb + bi))));
            sy.push(row1);
            y12.push(vd - k1 * w(f, 1, 0, k));
            sy.push(row2);
            y12.push(-k1 * w(f, 2, 0, k));
        }
    }
    let p = solve(&sy, &y12)?;
    let m = Matrix3::new(1.0, 0.0, 0.0, 0.0, 1.0, p[0], 0.0, p[0], p[1]);
    if m.cholesky().is_none() {
        return Err(format!(
            "the fitted sway–yaw inertia (M″23 = {:.3e}, M″33 = {:.3e} per M″22) is not positive definite",
            p[0], p[1]
        ));
    }
    let d = Matrix3::new(d11, 0.0, 0.0, 0.0, p[2], p[3], 0.0, p[4], p[5]);
    let m_inv = m.try_inverse().ok_or("M″ is singular")?;
    let a_h = -d * m_inv;
    let theta = [
        a_h[(0, 0)],
        a_h[(1, 1)],
        a_h[(1, 2)],
        a_h[(2, 1)],
        a_h[(2, 2)],
        k1,
        p[6],
        p[7],
        p[8],
    ];
    Ok(LsStart { m, theta })
}

/// The model note of an identification without M″ in the profile.
pub fn without_prior_note(m: &Matrix3<f64>) -> String {
    let sig = crate::numbers::sig3;
    format!(
        "No M″ in the profile: the EKF started from a least-squares fit on body velocities differentiated from the measured pose (M″ν̇ + D″ν = T″K″u + b, state-variable filter), which gave the sway–yaw inertia shape M″23 = {}, M″33 = {} per M″22, with M″11 = M″22 = 1, the rigid-body mass without added mass; M″ is then held fixed and C(ν)ν uses it. The common scale of M″ and K″ is not identifiable from commands and motion: each K″ is K″/M″ii of the ship (surge: M″11, sway–yaw: M″22), while A″_h11 and A″ do not depend on that choice. Give M″ in the profile for K″ in the Bis system.",
        sig(m[(1, 2)]),
        sig(m[(2, 2)])
    )
}

/// The structure finding of an identification without M″: the couplings
/// that depend on the rough inertia shape.
pub const WITHOUT_PRIOR_FINDING: &str = "Without M″ in the profile, θ″3 (A″_h23) and θ″4 (A″_h32) follow the least-squares inertia shape, which the data determine only roughly; their σ are conditional on it: treat them as unknown (within tens of percent) or give M″";
