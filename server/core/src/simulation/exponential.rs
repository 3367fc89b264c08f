//! Fourth-order exponential time differencing (Cox & Matthews 2002,
//! "ETDRK4", in the φ-function form of Hochbruck & Ostermann 2010, Acta
//! Numerica, sec. 2.3) for ẋ = L·x + N(x, u) where a linear part L acts on
//! the first `n` states: the linear modes are integrated exactly, however
//! fast, and only N is sampled at the stages.
//!
//! A fitted vessel model whose M⁻¹D̄ has a mode of 10³ s⁻¹ would need
//! hundreds of RK4 sub-steps per 0.1 s sample to stay stable; ETDRK4 takes
//! one, and in the fast direction it lands on the quasi-static value
//! N/|λ| (stiffly accurate in that limit). On states without a linear part
//! (L = 0) it is the classical RK4, stage for stage.

use nalgebra::DMatrix;

use super::integrate::with_stages;

/// The step's matrix functions of Z = h·L (the φ_k of Hochbruck &
/// Ostermann: φ₁(z) = (e^z − 1)/z, φ₂(z) = (e^z − 1 − z)/z², φ₃(z) =
/// (e^z − 1 − z − z²/2)/z³), computed from exponentials of block matrices
/// (exp([[Z, I, 0], [0, 0, I], [0, 0, 0]]) has e^Z, φ₁(Z), φ₂(Z) in its
/// first block row; Higham 2008, Functions of Matrices, thm. 10.30 / eq. 10.40).
#[derive(Debug, Clone)]
pub struct EtdRk4 {
    n: usize,
    h: f64,
    /// e^{Z/2}.
    e_half: DMatrix<f64>,
    /// (h/2)·φ₁(Z/2).
    f_half: DMatrix<f64>,
    /// e^Z.
    e_full: DMatrix<f64>,
    /// h·(φ₁ − 3φ₂ + 4φ₃)(Z).
    b1: DMatrix<f64>,
    /// h·(2φ₂ − 4φ₃)(Z).
    b23: DMatrix<f64>,
    /// h·(4φ₃ − φ₂)(Z).
    b4: DMatrix<f64>,
}

/// exp of [[Z, I, 0, …], [0, 0, I, …], …, [0, …, 0]] with `k` identity
/// blocks: its first block row is e^Z, φ₁(Z), …, φ_k(Z).
fn phi_functions(z: &DMatrix<f64>, k: usize) -> Vec<DMatrix<f64>> {
    let n = z.nrows();
    let mut big = DMatrix::zeros((k + 1) * n, (k + 1) * n);
    big.view_mut((0, 0), (n, n)).copy_from(z);
    for b in 0..k {
        for i in 0..n {
            big[(b * n + i, (b + 1) * n + i)] = 1.0;
        }
    }
    let e = big.exp();
    (0..=k)
        .map(|b| e.view((0, b * n), (n, n)).into_owned())
        .collect()
}

impl EtdRk4 {
    /// The coefficients of steps of `h` for the linear part `l` (square,
    /// finite).
    pub fn new(l: &DMatrix<f64>, h: f64) -> Self {
        let z = l * h;
        let full = phi_functions(&z, 3);
        let half = phi_functions(&(&z * 0.5), 1);
        let (p1, p2, p3) = (&full[1], &full[2], &full[3]);
        EtdRk4 {
            n: l.nrows(),
            h,
            e_half: half[0].clone(),
            f_half: &half[1] * (0.5 * h),
            e_full: full[0].clone(),
            b1: (p1 - p2 * 3.0 + p3 * 4.0) * h,
            b23: (p2 * 2.0 - p3 * 4.0) * h,
            b4: (p3 * 4.0 - p2) * h,
        }
    }

    /// One step of ẋ = L·x[..n] + N(x, u) over h with `u` held. `nl(x, u,
    /// dx)` writes N (the derivative without L·x) into `dx`.
    pub fn step<F>(&self, nl: &mut F, x: &mut [f64], u: &[f64])
    where
        F: FnMut(&[f64], &[f64], &mut [f64]),
    {
        let m = x.len();
        assert!(self.n <= m, "the linear part acts on the first states");
        with_stages(9 * m, |buf| self.stages(nl, x, u, buf));
    }

