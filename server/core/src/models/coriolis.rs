//! Coriolis–centripetal matrix C(ν) computed from the inertia matrix M
//! (rigid body plus added mass), Fossen (2011) eq. 3.46 / 6.43:
//!
//! with M = [[M₁₁ M₁₂],[M₂₁ M₂₂]], ν₁ = [u v w]ᵀ, ν₂ = [p q r]ᵀ,
//!
//! C(ν) = [[0₃ₓ₃, −S(M₁₁ν₁ + M₁₂ν₂)], [−S(M₁₁ν₁ + M₁₂ν₂), −S(M₂₁ν₁ + M₂₂ν₂)]]
//!
//! where S(a)b = a × b. For symmetric M this C(ν) is skew-symmetric, so
//! νᵀC(ν)ν = 0: Coriolis forces do no work and kinetic energy ½νᵀMν is
//! conserved without damping and forces. It adds no parameters to estimate
//! (Fossen et al. 1995, eq. 11).

use nalgebra::{DMatrix, DVector, Matrix3, Matrix6, Vector3, Vector6};

use super::error::{ModelError, check_finite};
use crate::planning::dof::Dof;

/// Skew-symmetric cross-product matrix S(a): S(a)b = a × b.
pub fn skew(a: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0)
}

/// 6-DOF C(ν) from M (6×6) at ν = [u v w p q r]ᵀ (Fossen 2011, eq. 6.43).
pub fn coriolis_6dof(m: &Matrix6<f64>, nu: &Vector6<f64>) -> Matrix6<f64> {
    let nu1 = nu.fixed_rows::<3>(0).into_owned();
    let nu2 = nu.fixed_rows::<3>(3).into_owned();
    let m11 = m.fixed_view::<3, 3>(0, 0);
    let m12 = m.fixed_view::<3, 3>(0, 3);
    let m21 = m.fixed_view::<3, 3>(3, 0);
    let m22 = m.fixed_view::<3, 3>(3, 3);
    let s1 = -skew(&(m11 * nu1 + m12 * nu2));
    let s2 = -skew(&(m21 * nu1 + m22 * nu2));
    let mut c = Matrix6::zeros();
    c.fixed_view_mut::<3, 3>(0, 3).copy_from(&s1);
    c.fixed_view_mut::<3, 3>(3, 0).copy_from(&s1);
    c.fixed_view_mut::<3, 3>(3, 3).copy_from(&s2);
    c
}

/// 3-DOF horizontal C(ν) from M (3×3, order surge, sway, yaw) at
/// ν = [u v r]ᵀ: the 6-DOF form restricted to w = p = q = 0,
///
/// C(ν) = [[0, 0, −(m₂₁u + m₂₂v + m₂₃r)], [0, 0, m₁₁u + m₁₂v + m₁₃r],
///         [m₂₁u + m₂₂v + m₂₃r, −(m₁₁u + m₁₂v + m₁₃r), 0]],
///
/// which for port–starboard symmetry (m₁₂ = m₁₃ = 0) is Fossen et al. (1995)
/// eq. 11.
pub fn coriolis_3dof(m: &Matrix3<f64>, nu: &Vector3<f64>) -> Matrix3<f64> {
    let a1 = m[(0, 0)] * nu.x + m[(0, 1)] * nu.y + m[(0, 2)] * nu.z;
    let a2 = m[(1, 0)] * nu.x + m[(1, 1)] * nu.y + m[(1, 2)] * nu.z;
    Matrix3::new(0.0, 0.0, -a2, 0.0, 0.0, a1, a2, -a1, 0.0)
}

/// C(ν) for a 6-DOF (6×6 M, ν = [u v w p q r]) or a 3-DOF horizontal
/// (3×3 M, ν = [u v r]) model; other sizes are an error naming `M`.
pub fn coriolis(m: &DMatrix<f64>, nu: &DVector<f64>) -> Result<DMatrix<f64>, ModelError> {
    let n = m.nrows();
    if !(n == 6 || n == 3) || m.ncols() != n {
        return Err(ModelError::Shape {
            name: "M".into(),
            expected: "6×6 (6 DOF) or 3×3 (surge, sway, yaw)".into(),
            found: m.shape(),
        });
    }
    if nu.len() != n {
        return Err(ModelError::Shape {
            name: "ν".into(),
            expected: format!("{n}×1 (one velocity per DOF of M)"),
            found: (nu.len(), 1),
        });
    }
    check_finite("M", m.iter())?;
    check_finite("ν", nu.iter())?;
    Ok(if n == 6 {
        let c = coriolis_6dof(
            &Matrix6::from_iterator(m.iter().copied()),
            &Vector6::from_iterator(nu.iter().copied()),
        );
        DMatrix::from_iterator(6, 6, c.iter().copied())
    } else {
        let c = coriolis_3dof(
            &Matrix3::from_iterator(m.iter().copied()),
            &Vector3::from_iterator(nu.iter().copied()),
        );
        DMatrix::from_iterator(3, 3, c.iter().copied())
    })
}

