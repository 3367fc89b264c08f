//! LQ factorization of the block-Hankel data matrix, accumulated in chunks.
//!
//! With past/future horizon i, every Hankel column t of an experiment is the
//! window w_t = (u, y) at t..t+2i, arranged as the rows
//! H = [U_f; U_p; Y_p; Y_f] (U_f = U_{i|2i−1} first: projecting out the
//! future inputs is then a truncation). H = L Qᵀ with L lower triangular.
//!
//! Two routes to L (see [`super::gram`]): the Gram matrix H Hᵀ from lagged
//! cross-products (O((m + l)² 4i j), exploiting the Hankel structure) and
//! its Cholesky factor, taken when that factor's diagonal spread is small;
//! otherwise the QR below. Why not the Gram always: it squares the
//! condition number. On noise-free or high-SNR data Y_p is (nearly) a linear
//! combination of U_p and n states, H is rank-deficient, Cholesky breaks
//! down or leaves √ε-size garbage in the null directions, and the oblique
//! projection inherits it. The QR keeps those directions at ε·‖H‖. Test
//! `gram_cholesky_loses_the_noise_free_null_space`, noise-free poles: QR
//! 1.5e-14 vs Gram 6.6e-14 (white input), 1.9e-14 vs 1.3e-12 (input
//! low-passed at 0.9, as oversampled trial data): the Gram loss grows with
//! cond(H)², the QR's does not; the spread test sends such data to the QR.
//!
//! The QR: L is the R factor (transposed) of Hᵀ, updated by QR of
//! [R; next rows of Hᵀ] so only r × r plus one chunk is ever held
//! (r = 2i(m + l)), never Q, never H itself.
//!
//! Cost O(j r²), memory (c + r)·r + r² doubles with c the chunk rows: both
//! independent of the number of samples beyond the linear pass.

use faer::Par;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::qr::no_pivoting::factor;
use faer::reborrow::ReborrowMut;
use faer::{Mat, MatMut};
use nalgebra::DMatrix;

use super::error::N4sidError;
use super::gram;
use crate::estimation::{Cancelled, Progress, SubProgress};

/// Row layout of H = [U_f; U_p; Y_p; Y_f] for m inputs, l outputs, horizon i.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Layout {
    pub m: usize,
    pub l: usize,
    pub i: usize,
}

impl Layout {
    /// Rows of H: 2i(m + l).
    pub fn rows(&self) -> usize {
        2 * self.i * (self.m + self.l)
    }
    /// Rows of U_f (= of U_p): m i.
    pub fn mi(&self) -> usize {
        self.m * self.i
    }
    /// Rows of Y_p (= of Y_f): l i.
    pub fn li(&self) -> usize {
        self.l * self.i
    }
    /// Row of H holding input `ch` at lag k (0 ≤ k < 2i) of the window.
    pub fn u_row(&self, k: usize, ch: usize) -> usize {
        if k < self.i {
            self.mi() + k * self.m + ch
        } else {
            (k - self.i) * self.m + ch
        }
    }
    /// Row of H holding output `ch` at lag k (0 ≤ k < 2i) of the window.
    pub fn y_row(&self, k: usize, ch: usize) -> usize {
        if k < self.i {
            2 * self.mi() + k * self.l + ch
        } else {
            2 * self.mi() + self.li() + (k - self.i) * self.l + ch
        }
    }
}

/// The lower-triangular factor L of H = L Qᵀ over all experiments.
#[derive(Debug, Clone)]
pub(crate) struct HankelLq {
    pub layout: Layout,
    /// r × r lower triangular.
    pub l: DMatrix<f64>,
    /// Hankel columns j summed over experiments.
    pub columns: usize,
}

/// How [`hankel_lq`] obtained L.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum LqRoute {
    /// Cholesky factor of the structured Gram matrix (well conditioned H).
    Gram,
    /// Chunked Householder QR.
    Qr,
}

/// L for the experiments (already validated), each channel divided by its
/// scale: from the Gram matrix when H is well conditioned, else by QR.
/// Every experiment contributes its own columns; no window straddles two
/// experiments.
pub(crate) fn hankel_lq(
    experiments: &[(&DMatrix<f64>, &DMatrix<f64>)],
    u_scale: &[f64],
    y_scale: &[f64],
    layout: Layout,
    chunk_rows: usize,
    progress: &mut dyn Progress,
) -> Result<(HankelLq, LqRoute), N4sidError> {
    let inv_u: Vec<f64> = u_scale.iter().map(|s| 1.0 / s).collect();
    let inv_y: Vec<f64> = y_scale.iter().map(|s| 1.0 / s).collect();
    let g = gram::hankel_gram(
        experiments,
        &inv_u,
        &inv_y,
        layout,
        &mut SubProgress::new(progress, 0.0, 0.2),
    )?;
    if let Some(l) = gram::well_conditioned_cholesky(g) {
        let columns = experiments
            .iter()
            .map(|(u, _)| u.nrows() + 1 - 2 * layout.i)
            .sum();
        progress
            .update(1.0, "Cholesky of the Gram matrix")
            .map_err(|Cancelled| N4sidError::Cancelled)?;
        return Ok((HankelLq { layout, l, columns }, LqRoute::Gram));
    }
    let lq = hankel_lq_qr(
        experiments,
        u_scale,
        y_scale,
        layout,
        chunk_rows,
        &mut SubProgress::new(progress, 0.2, 1.0),
    )?;
    Ok((lq, LqRoute::Qr))
}

