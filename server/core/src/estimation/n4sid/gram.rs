//! The Gram matrix H Hᵀ of the block-Hankel data from lagged
//! cross-products, and its Cholesky factor when H is well conditioned.
//!
//! Every row of H = [U_f; U_p; Y_p; Y_f] is one channel x_c delayed by a
//! lag k < 2i, so an entry of the Gram matrix is a lagged cross-product
//!
//!   G[(a, k₁), (b, k₂)] = Σ_{t=0}^{j−1} x_a(t + k₁) x_b(t + k₂)
//!                        = Σ_{s=k₁}^{k₁+j−1} x_a(s) x_b(s + d),  d = k₂ − k₁.
//!
//! All windows s ∈ [k₁, k₁ + j − 1] share the core s ∈ [2i − 1, j − 1], so
//! per channel pair (a, b) and lag d one dot product over the core serves
//! every (k₁, k₂) with k₂ − k₁ = d; each entry adds fewer than 2i head and
//! tail terms. Cost (m + l)²(4i − 1) j multiply–adds instead of the
//! (2i(m + l))² j / 2 of a plain syrk and the 2 (2i(m + l))² j of the
//! Householder QR: 20× and 80× less for i = 10, m = l = 6.
//!
//! Squaring H squares its condition number (see [`super::hankel`]): the
//! Cholesky factor is used only when its diagonal spread
//! max L_kk / min L_kk is below [`MAX_SPREAD`], where the Gram route's
//! relative error in the weakest direction, ε · spread², stays below 1e-8;
//! otherwise (noise-free or nearly collinear data) the caller falls back to
//! the QR.

use nalgebra::DMatrix;

use super::error::N4sidError;
use super::hankel::{Layout, column};
use crate::estimation::{Cancelled, Progress};
use crate::kernels::lagged_dots;

/// Largest accepted max L_kk / min L_kk of the Cholesky factor.
pub(crate) const MAX_SPREAD: f64 = 1e4;

/// Core samples per block: the block of every channel stays in L1/L2
/// while all channel pairs and lags sweep it.
const BLOCK: usize = 1024;

/// H Hᵀ (r × r) over all experiments, channels multiplied by their inverse
/// scales (u then y).
pub(crate) fn hankel_gram(
    experiments: &[(&DMatrix<f64>, &DMatrix<f64>)],
    inv_u: &[f64],
    inv_y: &[f64],
    layout: Layout,
    progress: &mut dyn Progress,
) -> Result<DMatrix<f64>, N4sidError> {
    let r = layout.rows();
    let w = 2 * layout.i;
    let nch = layout.m + layout.l;
    let row = |c: usize, k: usize| {
        if c < layout.m {
            layout.u_row(k, c)
        } else {
            layout.y_row(k, c - layout.m)
        }
    };
    let scale: Vec<f64> = inv_u.iter().chain(inv_y).copied().collect();
    let total: usize = experiments.iter().map(|(u, _)| u.nrows()).sum();
    let mut g = DMatrix::<f64>::zeros(r, r);
    let mut done = 0usize;
    let nd = 2 * w - 1; // lags d = −(w − 1) ..= w − 1
    for (u, y) in experiments {
        let n = u.nrows();
        let j = n + 1 - w;
        let x: Vec<&[f64]> = (0..layout.m)
            .map(|c| column(u, c))
            .chain((0..layout.l).map(|c| column(y, c)))
            .collect();
        // core[(a · nch + b) · nd + d + w − 1] = Σ_{s ∈ core} x_a(s) x_b(s + d).
        let (cs, ce) = (w - 1, j.max(w - 1));
        let mut core = vec![0.0; nch * nch * nd];
        let mut s0 = cs;
        while s0 < ce {
            let s1 = (s0 + BLOCK).min(ce);
            for a in 0..nch {
                let xa = &x[a][s0..s1];
                for b in a..nch {
                    let xb = &x[b][s0 + 1 - w..s1 + w - 1];
                    let out = &mut core[(a * nch + b) * nd..(a * nch + b + 1) * nd];
                    lagged_dots(xa, xb, out);
                }
            }
            done += s1 - s0;
            s0 = s1;
            progress
                .update(
                    done as f64 / total as f64,
                    "Gram matrix of the block-Hankel data",
                )
                .map_err(|Cancelled| N4sidError::Cancelled)?;
        }
        done += n - (ce - cs);
        for a in 0..nch {
            for b in a..nch {
                let (xa, xb) = (x[a], x[b]);
                let pair = &core[(a * nch + b) * nd..(a * nch + b + 1) * nd];
                for k1 in 0..w {
                    // For a = b the mirror entry (k₂, k₁) is the same sum.
                    let k2_from = if a == b { k1 } else { 0 };
                    for k2 in k2_from..w {
                        let d = k2 as isize - k1 as isize;
                        let mut sum = pair[(d + w as isize - 1) as usize];
                        // Head s ∈ [k₁, w − 2] and tail s ∈ [j, k₁ + j − 1] of
                        // the window (all of it when the core is empty).
                        let head_end = (w - 1).min(k1 + j);
                        let tail_start = j.max(head_end);
                        for s in (k1..head_end).chain(tail_start..k1 + j) {
                            sum += xa[s] * xb[(s as isize + d) as usize];
                        }
                        let (ra, rb) = (row(a, k1), row(b, k2));
                        g[(ra, rb)] += sum;
                        if ra != rb {
                            g[(rb, ra)] += sum;
                        }
                    }
                }
            }
        }
    }
    for p in 0..r {
        let (ca, _) = channel_of(layout, p);
        for q in 0..r {
            let (cb, _) = channel_of(layout, q);
            g[(p, q)] *= scale[ca] * scale[cb];
        }
    }
    Ok(g)
}