/// C(ν)ν over the modelled DOFs `dofs` (the columns of `m` and `nu`) for
/// the symmetric part of M (Fossen 1994): the 6-DOF form with unmodelled
/// velocities zero, so a horizontal model gets the 3-DOF C(ν)ν. Non-finite
/// input propagates (no error: a diverging simulation shows as such).
pub fn coriolis_force(dofs: &[Dof], m: &DMatrix<f64>, nu: &[f64]) -> Vec<f64> {
    let f6 = coriolis_force6(dofs, m, nu);
    dofs.iter().map(|d| f6[d.index()]).collect()
}

/// [`coriolis_force`] in the six DOFs' order ([`Dof::index`]), zero in the
/// DOFs not modelled; nothing allocated (discovery evaluates it per RK4
/// stage of every k-step prediction).
pub fn coriolis_force6(dofs: &[Dof], m: &DMatrix<f64>, nu: &[f64]) -> [f64; 6] {
    let n = dofs.len();
    let ms = m.as_slice();
    let mut m6 = [[0.0; 6]; 6];
    let mut v6 = [0.0; 6];
    for (i, di) in dofs.iter().enumerate() {
        v6[di.index()] = nu[i];
        for (j, dj) in dofs.iter().enumerate() {
            // Column-major: M_ij at i + j·n.
            m6[di.index()][dj.index()] = 0.5 * (ms[i + j * n] + ms[j + i * n]);
        }
    }
    let a: [f64; 6] = std::array::from_fn(|i| (0..6).map(|j| m6[i][j] * v6[j]).sum());
    let cross = |x: [f64; 3], y: [f64; 3]| {
        [
            x[1] * y[2] - x[2] * y[1],
            x[2] * y[0] - x[0] * y[2],
            x[0] * y[1] - x[1] * y[0],
        ]
    };
    let (n1, n2) = ([v6[0], v6[1], v6[2]], [v6[3], v6[4], v6[5]]);
    let (a1, a2) = ([a[0], a[1], a[2]], [a[3], a[4], a[5]]);
    let lin = cross(n2, a1);
    let ang1 = cross(n1, a1);
    let ang2 = cross(n2, a2);
    [
        lin[0],
        lin[1],
        lin[2],
        ang1[0] + ang2[0],
        ang1[1] + ang2[1],
        ang1[2] + ang2[2],
    ]
}

/// The second-order part of C(ν)ν about straight-ahead motion at the
/// scheduled forward speed: C(δ)δ with δ = ν except u (the entry `surge`),
/// which the scheduling follows.
///
/// C(ν)ν is quadratic in ν, so with ν = ν₀ + δ about ν₀ = (u₀, 0, …, 0) it
/// is C(ν₀)ν₀ + J_C(u₀)δ + C(δ)δ. A sub-model linearized at u₀ holds the
/// first two in its load and D̄; blending sub-models linearly in u about
/// the measured u makes the u-products of the blend exact, leaving C(δ)δ —
/// the centripetal forces of a turning, heaving, rolling hull (the surge
/// force (M₂₂v + …)r of a turn) that no linear sub-model can carry. It adds
/// no parameter: M gives it (Fossen et al. 1995, eq. 11).
pub fn second_order_force(dofs: &[Dof], m: &DMatrix<f64>, nu: &[f64], surge: usize) -> Vec<f64> {
    let mut delta = nu.to_vec();
    delta[surge] = 0.0;
    coriolis_force(dofs, m, &delta)
}