/// L by chunked Householder QR of Hᵀ, whatever the conditioning.
pub(crate) fn hankel_lq_qr(
    experiments: &[(&DMatrix<f64>, &DMatrix<f64>)],
    u_scale: &[f64],
    y_scale: &[f64],
    layout: Layout,
    chunk_rows: usize,
    progress: &mut dyn Progress,
) -> Result<HankelLq, N4sidError> {
    let r = layout.rows();
    let c = chunk_rows.max(1);
    let total: usize = experiments
        .iter()
        .map(|(u, _)| u.nrows() + 1 - 2 * layout.i)
        .sum();
    // Rows 0..r hold the running R, rows r..r+c the next chunk of Hᵀ.
    let mut work = Mat::<f64>::zeros(r + c, r);
    let block = factor::recommended_block_size::<f64>(r + c, r).max(1);
    let mut householder = Mat::<f64>::zeros(block, r);
    let mut scratch = MemBuffer::new(factor::qr_in_place_scratch::<f64>(
        r + c,
        r,
        block,
        Par::Seq,
        Default::default(),
    ));
    let inv_u: Vec<f64> = u_scale.iter().map(|s| 1.0 / s).collect();
    let inv_y: Vec<f64> = y_scale.iter().map(|s| 1.0 / s).collect();
    let mut done = 0usize;
    for (u, y) in experiments {
        let j = u.nrows() + 1 - 2 * layout.i;
        let mut t0 = 0;
        while t0 < j {
            let cnt = c.min(j - t0);
            fill_chunk(
                work.as_mut().submatrix_mut(r, 0, cnt, r),
                u,
                y,
                &inv_u,
                &inv_y,
                layout,
                t0,
            );
            factor::qr_in_place(
                work.as_mut().submatrix_mut(0, 0, r + cnt, r),
                householder.as_mut(),
                Par::Seq,
                MemStack::new(&mut scratch),
                Default::default(),
            );
            // Keep R; the Householder vectors below its diagonal are dropped.
            for col in 0..r {
                for row in col + 1..r {
                    work[(row, col)] = 0.0;
                }
            }
            t0 += cnt;
            done += cnt;
            progress
                .update(done as f64 / total as f64, "LQ of the block-Hankel data")
                .map_err(|Cancelled| N4sidError::Cancelled)?;
        }
    }
    let l = DMatrix::from_fn(r, r, |a, b| if a >= b { work[(b, a)] } else { 0.0 });
    Ok(HankelLq {
        layout,
        l,
        columns: total,
    })
}

/// Column `ch` of a column-major matrix, borrowed from its storage.
pub(crate) fn column(m: &DMatrix<f64>, ch: usize) -> &[f64] {
    &m.as_slice()[ch * m.nrows()..(ch + 1) * m.nrows()]
}

/// Writes rows t0..t0+cnt of Hᵀ (scaled) into `dst` (cnt × r).
fn fill_chunk(
    mut dst: MatMut<'_, f64>,
    u: &DMatrix<f64>,
    y: &DMatrix<f64>,
    inv_u: &[f64],
    inv_y: &[f64],
    layout: Layout,
    t0: usize,
) {
    let cnt = dst.nrows();
    for k in 0..2 * layout.i {
        for (ch, &s) in inv_u.iter().enumerate() {
            let src = &column(u, ch)[t0 + k..t0 + k + cnt];
            let mut col = dst.rb_mut().col_mut(layout.u_row(k, ch));
            for (row, v) in src.iter().enumerate() {
                col[row] = v * s;
            }
        }
        for (ch, &s) in inv_y.iter().enumerate() {
            let src = &column(y, ch)[t0 + k..t0 + k + cnt];
            let mut col = dst.rb_mut().col_mut(layout.y_row(k, ch));
            for (row, v) in src.iter().enumerate() {
                col[row] = v * s;
            }
        }
    }
}

/// The dense H (r × j) of one experiment, for tests on small data.
#[cfg(test)]
pub(crate) fn dense_hankel(u: &DMatrix<f64>, y: &DMatrix<f64>, layout: Layout) -> DMatrix<f64> {
    let j = u.nrows() + 1 - 2 * layout.i;
    let mut h = DMatrix::zeros(layout.rows(), j);
    for t in 0..j {
        for k in 0..2 * layout.i {
            for ch in 0..layout.m {
                h[(layout.u_row(k, ch), t)] = u[(t + k, ch)];
            }
            for ch in 0..layout.l {
                h[(layout.y_row(k, ch), t)] = y[(t + k, ch)];
            }
        }
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::estimation::NoProgress;
    use crate::rng::SplitMix64;

    #[test]
    fn chunked_lq_reproduces_the_gram_of_the_stacked_hankel_blocks() {
        let layout = Layout { m: 2, l: 3, i: 3 };
        let mut rng = SplitMix64::new(3);
        let mut data = Vec::new();
        for n in [57usize, 80] {
            let u = DMatrix::from_fn(n, 2, |_, _| rng.normal());
            let y = DMatrix::from_fn(n, 3, |_, _| rng.normal());
            data.push((u, y));
        }
        let refs: Vec<_> = data.iter().map(|(u, y)| (u, y)).collect();
        let mut gram = DMatrix::zeros(layout.rows(), layout.rows());
        for (u, y) in &data {
            let h = dense_hankel(u, y, layout);
            gram += &h * h.transpose();
        }
        for chunk in [1usize, 7, 1000] {
            let lq =
                hankel_lq_qr(&refs, &[1.0; 2], &[1.0; 3], layout, chunk, &mut NoProgress).unwrap();
            assert_eq!(lq.columns, 52 + 75);
            let err = (&lq.l * lq.l.transpose() - &gram).amax() / gram.amax();
            assert!(err < 1e-13, "chunk {chunk}: relative error {err}");
        }
    }
}
