//! Blockwise covariance algebra of the parallel augmented EKF.
//!
//! The augmented state is ξ = [x_1; …; x_N; θ] (eq. 22–24), dim Nn + p. Its
//! transition Jacobian Φ (Table 1) is block-sparse: run i's rows are
//! [0 … Φ_ix … 0 Φ_iθ] and the θ rows are [0 … 0 I]. So Φ·P·Φᵀ never needs a
//! dense (Nn+p)³ product:
//!
//! - (P·Φᵀ)[:, run i] = P[:, run i]·Φ_ixᵀ + P[:, θ]·Φ_iθᵀ  (dim × n each),
//! - P⁺[θ, θ] = P[θ, θ]; P⁺[θ, run i] = (P·Φᵀ)[θ, run i],
//! - P⁺[run j, run i] = Φ_jx·(P·Φᵀ)[run j, run i] + Φ_jθ·(P·Φᵀ)[θ, run i].
//!
//! The cross-run blocks P[run j, run i] are kept: the runs are independent
//! given θ, but once θ is estimated from all of them their errors correlate.
//! The result is exactly Table 1's Φ·P·Φᵀ, at 2·N·n·(n+p)·dim flops instead
//! of 2·dim³.
//!
//! The measurement update is Table 1's Joseph form
//! P⁺ = (I − K·H)·P·(I − K·H)ᵀ + K·R·Kᵀ, expanded with U = P·Hᵀ and
//! S = H·U + R into the symmetric rank-2m update
//! P⁺ = P + K·Wᵀ + W·Kᵀ with W = K·S/2 − U — the same value for any gain K,
//! computed on one triangle and mirrored, so P stays exactly symmetric.

use nalgebra::DMatrix;

use crate::kernels::{has_avx2_fma, madd};

/// y += a·x on contiguous columns (vectorizes).
#[inline(always)]
pub(crate) fn axpy<const FMA: bool>(y: &mut [f64], a: f64, x: &[f64]) {
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi = madd::<FMA>(a, *xi, *yi);
    }
}

/// Φ·P·Φᵀ + Q in place, blockwise. `phi_x[i]` is n × n, `phi_theta[i]` is
/// n × p; `q_x[i]` is run i's process-noise diagonal (n), `q_theta` θ's (p).
/// `at` is scratch of dim × (N·n). Zero entries of Φ are skipped: a model's
/// Φ_θ is often sparse (each state depends on a few parameters).
pub(crate) fn predict(
    p: &mut DMatrix<f64>,
    n: usize,
    phi_x: &[DMatrix<f64>],
    phi_theta: &[DMatrix<f64>],
    q_x: &[&[f64]],
    q_theta: &[f64],
    at: &mut DMatrix<f64>,
) {
    #[cfg(target_arch = "x86_64")]
    if has_avx2_fma() {
        // SAFETY: the CPU has the features the function is compiled for.
        return unsafe { predict_avx2(p, n, phi_x, phi_theta, q_x, q_theta, at) };
    }
    predict_body::<false>(p, n, phi_x, phi_theta, q_x, q_theta, at)
}

/// [`predict`] compiled for AVX2 and FMA (equal to the plain one to
/// rounding).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn predict_avx2(
    p: &mut DMatrix<f64>,
    n: usize,
    phi_x: &[DMatrix<f64>],
    phi_theta: &[DMatrix<f64>],
    q_x: &[&[f64]],
    q_theta: &[f64],
    at: &mut DMatrix<f64>,
) {
    predict_body::<true>(p, n, phi_x, phi_theta, q_x, q_theta, at)
}