/// C(δ)δ about the sub-model's own speed: δ = ν − (u₀, 0, …, 0). Blended
/// linearly in u between sub-models the (u − u₀)-products cancel, so
/// within the grid (and an extension) it equals [`second_order_force`];
/// where a sub-model is held — a single grid point, beyond the grid without
/// an extension, nearest scheduling — it adds the u-products (the Munk
/// moment (m_v − m_u)(u − u₀)v, the sway m_u(u − u₀)r) that no scheduling
/// then follows: with one grid point at u₀ = 0 (a DP vessel) it is the whole
/// C(ν)ν.
pub fn second_order_force_about(
    dofs: &[Dof],
    m: &DMatrix<f64>,
    nu: &[f64],
    surge: usize,
    u0: f64,
) -> Vec<f64> {
    let mut delta = nu.to_vec();
    delta[surge] -= u0;
    coriolis_force(dofs, m, &delta)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Diagonal M, δ = (0, v, 0, 0, 0, r): the only second-order force is
    /// the surge −m_v·v·r of a turning hull (Fossen 2011, eq. 6.43 with
    /// C(ν)ν on the left), and u plays no part.
    #[test]
    fn second_order_force_of_a_turn_is_the_surge_centripetal_term() {
        let m = DMatrix::from_diagonal(&DVector::from_vec(vec![
            300.0, 450.0, 500.0, 40.0, 60.0, 70.0,
        ]));
        let (v, r) = (0.3, 0.2);
        for u in [0.0, 1.7] {
            let f = second_order_force(&Dof::ALL, &m, &[u, v, 0.0, 0.0, 0.0, r], 0);
            assert!((f[0] + 450.0 * v * r).abs() < 1e-12, "surge {}", f[0]);
            for (i, x) in f.iter().enumerate().skip(1) {
                assert!(x.abs() < 1e-12, "DOF {i}: {x}");
            }
        }
        // The full C(ν)ν at u = 1.7 has the Munk moment (m_v − m_u)·u·v in
        // yaw and m_u·u·r in sway: those belong to the linear sub-models.
        let full = coriolis_force(&Dof::ALL, &m, &[1.7, v, 0.0, 0.0, 0.0, r]);
        assert!((full[1] - 300.0 * 1.7 * r).abs() < 1e-9);
        assert!((full[5] - (450.0 - 300.0) * 1.7 * v).abs() < 1e-9);
    }

    /// About u₀ = 0 the second-order force is the whole C(ν)ν; about the
    /// measured u it is C(δ)δ with δ = ν except u.
    #[test]
    fn second_order_force_about_a_speed() {
        let m3 =
            DMatrix::from_row_slice(3, 3, &[300.0, 0.0, 0.0, 0.0, 450.0, 20.0, 0.0, 20.0, 70.0]);
        let nu = [1.2, -0.4, 0.15];
        let full = coriolis_force(&Dof::HORIZONTAL, &m3, &nu);
        let about0 = second_order_force_about(&Dof::HORIZONTAL, &m3, &nu, 0, 0.0);
        let at_u = second_order_force_about(&Dof::HORIZONTAL, &m3, &nu, 0, 1.2);
        let scheduled = second_order_force(&Dof::HORIZONTAL, &m3, &nu, 0);
        for i in 0..3 {
            assert!((about0[i] - full[i]).abs() < 1e-12);
            assert!((at_u[i] - scheduled[i]).abs() < 1e-12);
        }
        // Linear blending in u of two sub-models cancels the u-products.
        let (u0, u1, w) = (1.0, 1.5, 0.6);
        let u = w * u0 + (1.0 - w) * u1;
        let nu = [u, -0.4, 0.15];
        let lo = second_order_force_about(&Dof::HORIZONTAL, &m3, &nu, 0, u0);
        let hi = second_order_force_about(&Dof::HORIZONTAL, &m3, &nu, 0, u1);
        let scheduled = second_order_force(&Dof::HORIZONTAL, &m3, &nu, 0);
        for i in 0..3 {
            assert!((w * lo[i] + (1.0 - w) * hi[i] - scheduled[i]).abs() < 1e-9);
        }
    }

    /// On a horizontal model (surge, sway, yaw) the embedding gives the
    /// 3-DOF C(ν)ν.
    #[test]
    fn horizontal_embedding_is_the_three_dof_form() {
        let m3 = Matrix3::new(300.0, 0.0, 0.0, 0.0, 450.0, 20.0, 0.0, 20.0, 70.0);
        let nu = Vector3::new(1.2, -0.4, 0.15);
        let want = coriolis_3dof(&m3, &nu) * nu;
        let got = coriolis_force(
            &[Dof::Surge, Dof::Sway, Dof::Yaw],
            &DMatrix::from_iterator(3, 3, m3.iter().copied()),
            nu.as_slice(),
        );
        for i in 0..3 {
            assert!(
                (got[i] - want[i]).abs() < 1e-9,
                "{i}: {} vs {}",
                got[i],
                want[i]
            );
        }
    }

    /// A coupled symmetric positive-definite M (ROV-like magnitudes).
    fn coupled_m() -> Matrix6<f64> {
        let mut m = Matrix6::from_diagonal(&Vector6::new(
            7500.0, 9000.0, 10000.0, 2500.0, 6000.0, 6500.0,
        ));
        for (i, j, v) in [
            (0, 2, -400.0),
            (0, 4, 900.0),
            (1, 3, -700.0),
            (1, 5, 350.0),
            (2, 4, 500.0),
        ] {
            m[(i, j)] = v;
            m[(j, i)] = v;
        }
        m
    }

    #[test]
    fn six_dof_c_is_skew_and_does_no_work() {
        let m = coupled_m();
        assert!(m.cholesky().is_some());
        let nus = [
            Vector6::new(1.2, -0.3, 0.2, 0.05, -0.1, 0.2),
            Vector6::new(-0.4, 0.8, -0.6, 0.3, 0.2, -0.25),
        ];
        for nu in nus {
            let c = coriolis_6dof(&m, &nu);
            let scale = c.amax();
            assert!(scale > 100.0, "C(ν) is not trivially zero");
            assert!((c + c.transpose()).amax() < 1e-12 * scale);
            let work = nu.dot(&(c * nu));
            assert!(work.abs() < 1e-12 * scale, "νᵀCν = {work}");
        }
        // Direct check of one entry: C[0][4] = −S(a)[0][1] = a_z where
        // a = M₁₁ν₁ + M₁₂ν₂.
        let nu = nus[0];
        let a = m.fixed_view::<3, 3>(0, 0) * nu.fixed_rows::<3>(0)
            + m.fixed_view::<3, 3>(0, 3) * nu.fixed_rows::<3>(3);
        let c = coriolis_6dof(&m, &nu);
        assert!((c[(0, 4)] - a.z).abs() < 1e-12);
        assert!((c[(1, 3)] + a.z).abs() < 1e-12);
    }

    #[test]
    fn three_dof_hand_computed_case() {
        // M = [[100, 0, 0], [0, 200, 30], [0, 30, 400]], ν = [2, 1, 0.5]:
        // a₁ = 100·2 = 200, a₂ = 200·1 + 30·0.5 = 215.
        let m = Matrix3::new(100.0, 0.0, 0.0, 0.0, 200.0, 30.0, 0.0, 30.0, 400.0);
        let nu = Vector3::new(2.0, 1.0, 0.5);
        let c = coriolis_3dof(&m, &nu);
        let want = Matrix3::new(0.0, 0.0, -215.0, 0.0, 0.0, 200.0, 215.0, -200.0, 0.0);
        assert_eq!(c, want);
        // C(ν)ν = [−215·0.5, 200·0.5, 215·2 − 200·1] = [−107.5, 100, 230].
        assert_eq!(c * nu, Vector3::new(-107.5, 100.0, 230.0));
        assert_eq!(nu.dot(&(c * nu)), 0.0);
        // The same numbers from the 6-DOF form restricted to (u, v, r).
        let mut m6 = Matrix6::identity();
        for (i, a) in [0usize, 1, 5].iter().enumerate() {
            for (j, b) in [0usize, 1, 5].iter().enumerate() {
                m6[(*a, *b)] = m[(i, j)];
            }
        }
        let c6 = coriolis_6dof(&m6, &Vector6::new(2.0, 1.0, 0.0, 0.0, 0.0, 0.5));
        for (i, a) in [0usize, 1, 5].iter().enumerate() {
            for (j, b) in [0usize, 1, 5].iter().enumerate() {
                assert_eq!(c6[(*a, *b)], c[(i, j)], "({a},{b})");
            }
        }
    }

    #[test]
    fn dynamic_front_end_checks_shapes() {
        let m = DMatrix::from_iterator(6, 6, coupled_m().iter().copied());
        let nu = DVector::from_vec(vec![1.0, 0.0, 0.0, 0.0, 0.0, 0.3]);
        let c = coriolis(&m, &nu).unwrap();
        // Surge–yaw: C[1][5] = (M₁₁ν₁ + M₁₂ν₂)_x = 7500·1 = 7500 (m₁₆ = 0).
        assert!((c[(1, 5)] - 7500.0).abs() < 1e-9);
        let err = coriolis(&DMatrix::zeros(4, 4), &DVector::zeros(4)).unwrap_err();
        assert!(err.to_string().starts_with("M is 4×4"), "{err}");
        let err = coriolis(&m, &DVector::zeros(3)).unwrap_err();
        assert!(err.to_string().starts_with("ν is 3×1"), "{err}");
        let mut bad = nu.clone();
        bad[2] = f64::NAN;
        assert!(matches!(
            coriolis(&m, &bad),
            Err(ModelError::NonFinite { .. })
        ));
    }
}
