//! The normalized Gram matrix `ΦᵀΦ / n_rows` of the ARX regressor (see
//! [`super::regressor`]), accumulated from the channels without forming Φ.

use std::ops::Range;

use nalgebra::DMatrix;

use crate::kernels::dots;

/// Rows per chunk of the Gram accumulation: the chunk of every channel
/// (12 × 2048 doubles) stays in the L2 cache while all its dot products run.
const CHUNK: usize = 2048;

/// Core rows × channels per part of a block's core sums on the pool (see
/// `crate::par`): ~0.2 ms of dot products; at most 4 parts.
const PARALLEL_SAMPLES: usize = 1 << 18;

/// Blocks whose core (rows common to all lags) is shorter than this are
/// summed row by row.
const MIN_CORE: usize = 64;

/// `ΦᵀΦ / n_rows` with unit-RMS columns (zero columns stay zero).
pub(super) fn normalized_gram(
    channels: &[&[f64]],
    stats: &[(f64, f64)],
    blocks: &[Range<usize>],
    lags: usize,
) -> DMatrix<f64> {
    let p = channels.len() * lags;
    let centre: Vec<(f64, f64)> = stats
        .iter()
        .map(|&(mean, rms)| (mean, if rms > 0.0 { 1.0 / rms } else { 0.0 }))
        .collect();
    let mut g = vec![0.0; p * p];
    let mut n_rows = 0usize;
    for b in blocks {
        if b.len() <= lags {
            continue;
        }
        n_rows += b.len() - lags;
        if b.len() < 2 * lags - 1 + MIN_CORE {
            gram_direct(channels, &centre, b.clone(), lags, &mut g);
        } else {
            gram_structured(channels, &centre, b.clone(), lags, &mut g);
        }
    }
    let mut m = DMatrix::<f64>::zeros(p, p);
    if n_rows == 0 {
        return m;
    }
    let d: Vec<f64> = (0..p)
        .map(|u| {
            let v = g[u * p + u] / n_rows as f64;
            if v > 0.0 { v.sqrt() } else { 0.0 }
        })
        .collect();
    for u in 0..p {
        for v in u..p {
            let val = if d[u] > 0.0 && d[v] > 0.0 {
                g[u * p + v] / n_rows as f64 / (d[u] * d[v])
            } else {
                0.0
            };
            m[(u, v)] = val;
            m[(v, u)] = val;
        }
    }
    m
}

/// Column index of channel `c` at lag `l` (1-based).
pub(super) fn col(c: usize, l: usize, lags: usize) -> usize {
    c * lags + l - 1
}

/// [`core_sums`] of `range` in `parts` (a power of two) consecutive parts
/// split at chunk boundaries (sizes only) on the pool, added in order.
fn split_core_sums(
    channels: &[&[f64]],
    centre: &[(f64, f64)],
    range: Range<usize>,
    lags: usize,
    parts: usize,
) -> Vec<f64> {
    let n_chunks = range.len().div_ceil(CHUNK);
    if parts < 2 || n_chunks < 2 {
        return core_sums(channels, centre, range, lags);
    }
    let mid = range.start + n_chunks / 2 * CHUNK;
    let (mut a, b) = crate::par::join(
        true,
        || split_core_sums(channels, centre, range.start..mid, lags, parts / 2),
        || split_core_sums(channels, centre, mid..range.end, lags, parts / 2),
    );
    for (x, y) in a.iter_mut().zip(b) {
        *x += y;
    }
    a
}

/// Adds the rows of block `b` to the upper triangle of `g`, row by row.
fn gram_direct(
    channels: &[&[f64]],
    centre: &[(f64, f64)],
    b: Range<usize>,
    lags: usize,
    g: &mut [f64],
) {
    let p = channels.len() * lags;
    let mut phi = vec![0.0; p];
    for t in b.start + lags..b.end {
        for (c, x) in channels.iter().enumerate() {
            let (mean, scale) = centre[c];
            for l in 1..=lags {
                phi[col(c, l, lags)] = (x[t - l] - mean) * scale;
            }
        }
        for u in 0..p {
            for v in u..p {
                g[u * p + v] += phi[u] * phi[v];
            }
        }
    }
}

