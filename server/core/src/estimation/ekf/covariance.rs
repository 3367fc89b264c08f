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

/// Φ·P·Φᵀ + Q in place, blockwise. `phi_x[i]` is n × n, `phi_theta[i]` is
/// n × p; `q_x[i]` is run i's process-noise diagonal (n), `q_theta` θ's (p).
/// `at` is scratch of dim × (N·n).
#[allow(clippy::too_many_arguments)]
pub(crate) fn predict(
    p: &mut DMatrix<f64>,
    n: usize,
    phi_x: &[DMatrix<f64>],
    phi_theta: &[DMatrix<f64>],
    q_x: &[&[f64]],
    q_theta: &[f64],
    at: &mut DMatrix<f64>,
    phi_t: &mut (DMatrix<f64>, DMatrix<f64>),
) {
    let runs = phi_x.len();
    let off = runs * n;
    let np = p.nrows() - off;
    // (P·Φᵀ)[:, run i], from the old P.
    for i in 0..runs {
        phi_x[i].transpose_to(&mut phi_t.0);
        phi_theta[i].transpose_to(&mut phi_t.1);
        let mut a = at.columns_mut(i * n, n);
        a.gemm(1.0, &p.columns(i * n, n), &phi_t.0, 0.0);
        if np > 0 {
            a.gemm(1.0, &p.columns(off, np), &phi_t.1, 1.0);
        }
    }
    for i in 0..runs {
        // θ rows and columns of run i.
        for c in 0..n {
            for r in 0..np {
                let v = at[(off + r, i * n + c)];
                p[(off + r, i * n + c)] = v;
                p[(i * n + c, off + r)] = v;
            }
        }
        // Run blocks j ≥ i, mirrored to (i, j).
        for j in i..runs {
            let mut blk = phi_x[j].clone() * at.view((j * n, i * n), (n, n));
            if np > 0 {
                blk.gemm(1.0, &phi_theta[j], &at.view((off, i * n), (np, n)), 1.0);
            }
            if i == j {
                // Φ·P·Φᵀ is symmetric; rounding is split evenly.
                let t = blk.transpose();
                blk += t;
                blk *= 0.5;
            }
            for c in 0..n {
                for r in 0..n {
                    let v = blk[(r, c)];
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
/// with W = K·S/2 − U; see the module doc). `k` and `w` are dim × M.
pub(crate) fn symmetric_rank2_update(p: &mut DMatrix<f64>, k: &DMatrix<f64>, w: &DMatrix<f64>) {
    let dim = p.nrows();
    let m = k.ncols();
    let ks = k.as_slice();
    let ws = w.as_slice();
    let ps = p.as_mut_slice();
    for c in 0..dim {
        let col = &mut ps[c * dim..c * dim + c + 1];
        for l in 0..m {
            let kc = ks[l * dim + c];
            let wc = ws[l * dim + c];
            let kl = &ks[l * dim..l * dim + c + 1];
            let wl = &ws[l * dim..l * dim + c + 1];
            for ((pr, &kr), &wr) in col.iter_mut().zip(kl).zip(wl) {
                *pr += kr * wc + wr * kc;
            }
        }
    }
    for c in 0..dim {
        for r in 0..c {
            ps[r * dim + c] = ps[c * dim + r];
        }
    }
}