#[inline(always)]
fn predict_body<const FMA: bool>(
    p: &mut DMatrix<f64>,
    n: usize,
    phi_x: &[DMatrix<f64>],
    phi_theta: &[DMatrix<f64>],
    q_x: &[&[f64]],
    q_theta: &[f64],
    at: &mut DMatrix<f64>,
) {
    let runs = phi_x.len();
    let dim = p.nrows();
    let off = runs * n;
    let np = dim - off;
    // (P·Φᵀ)[:, run i] = P[:, run i]·Φ_ixᵀ + P[:, θ]·Φ_iθᵀ, from the old P,
    // column by column as sums of P's (contiguous) columns.
    {
        let ps = p.as_slice();
        let ats = at.as_mut_slice();
        // (coefficient, first index of P's column) of every nonzero term.
        let mut terms: Vec<(f64, usize)> = Vec::with_capacity(n + np);
        for i in 0..runs {
            for c in 0..n {
                terms.clear();
                terms.extend(
                    (0..n)
                        .map(|l| (phi_x[i][(c, l)], (i * n + l) * dim))
                        .chain((0..np).map(|l| (phi_theta[i][(c, l)], (off + l) * dim)))
                        .filter(|&(a, _)| a != 0.0),
                );
                let col = &mut ats[(i * n + c) * dim..(i * n + c + 1) * dim];
                // Rows in chunks held in registers across all terms: one
                // store per chunk instead of one per term.
                let mut r0 = 0;
                while r0 + ROWS <= dim {
                    let mut acc = [0.0f64; ROWS];
                    for &(a, start) in &terms {
                        let src: &[f64; ROWS] =
                            ps[start + r0..start + r0 + ROWS].try_into().unwrap();
                        for (v, x) in acc.iter_mut().zip(src) {
                            *v = madd::<FMA>(a, *x, *v);
                        }
                    }
                    col[r0..r0 + ROWS].copy_from_slice(&acc);
                    r0 += ROWS;
                }
                let tail = &mut col[r0..];
                tail.fill(0.0);
                for &(a, start) in &terms {
                    axpy::<FMA>(tail, a, &ps[start + r0..start + dim]);
                }
            }
        }
    }
    let mut blk = vec![0.0; n * n];
    let phi_tt: Vec<Vec<f64>> = phi_theta
        .iter()
        .map(|f| {
            let mut t = vec![0.0; n * np];
            for r in 0..n {
                for l in 0..np {
                    t[r * np + l] = f[(r, l)];
                }
            }
            t
        })
        .collect();
    for i in 0..runs {
        // θ rows and columns of run i.
        for c in 0..n {
            for r in 0..np {
                let v = at[(off + r, i * n + c)];
                p[(off + r, i * n + c)] = v;
                p[(i * n + c, off + r)] = v;
            }
        }
        // Run blocks j ≥ i, mirrored to (i, j):
        // P⁺[j, i] = Φ_jx·(PΦᵀ)[run j, run i] + Φ_jθ·(PΦᵀ)[θ, run i].
        for j in i..runs {
            for c in 0..n {
                let a_col = &at.as_slice()[(i * n + c) * dim..(i * n + c + 1) * dim];
                let a_theta = &a_col[off..];
                for r in 0..n {
                    let mut v = 0.0;
                    for l in 0..n {
                        v += phi_x[j][(r, l)] * a_col[j * n + l];
                    }
                    // Row r of Φ_jθ, made contiguous in `phi_tt`.
                    let row = &phi_tt[j][r * np..(r + 1) * np];
                    v += row.iter().zip(a_theta).map(|(f, a)| f * a).sum::<f64>();
                    blk[c * n + r] = v;
                }
            }
            for c in 0..n {
                for r in 0..n {
                    // Φ·P·Φᵀ is symmetric: on diagonal blocks rounding is
                    // split evenly.
                    let v = if i == j {
                        0.5 * (blk[c * n + r] + blk[r * n + c])
                    } else {
                        blk[c * n + r]
                    };
                    p[(j * n + r, i * n + c)] = v;
                    p[(i * n + c, j * n + r)] = v;
                }
            }
        }
    }
    for (i, q) in q_x.iter().enumerate() {
        for (c, &v) in q.iter().enumerate() {
            p[(i * n + c, i * n + c)] += v;
        }
    }
    for (c, &v) in q_theta.iter().enumerate() {
        p[(off + c, off + c)] += v;
    }
}

/// P ← P + K·Wᵀ + W·Kᵀ on the upper triangle, then mirrored (the Joseph form
/// with W = K·S/2 − U; see the module doc). `k` and `w` are dim × M. Columns
/// of K and W are taken three at a time so each column of P is loaded and
/// stored once per six products.
pub(crate) fn symmetric_rank2_update(p: &mut DMatrix<f64>, k: &DMatrix<f64>, w: &DMatrix<f64>) {
    #[cfg(target_arch = "x86_64")]
    if has_avx2_fma() {
        // SAFETY: the CPU has the features the function is compiled for.
        return unsafe { symmetric_rank2_update_avx2(p, k, w) };
    }
    symmetric_rank2_update_body::<false>(p, k, w)
}

