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
use crate::simulation::dp_ship::{N_GROUPS, N_THETA, ThrustLayout};

/// Samples each side of the local linear fit that differentiates the pose.
const SLOPE_HALF_WINDOW: usize = 2;
/// State-variable filter time constant, in samples.
const FILTER_SAMPLES: f64 = 4.0;

/// Share of a group's force energy in surge above which its K″ is fitted
/// from the surge equation.
const SURGE_SHARE: f64 = 0.05;
/// Share of the sway–yaw force energy from surge-fitted groups above which
/// M″22 is fitted against them instead of fixed at 1.
const SWAY_FROM_SURGE_SHARE: f64 = 0.01;

/// One gap-free block: commands u (N × r) and the measured pose z (N × 3:
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
    /// M″ with M″11 = 1 and the estimated sway–yaw inertia: M″22 = 1 too
    /// unless groups fitted in surge also drive sway–yaw (then M″22 is
    /// fitted against their K″).
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

/// The least-squares start from `blocks` (sample time `h`, Bis) and the
/// thrust layout (T and the K″ group of each column, θ″6 … θ″9). A group
/// whose force is mostly not surge-free (≥ 5 % of its energy in surge) has
/// its K″ fitted from the surge equation, the others from sway–yaw. Errors
/// say why the data cannot give it (too short, singular, an inertia shape
/// that is not positive definite).
pub fn ls_start(
    blocks: &[InitBlock<'_>],
    h: f64,
    thrust: &ThrustLayout,
) -> Result<LsStart, String> {
    let skip = (3.0 * FILTER_SAMPLES).ceil() as usize;
    let nb = blocks.len();
    let t = &thrust.t;
    let w = |f: &Filtered, i: usize, g: usize, k: usize| -> f64 {
        (0..thrust.columns())
            .filter(|&j| thrust.groups[j] == g)
            .map(|j| t[(i, j)] * f.u[j][k])
            .sum()
    };
    let filt: Vec<Filtered> = blocks.iter().map(|b| filtered(b, h)).collect();
    // Force energy per group and DOF.
    let mut energy = [[0.0f64; 3]; N_GROUPS];
    for f in &filt {
        for k in skip..f.nu[0].len() {
            for (g, e) in energy.iter_mut().enumerate() {
                for (i, ei) in e.iter_mut().enumerate() {
                    *ei += w(f, i, g, k).powi(2);
                }
            }
        }
    }
    let total = |g: usize| energy[g].iter().sum::<f64>();
    let used: Vec<usize> = (0..N_GROUPS)
        .filter(|&g| thrust.uses(g) && total(g) > 0.0)
        .collect();
    let (surge_g, sway_g): (Vec<usize>, Vec<usize>) = used
        .iter()
        .partition(|&&g| energy[g][0] >= SURGE_SHARE * total(g));
    if surge_g.is_empty() {
        return Err("no thruster group pushes in surge in the estimation runs".into());
    }
    let sway_energy: f64 = used.iter().map(|&g| energy[g][1] + energy[g][2]).sum();
    let from_surge: f64 = surge_g.iter().map(|&g| energy[g][1] + energy[g][2]).sum();
    let fit_m22 = sway_g.is_empty() || from_surge > SWAY_FROM_SURGE_SHARE * sway_energy;
    // Surge: s·F·ν1 = −d11·F·ν1 + Σ_g K_g·F·w_g1 + b0 per block (M″11 = 1).
    let (mut surge, mut y0) = (Vec::new(), Vec::new());
    for (bi, f) in filt.iter().enumerate() {
        for k in skip..f.nu[0].len() {
            let mut row = vec![-f.nu[0][k]];
            row.extend(surge_g.iter().map(|&g| w(f, 0, g, k)));
            row.extend((0..nb).map(|j| f64::from(u8::from(j == bi))));
            surge.push(row);
            y0.push(f.nu_dot[0][k]);
        }
    }
    let s0 = solve(&surge, &y0)?;
    let d11 = s0[0];
    let mut theta = [0.0; N_THETA];
    for (c, &g) in surge_g.iter().enumerate() {
        theta[5 + g] = s0[1 + c];
    }
    // Sway–yaw, unknowns [m22 (when fitted), m23, m33, d22, d23, d32, d33,
    // K_g of the sway–yaw groups, b1 per block, b2 per block].
    let lead = usize::from(fit_m22);
    let (mut sy, mut y12) = (Vec::new(), Vec::new());
    for (bi, f) in filt.iter().enumerate() {
        for k in skip..f.nu[0].len() {
            let (v, r, vd, rd) = (f.nu[1][k], f.nu[2][k], f.nu_dot[1][k], f.nu_dot[2][k]);
            let mut row1 = vec![-rd, 0.0, -v, -r, 0.0, 0.0];
            let mut row2 = vec![-vd, -rd, 0.0, 0.0, -v, -r];
            if fit_m22 {
                row1.insert(0, -vd);
                row2.insert(0, 0.0);
            }
            for &g in &sway_g {
                row1.push(w(f, 1, g, k));
                row2.push(w(f, 2, g, k));
            }
            row1.extend((0..2 * nb).map(|j| f64::from(u8::from(j == bi))));
            row2.extend((0..2 * nb).map(|j| f64::from(u8::from(j == nb + bi))));
            let known =
                |i: usize| -> f64 { surge_g.iter().map(|&g| theta[5 + g] * w(f, i, g, k)).sum() };
            sy.push(row1);
            y12.push(if fit_m22 { -known(1) } else { vd - known(1) });
            sy.push(row2);
            y12.push(-known(2));
        }
    }
    let p = solve(&sy, &y12)?;
    let m22 = if fit_m22 { p[0] } else { 1.0 };
    let (m23, m33) = (p[lead], p[lead + 1]);
    let m = Matrix3::new(1.0, 0.0, 0.0, 0.0, m22, m23, 0.0, m23, m33);
    if m.cholesky().is_none() {
        return Err(format!(
            "the fitted sway–yaw inertia (M″22 = {:.3e}, M″23 = {:.3e}, M″33 = {:.3e}) is not positive definite",
            m22, m23, m33
        ));
    }
    let q = &p.as_slice()[lead + 2..];
    let d = Matrix3::new(d11, 0.0, 0.0, 0.0, q[0], q[1], 0.0, q[2], q[3]);
    for (c, &g) in sway_g.iter().enumerate() {
        theta[5 + g] = q[4 + c];
    }
    let m_inv = m.try_inverse().ok_or("M″ is singular")?;
    let a_h = -d * m_inv;
    theta[..5].copy_from_slice(&[
        a_h[(0, 0)],
        a_h[(1, 1)],
        a_h[(1, 2)],
        a_h[(2, 1)],
        a_h[(2, 2)],
    ]);
    Ok(LsStart { m, theta })
}

/// The model note of an identification without M″ in the profile.
pub fn without_prior_note(m: &Matrix3<f64>) -> String {
    let sig = crate::numbers::sig3;
    if m[(1, 1)] != 1.0 {
        return format!(
            "No M″ in the profile: the EKF started from a least-squares fit on body velocities differentiated from the measured pose (M″ν̇ + D″ν = T″K″u + b, state-variable filter), which gave M″22 = {}, M″23 = {}, M″33 = {} per M″11 = 1, the rigid-body mass without added mass (M″22 from thrusters that push in surge and sway alike); M″ is then held fixed and C(ν)ν uses it. The common scale of M″ and K″ is not identifiable from commands and motion: each K″ is K″/M″11 of the ship, while A″_h11 and A″ do not depend on that choice. Give M″ in the profile for K″ in the Bis system.",
            sig(m[(1, 1)]),
            sig(m[(1, 2)]),
            sig(m[(2, 2)])
        );
    }
    format!(
        "No M″ in the profile: the EKF started from a least-squares fit on body velocities differentiated from the measured pose (M″ν̇ + D″ν = T″K″u + b, state-variable filter), which gave the sway–yaw inertia shape M″23 = {}, M″33 = {} per M″22, with M″11 = M″22 = 1, the rigid-body mass without added mass; M″ is then held fixed and C(ν)ν uses it. The common scale of M″ and K″ is not identifiable from commands and motion: each K″ is K″/M″ii of the ship (surge: M″11, sway–yaw: M″22), while A″_h11 and A″ do not depend on that choice. Give M″ in the profile for K″ in the Bis system.",
        sig(m[(1, 2)]),
        sig(m[(2, 2)])
    )
}

/// The structure finding of an identification without M″: the couplings
/// that depend on the rough inertia shape.
pub const WITHOUT_PRIOR_FINDING: &str = "Without M″ in the profile, θ″3 (A″_h23) and θ″4 (A″_h32) follow the least-squares inertia shape, which the data determine only roughly; their σ are conditional on it: treat them as unknown (within tens of percent) or give M″";