/// The channel (u first, then y) and lag of row `p` of H.
fn channel_of(layout: Layout, p: usize) -> (usize, usize) {
    let (mi, li) = (layout.mi(), layout.li());
    if p < mi {
        (p % layout.m, layout.i + p / layout.m)
    } else if p < 2 * mi {
        ((p - mi) % layout.m, (p - mi) / layout.m)
    } else if p < 2 * mi + li {
        let q = p - 2 * mi;
        (layout.m + q % layout.l, q / layout.l)
    } else {
        let q = p - 2 * mi - li;
        (layout.m + q % layout.l, layout.i + q / layout.l)
    }
}

/// The Cholesky factor L of the Gram matrix (G = L Lᵀ, so H = L Qᵀ for
/// some Q with orthonormal columns), or `None` when G is not positive
/// definite or L's diagonal spread exceeds [`MAX_SPREAD`].
pub(crate) fn well_conditioned_cholesky(g: DMatrix<f64>) -> Option<DMatrix<f64>> {
    let l = g.cholesky()?.unpack();
    let diag = l.diagonal();
    let (lo, hi) = (diag.min(), diag.max());
    (lo > 0.0 && hi / lo <= MAX_SPREAD).then_some(l)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::estimation::NoProgress;
    use crate::estimation::n4sid::hankel::dense_hankel;
    use crate::rng::SplitMix64;

    #[test]
    fn gram_equals_the_dense_hankel_product() {
        let mut rng = SplitMix64::new(7);
        // Runs shorter than, equal to and longer than 2i windows, and past
        // one core block; two layouts.
        for (layout, lens) in [
            (Layout { m: 2, l: 3, i: 3 }, vec![6usize, 7, 11, 57, 1200]),
            (Layout { m: 1, l: 2, i: 5 }, vec![10, 19, 2100]),
        ] {
            let data: Vec<_> = lens
                .iter()
                .map(|&n| {
                    (
                        DMatrix::from_fn(n, layout.m, |_, _| rng.normal()),
                        DMatrix::from_fn(n, layout.l, |_, _| rng.normal() + 0.3),
                    )
                })
                .collect();
            let refs: Vec<_> = data.iter().map(|(u, y)| (u, y)).collect();
            let inv_u: Vec<f64> = (0..layout.m).map(|c| 0.5 + c as f64).collect();
            let inv_y: Vec<f64> = (0..layout.l).map(|c| 2.0 - 0.3 * c as f64).collect();
            let g = hankel_gram(&refs, &inv_u, &inv_y, layout, &mut NoProgress).unwrap();
            let mut want = DMatrix::zeros(layout.rows(), layout.rows());
            for (u, y) in &data {
                let mut us = u.clone();
                let mut ys = y.clone();
                for (c, s) in inv_u.iter().enumerate() {
                    us.column_mut(c).scale_mut(*s);
                }
                for (c, s) in inv_y.iter().enumerate() {
                    ys.column_mut(c).scale_mut(*s);
                }
                let h = dense_hankel(&us, &ys, layout);
                want += &h * h.transpose();
            }
            let err = (&g - &want).amax() / want.amax();
            assert!(err < 1e-13, "{layout:?}: relative error {err:e}");
        }
    }

    #[test]
    fn channel_of_inverts_the_row_layout() {
        let layout = Layout { m: 2, l: 3, i: 4 };
        for k in 0..2 * layout.i {
            for c in 0..layout.m {
                assert_eq!(channel_of(layout, layout.u_row(k, c)), (c, k));
            }
            for c in 0..layout.l {
                assert_eq!(channel_of(layout, layout.y_row(k, c)), (layout.m + c, k));
            }
        }
    }

    #[test]
    fn the_cholesky_is_refused_when_the_spread_is_too_large() {
        let well = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![4.0, 1.0, 0.25]));
        assert!(well_conditioned_cholesky(well).is_some());
        let s = MAX_SPREAD * 2.0;
        let ill = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![s * s, 1.0]));
        assert!(well_conditioned_cholesky(ill).is_none());
        let indefinite = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 1.0]);
        assert!(well_conditioned_cholesky(indefinite).is_none());
    }
}