/// Adds the rows of block `b = [a, e)` to the upper triangle of `g` using
/// the lag structure.
///
/// Entry `((i, l), (j, m))` is `Σ_{t=a+L}^{e−1} z_i(t−l) z_j(t−m)`
/// `= Σ_{s ∈ [a+L−l, e−l)} z_i(s) z_j(s+δ)` with `δ = l − m`. All windows
/// share the core `[a+L−1, e−L)`: its sums `D_ij(δ)` are computed once per
/// channel pair and `δ ∈ −(L−1)..=L−1` (chunked, vectorised dot products),
/// and each entry adds its `< L` head and tail terms.
fn gram_structured(
    channels: &[&[f64]],
    centre: &[(f64, f64)],
    b: Range<usize>,
    lags: usize,
    g: &mut [f64],
) {
    let nc = channels.len();
    let p = nc * lags;
    let nd = 2 * lags - 1; // δ + (L − 1) ∈ 0..nd
    let margin = lags - 1;
    let (core_start, core_end) = (b.start + lags - 1, b.end - lags);
    let z = |c: usize, s: usize| (channels[c][s] - centre[c].0) * centre[c].1;

    // Core sums D[(i·nc + j)·nd + δ + L − 1] for i ≤ j (δ ≤ 0 when i = j),
    // the halves of a long core (split at a chunk boundary: sizes only)
    // on two threads, then added.
    let n_chunks = (core_end - core_start).div_ceil(CHUNK);
    let parts = ((core_end - core_start).saturating_mul(nc) / PARALLEL_SAMPLES).clamp(1, 4);
    let core = if parts >= 2 && n_chunks >= 2 {
        split_core_sums(
            channels,
            centre,
            core_start..core_end,
            lags,
            1 << parts.ilog2(),
        )
    } else {
        core_sums(channels, centre, core_start..core_end, lags)
    };

    for i in 0..nc {
        for j in i..nc {
            for l in 1..=lags {
                for m in 1..=lags {
                    let (u, v) = (col(i, l, lags), col(j, m, lags));
                    if u > v {
                        continue;
                    }
                    let d = l + margin - m; // δ + L − 1
                    let mut val = core[(i * nc + j) * nd + d];
                    let head = b.start + lags - l..core_start;
                    let tail = core_end..b.end - l;
                    for s in head.chain(tail) {
                        val += z(i, s) * z(j, s + l - m);
                    }
                    g[u * p + v] += val;
                }
            }
        }
    }
}

/// The core sums `D_ij(δ)` of [`gram_structured`] over the rows `rows`
/// (`s ∈ rows`, channel j shifted by δ), chunk by chunk:
/// `[(i·nc + j)·nd + δ + L − 1]` for `i ≤ j` (`δ ≤ 0` when `i = j`).
fn core_sums(
    channels: &[&[f64]],
    centre: &[(f64, f64)],
    rows: Range<usize>,
    lags: usize,
) -> Vec<f64> {
    let nc = channels.len();
    let nd = 2 * lags - 1;
    let margin = lags - 1;
    let (core_start, core_end) = (rows.start, rows.end);
    let mut core = vec![0.0; nc * nc * nd];
    let width = CHUNK + 2 * margin;
    let mut buf = vec![0.0; nc * width];
    let mut s0 = core_start;
    while s0 < core_end {
        let w = CHUNK.min(core_end - s0);
        let lo = s0 - margin;
        for (c, x) in channels.iter().enumerate() {
            let (mean, scale) = centre[c];
            for (dst, v) in buf[c * width..c * width + w + 2 * margin]
                .iter_mut()
                .zip(&x[lo..lo + w + 2 * margin])
            {
                *dst = (v - mean) * scale;
            }
        }
        for i in 0..nc {
            let xi = &buf[i * width + margin..i * width + margin + w];
            // Every (j ≥ i, d) window of this chunk; d ≤ margin when j = i.
            let (ys, slots): (Vec<&[f64]>, Vec<usize>) = (i..nc)
                .flat_map(|j| {
                    let d_count = if i == j { margin + 1 } else { nd };
                    (0..d_count).map(move |d| (j, d))
                })
                .map(|(j, d)| {
                    (
                        &buf[j * width + d..j * width + d + w],
                        (i * nc + j) * nd + d,
                    )
                })
                .unzip();
            let mut sums = vec![0.0; ys.len()];
            dots(xi, &ys, &mut sums);
            for (slot, v) in slots.into_iter().zip(sums) {
                core[slot] += v;
            }
        }
        s0 += w;
    }
    core
}

