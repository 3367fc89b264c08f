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

/// y += a·x on contiguous columns (vectorizes).
#[inline]
pub(crate) fn axpy(y: &mut [f64], a: f64, x: &[f64]) {
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi += a * xi;
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
    let runs = phi_x.len();
    let dim = p.nrows();
    let off = runs * n;
    let np = dim - off;
    // (P·Φᵀ)[:, run i] = P[:, run i]·Φ_ixᵀ + P[:, θ]·Φ_iθᵀ, from the old P,
    // column by column as sums of P's (contiguous) columns.
    {
        let ps = p.as_slice();
        let ats = at.as_mut_slice();
        for i in 0..runs {
            for c in 0..n {
                let col = &mut ats[(i * n + c) * dim..(i * n + c + 1) * dim];
                col.fill(0.0);
                for l in 0..n {
                    let a = phi_x[i][(c, l)];
                    if a != 0.0 {
                        axpy(col, a, &ps[(i * n + l) * dim..(i * n + l + 1) * dim]);
                    }
                }
                for l in 0..np {
                    let a = phi_theta[i][(c, l)];
                    if a != 0.0 {
                        axpy(col, a, &ps[(off + l) * dim..(off + l + 1) * dim]);
                    }
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
    let dim = p.nrows();
    let m = k.ncols().min(w.ncols());
    let ks = k.as_slice();
    let ws = w.as_slice();
    let ps = p.as_mut_slice();
    let kcol = |l: usize, len: usize| &ks[l * dim..l * dim + len];
    let wcol = |l: usize, len: usize| &ws[l * dim..l * dim + len];
    for c in 0..dim {
        let len = c + 1;
        let col = &mut ps[c * dim..c * dim + len];
        let mut l = 0;
        while l + 3 <= m {
            let (k0, k1, k2) = (kcol(l, len), kcol(l + 1, len), kcol(l + 2, len));
            let (w0, w1, w2) = (wcol(l, len), wcol(l + 1, len), wcol(l + 2, len));
            let (a0, a1, a2) = (
                ws[l * dim + c],
                ws[(l + 1) * dim + c],
                ws[(l + 2) * dim + c],
            );
            let (b0, b1, b2) = (
                ks[l * dim + c],
                ks[(l + 1) * dim + c],
                ks[(l + 2) * dim + c],
            );
            for r in 0..len {
                col[r] +=
                    k0[r] * a0 + w0[r] * b0 + k1[r] * a1 + w1[r] * b1 + k2[r] * a2 + w2[r] * b2;
            }
            l += 3;
        }
        while l < m {
            let (kc, wc) = (ks[l * dim + c], ws[l * dim + c]);
            axpy(col, wc, kcol(l, len));
            axpy(col, kc, wcol(l, len));
            l += 1;
        }
    }
    for c in 0..dim {
        for r in 0..c {
            ps[r * dim + c] = ps[c * dim + r];
        }
    }
}