    fn stages<F>(&self, nl: &mut F, x: &mut [f64], u: &[f64], buf: &mut [f64])
    where
        F: FnMut(&[f64], &[f64], &mut [f64]),
    {
        let (m, n, h) = (x.len(), self.n, self.h);
        let (n_u, rest) = buf.split_at_mut(m);
        let (n_a, rest) = rest.split_at_mut(m);
        let (n_b, rest) = rest.split_at_mut(m);
        let (n_c, rest) = rest.split_at_mut(m);
        let (a, rest) = rest.split_at_mut(m);
        let (b, rest) = rest.split_at_mut(m);
        let (c, w) = rest.split_at_mut(m);
        let (w, next) = w.split_at_mut(m);
        // y = P·x[..n] + Q·v[..n] on the linear block, x + q·v beyond it.
        let combine = |out: &mut [f64],
                       p: &DMatrix<f64>,
                       x: &[f64],
                       q: &DMatrix<f64>,
                       v: &[f64],
                       q_scalar: f64| {
            for i in 0..n {
                let mut s = 0.0;
                for j in 0..n {
                    s += p[(i, j)] * x[j] + q[(i, j)] * v[j];
                }
                out[i] = s;
            }
            for i in n..m {
                out[i] = x[i] + q_scalar * v[i];
            }
        };
        nl(x, u, n_u);
        combine(a, &self.e_half, x, &self.f_half, n_u, 0.5 * h);
        nl(a, u, n_a);
        combine(b, &self.e_half, x, &self.f_half, n_a, 0.5 * h);
        nl(b, u, n_b);
        for ((wi, nb), nu) in w.iter_mut().zip(n_b.iter()).zip(n_u.iter()) {
            *wi = 2.0 * nb - nu;
        }
        combine(c, &self.e_half, a, &self.f_half, w, 0.5 * h);
        nl(c, u, n_c);
        for (i, out) in next.iter_mut().enumerate() {
            *out = if i < n {
                (0..n)
                    .map(|j| {
                        self.e_full[(i, j)] * x[j]
                            + self.b1[(i, j)] * n_u[j]
                            + self.b23[(i, j)] * (n_a[j] + n_b[j])
                            + self.b4[(i, j)] * n_c[j]
                    })
                    .sum()
            } else {
                x[i] + h / 6.0 * (n_u[i] + 2.0 * (n_a[i] + n_b[i]) + n_c[i])
            };
        }
        x.copy_from_slice(next);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simulation::integrate::rk4_step;

    fn phi(z: f64) -> [f64; 4] {
        let e = z.exp();
        [
            e,
            (e - 1.0) / z,
            (e - 1.0 - z) / (z * z),
            (e - 1.0 - z - z * z / 2.0) / (z * z * z),
        ]
    }

    #[test]
    fn block_exponentials_give_the_scalar_phi_functions() {
        let z = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![-0.3, -2.0, -40.0]));
        let got = phi_functions(&z, 3);
        for (i, &zi) in [-0.3, -2.0, -40.0].iter().enumerate() {
            let want = phi(zi);
            for k in 0..4 {
                let rel = (got[k][(i, i)] - want[k]).abs() / want[k].abs();
                assert!(rel < 1e-12, "φ{k}({zi}): {} vs {}", got[k][(i, i)], want[k]);
            }
        }
    }

    /// ẋ = −λx + c: exact for constant forcing at any stiffness (the
    /// fast limit is the quasi-static c/λ), where RK4 with one step
    /// explodes.
    #[test]
    fn a_stiff_linear_mode_with_constant_forcing_is_exact() {
        let (c, h) = (3.0, 0.1);
        for lambda in [0.5, 20.0, 2500.0] {
            let etd = EtdRk4::new(&DMatrix::from_element(1, 1, -lambda), h);
            let mut x = [1.0];
            for k in 1..=50 {
                etd.step(
                    &mut |_x: &[f64], _u: &[f64], dx: &mut [f64]| dx[0] = c,
                    &mut x,
                    &[],
                );
                let t = k as f64 * h;
                let exact = c / lambda + (1.0 - c / lambda) * (-lambda * t).exp();
                assert!(
                    (x[0] - exact).abs() < 1e-12 * exact.abs().max(1.0),
                    "λ={lambda} k={k}: {} vs {exact}",
                    x[0]
                );
            }
        }
        let mut y = [1.0];
        for _ in 0..50 {
            rk4_step(
                &mut |x: &[f64], _u: &[f64], dx: &mut [f64]| dx[0] = -2500.0 * x[0] + c,
                &mut y,
                &[],
                h,
            );
        }
        assert!(
            y[0].is_nan() || y[0].abs() > 1e10,
            "one RK4 step per sample is unstable at λh = 250"
        );
    }

    /// x = [ν1, ν2, t]: ν̇ = L ν + [sin t, 0], ṫ = 1, from h = 0.1 and 0.05
    /// against many small RK4 steps: the errors at h and h/2.
    fn errors(l: &DMatrix<f64>) -> (f64, f64) {
        let rhs = |x: &[f64], dx: &mut [f64]| {
            dx[0] = x[2].sin();
            dx[1] = 0.0;
            dx[2] = 1.0;
        };
        let t_end = 2.0;
        let mut reference = [0.2, -0.1, 0.0];
        let fine = 200_000;
        for _ in 0..fine {
            rk4_step(
                &mut |x: &[f64], _u: &[f64], dx: &mut [f64]| {
                    rhs(x, dx);
                    dx[0] += l[(0, 0)] * x[0] + l[(0, 1)] * x[1];
                    dx[1] += l[(1, 0)] * x[0] + l[(1, 1)] * x[1];
                },
                &mut reference,
                &[],
                t_end / fine as f64,
            );
        }
        let err = |steps: usize| {
            let etd = EtdRk4::new(l, t_end / steps as f64);
            let mut x = [0.2, -0.1, 0.0];
            for _ in 0..steps {
                etd.step(
                    &mut |x: &[f64], _u: &[f64], dx: &mut [f64]| rhs(x, dx),
                    &mut x,
                    &[],
                );
            }
            (x[0] - reference[0]).abs().max((x[1] - reference[1]).abs())
        };
        (err(20), err(40))
    }

    /// Slow coupled modes: fourth order (halving h cuts the error ~16×).
    #[test]
    fn slow_coupled_modes_converge_at_fourth_order() {
        let (e1, e2) = errors(&DMatrix::from_row_slice(2, 2, &[-0.8, 0.4, 0.1, -1.5]));
        assert!(e1 < 1e-6, "error {e1}");
        assert!(e1 / e2 > 12.0, "order: {e1} → {e2}");
    }

    /// A stiff coupled pair (a mode of 300 s⁻¹ at h = 0.1 s): stable and
    /// accurate to 10⁻⁸, converging at the reduced order ≥ 2 that
    /// Hochbruck & Ostermann (2005) prove for Cox–Matthews in the stiff
    /// limit.
    #[test]
    fn a_stiff_coupled_pair_stays_accurate() {
        let (e1, e2) = errors(&DMatrix::from_row_slice(2, 2, &[-300.0, 40.0, 10.0, -1.5]));
        assert!(e1 < 1e-8, "error {e1}");
        assert!(e1 / e2 > 3.5, "order: {e1} → {e2}");
    }

    /// Without a linear part the step is RK4's, stage for stage.
    #[test]
    fn without_a_linear_part_it_is_rk4() {
        let f = |x: &[f64], _u: &[f64], dx: &mut [f64]| {
            dx[0] = x[1];
            dx[1] = -x[0].sin();
        };
        let etd = EtdRk4::new(&DMatrix::zeros(0, 0), 0.1);
        let (mut a, mut b) = ([1.0, 0.3], [1.0, 0.3]);
        for _ in 0..100 {
            etd.step(&mut { f }, &mut a, &[]);
            rk4_step(&mut { f }, &mut b, &[], 0.1);
        }
        assert!((a[0] - b[0]).abs() < 1e-13 && (a[1] - b[1]).abs() < 1e-13);
    }
}