/// [`symmetric_rank2_update`] compiled for AVX2 and FMA (equal to rounding).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn symmetric_rank2_update_avx2(p: &mut DMatrix<f64>, k: &DMatrix<f64>, w: &DMatrix<f64>) {
    symmetric_rank2_update_body::<true>(p, k, w)
}

/// Rows of P·Φᵀ accumulated in registers at once.
const ROWS: usize = 16;

/// Rows and columns of one register block of the update.
const RB: usize = 8;
const CB: usize = 4;

#[inline(always)]
fn symmetric_rank2_update_body<const FMA: bool>(
    p: &mut DMatrix<f64>,
    k: &DMatrix<f64>,
    w: &DMatrix<f64>,
) {
    let dim = p.nrows();
    let m = k.ncols().min(w.ncols());
    let ks = k.as_slice();
    let ws = w.as_slice();
    let ps = p.as_mut_slice();
    // Blocks of RB rows × CB columns on and above the diagonal, each summed
    // over all M products in registers before one add to P (the lower
    // entries of diagonal blocks are overwritten by the mirror below).
    for c0 in (0..dim).step_by(CB) {
        let cw = CB.min(dim - c0);
        let rows = c0 + cw;
        let full = rows / RB * RB;
        for r0 in (0..full).step_by(RB) {
            let mut acc = [[0.0f64; RB]; CB];
            for l in 0..m {
                let kr: &[f64; RB] = ks[l * dim + r0..l * dim + r0 + RB].try_into().unwrap();
                let wr: &[f64; RB] = ws[l * dim + r0..l * dim + r0 + RB].try_into().unwrap();
                for (cc, a) in acc.iter_mut().enumerate().take(cw) {
                    let (wc, kc) = (ws[l * dim + c0 + cc], ks[l * dim + c0 + cc]);
                    for rr in 0..RB {
                        a[rr] = madd::<FMA>(kr[rr], wc, madd::<FMA>(wr[rr], kc, a[rr]));
                    }
                }
            }
            for (cc, a) in acc.iter().enumerate().take(cw) {
                let col = &mut ps[(c0 + cc) * dim + r0..(c0 + cc) * dim + r0 + RB];
                for (pv, v) in col.iter_mut().zip(a) {
                    *pv += v;
                }
            }
        }
        for c in c0..rows {
            for r in full..=c {
                let mut v = 0.0;
                for l in 0..m {
                    let (kr, wr) = (ks[l * dim + r], ws[l * dim + r]);
                    v = madd::<FMA>(kr, ws[l * dim + c], madd::<FMA>(wr, ks[l * dim + c], v));
                }
                ps[c * dim + r] += v;
            }
        }
    }
    for c in 0..dim {
        for r in 0..c {
            ps[r * dim + c] = ps[c * dim + r];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;

    #[test]
    fn rank2_update_is_p_plus_k_wt_plus_w_kt() {
        let mut rng = SplitMix64::new(9);
        for (dim, m) in [(1usize, 1usize), (5, 2), (8, 3), (13, 6), (54, 6), (61, 12)] {
            let a = DMatrix::from_fn(dim, dim, |_, _| rng.normal());
            let p0 = &a * a.transpose();
            let k = DMatrix::from_fn(dim, m, |_, _| rng.normal());
            let w = DMatrix::from_fn(dim, m, |_, _| rng.normal());
            let want = &p0 + &k * w.transpose() + &w * k.transpose();
            for fma in [false, true] {
                let mut p = p0.clone();
                if fma {
                    symmetric_rank2_update(&mut p, &k, &w);
                } else {
                    symmetric_rank2_update_body::<false>(&mut p, &k, &w);
                }
                let err = (&p - &want).amax() / want.amax();
                assert!(err < 1e-14, "dim {dim} m {m}: {err:e}");
                assert_eq!(p, p.transpose(), "dim {dim}: exactly symmetric");
            }
        }
    }
}