#[cfg(test)]
#[allow(clippy::single_range_in_vec_init)] // vectors of blocks
mod tests {
    use super::super::record::mean_rms;
    use super::*;

    fn gram_reference(channels: &[&[f64]], blocks: &[Range<usize>], lags: usize) -> DMatrix<f64> {
        let p = channels.len() * lags;
        let means: Vec<f64> = channels.iter().map(|x| mean_rms(x, blocks).0).collect();
        let mut rows = Vec::new();
        for b in blocks {
            for t in b.start + lags..b.end {
                let mut r = vec![0.0; p];
                for (c, x) in channels.iter().enumerate() {
                    let mean = means[c];
                    for l in 1..=lags {
                        r[col(c, l, lags)] = x[t - l] - mean;
                    }
                }
                rows.push(r);
            }
        }
        let n = rows.len();
        let phi = DMatrix::from_fn(n, p, |i, j| rows[i][j]);
        let mut g = phi.transpose() * &phi / n as f64;
        let d: Vec<f64> = (0..p).map(|u| g[(u, u)].sqrt()).collect();
        for u in 0..p {
            for v in 0..p {
                g[(u, v)] /= d[u] * d[v];
            }
        }
        g
    }

    fn signals(n: usize) -> Vec<Vec<f64>> {
        (0..4)
            .map(|c| {
                (0..n)
                    .map(|t| {
                        let t = t as f64;
                        100.0 * c as f64
                            + (0.37 * t * (c + 1) as f64).sin()
                            + 0.5 * (0.011 * t * t + c as f64).cos()
                    })
                    .collect()
            })
            .collect()
    }

    #[test]
    fn structured_gram_matches_explicit_regressor() {
        let chans = signals(2000);
        let refs: Vec<&[f64]> = chans.iter().map(Vec::as_slice).collect();
        // Long blocks (structured path), a short one (direct path) and one
        // too short for a row.
        let blocks = vec![0..700, 705..760, 800..802, 810..2000];
        for lags in [1, 2, 3, 5] {
            let stats: Vec<(f64, f64)> = refs.iter().map(|x| mean_rms(x, &blocks)).collect();
            let got = normalized_gram(&refs, &stats, &blocks, lags);
            let want = gram_reference(&refs, &blocks, lags);
            let err = (&got - &want).amax();
            assert!(err < 1e-12, "lags {lags}: max error {err:e}");
        }
    }

    /// A core long enough to be split between two threads: the two
    /// halves' sums, added, equal the explicit Gram matrix to 1e-12.
    #[test]
    fn split_core_matches_explicit_regressor() {
        let chans = signals(70_000);
        let refs: Vec<&[f64]> = chans.iter().map(Vec::as_slice).collect();
        let blocks = vec![0..70_000];
        assert!(70_000 * refs.len() >= PARALLEL_SAMPLES && 70_000 > 2 * CHUNK);
        for lags in [1, 2] {
            let stats: Vec<(f64, f64)> = refs.iter().map(|x| mean_rms(x, &blocks)).collect();
            let got = normalized_gram(&refs, &stats, &blocks, lags);
            let want = gram_reference(&refs, &blocks, lags);
            let err = (&got - &want).amax();
            assert!(err < 1e-12, "lags {lags}: max error {err:e}");
        }
    }
}
