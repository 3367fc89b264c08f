//! The normalized Gram matrix `ΦᵀΦ / n_rows` of the ARX regressor (see
//! [`super::regressor`]), accumulated from the channels without forming Φ,
//! and in the same pass every channel's mean and RMS.

use std::ops::Range;

use nalgebra::DMatrix;

use crate::kernels::{dots, prefetch_line};

/// Rows per chunk of the Gram accumulation: the chunk of every channel
/// (12 × 2048 doubles) stays in the L2 cache while all its dot products run.
const CHUNK: usize = 2048;

/// Core rows × channels per part of a block's core sums on the pool (see
/// `crate::par`): ~0.2 ms of dot products; at most 4 parts.
const PARALLEL_SAMPLES: usize = 1 << 18;

/// Blocks whose core (rows common to all lags) is shorter than this are
/// summed row by row.
const MIN_CORE: usize = 64;

/// `ΦᵀΦ / n_rows` with unit-RMS columns (zero columns stay zero), and
/// each channel's mean and RMS about it over the valid samples, from one
/// pass over the samples.
///
/// Why one pass: on a long log each pass over the samples is paid in
/// memory bandwidth, and the statistics and the centred products read the
/// same values. The sums are taken about each channel's first valid
/// sample `x₀` and centred afterwards:
/// `Σ (a − d)(b − e) = Σ ab − e Σa − d Σb + n d e` with `a = x − x₀`, `d`
/// the mean of `a`. Rounding grows with `((mean − x₀)/σ)²`, ~1e-16 per
/// unit: negligible unless the mean lies ~10⁶ standard deviations from
/// the first sample.
///
/// The statistics are non-finite when a sample is (or the sums
/// overflow); the matrix is then meaningless and must not be used.
pub(super) fn normalized_gram(
    channels: &[&[f64]],
    blocks: &[Range<usize>],
    lags: usize,
) -> (DMatrix<f64>, Vec<(f64, f64)>) {
    let nc = channels.len();
    let p = nc * lags;
    let first = blocks.iter().find(|b| !b.is_empty()).map(|b| b.start);
    let shift: Vec<f64> = channels
        .iter()
        .map(|x| first.map_or(0.0, |s| x[s]))
        .collect();
    let mut sums = Sums::new(nc, lags);
    for b in blocks {
        sums.n += b.len();
        if b.len() <= lags {
            sums.add_moments(channels, &shift, b.clone());
            continue;
        }
        sums.n_rows += b.len() - lags;
        if b.len() < 2 * lags - 1 + MIN_CORE {
            sums.add_moments(channels, &shift, b.clone());
            gram_direct(channels, &shift, b.clone(), lags, &mut sums);
        } else {
            gram_structured(channels, &shift, b.clone(), lags, &mut sums);
        }
    }
    let stats: Vec<(f64, f64)> = (0..nc)
        .map(|c| super::record::from_shifted_sums(shift[c], sums.n, sums.s1[c], sums.s2[c]))
        .collect();
    let mut m = DMatrix::<f64>::zeros(p, p);
    if sums.n_rows == 0 {
        return (m, stats);
    }
    // Centred: each channel's offset d = mean(a) over all valid samples.
    let offset: Vec<f64> = sums.s1.iter().map(|s| s / sums.n as f64).collect();
    let rows = sums.n_rows as f64;
    let centred = |u: usize, v: usize| {
        let (i, j) = (u / lags, v / lags);
        let (di, dj) = (offset[i], offset[j]);
        sums.g[u * p + v] - dj * sums.col[u] - di * sums.col[v] + rows * di * dj
    };
    let d: Vec<f64> = (0..p)
        .map(|u| {
            let v = centred(u, u) / rows;
            if v > 0.0 { v.sqrt() } else { 0.0 }
        })
        .collect();
    for u in 0..p {
        for v in u..p {
            let val = if d[u] > 0.0 && d[v] > 0.0 {
                centred(u, v) / rows / (d[u] * d[v])
            } else {
                0.0
            };
            m[(u, v)] = val;
            m[(v, u)] = val;
        }
    }
    (m, stats)
}

/// Column index of channel `c` at lag `l` (1-based).
pub(super) fn col(c: usize, l: usize, lags: usize) -> usize {
    c * lags + l - 1
}

/// The sums of one pass, about the shifts `x₀`: `a = x − x₀`.
struct Sums {
    /// `Σ_rows a_u a_v`, upper triangle of p × p (u = column (c, l)).
    g: Vec<f64>,
    /// `Σ_rows a_u`, per column.
    col: Vec<f64>,
    /// `Σ a` and `Σ a²` per channel over every valid sample.
    s1: Vec<f64>,
    s2: Vec<f64>,
    /// Valid samples, and regressor rows.
    n: usize,
    n_rows: usize,
}

impl Sums {
    fn new(nc: usize, lags: usize) -> Self {
        let p = nc * lags;
        Sums {
            g: vec![0.0; p * p],
            col: vec![0.0; p],
            s1: vec![0.0; nc],
            s2: vec![0.0; nc],
            n: 0,
            n_rows: 0,
        }
    }

    /// Adds `Σ a` and `Σ a²` of every channel over `range`.
    fn add_moments(&mut self, channels: &[&[f64]], shift: &[f64], range: Range<usize>) {
        for (c, x) in channels.iter().enumerate() {
            let (a1, a2) = super::record::shifted_sums(&x[range.clone()], shift[c]);
            self.s1[c] += a1;
            self.s2[c] += a2;
        }
    }
}

/// [`core_sums`] of `range` in `parts` (a power of two) consecutive parts
/// split at chunk boundaries (sizes only) on the pool, added in order.
fn split_core_sums(
    channels: &[&[f64]],
    shift: &[f64],
    range: Range<usize>,
    lags: usize,
    parts: usize,
) -> Vec<f64> {
    let n_chunks = range.len().div_ceil(CHUNK);
    if parts < 2 || n_chunks < 2 {
        return core_sums(channels, shift, range, lags);
    }
    let mid = range.start + n_chunks / 2 * CHUNK;
    let (mut a, b) = crate::par::join(
        true,
        || split_core_sums(channels, shift, range.start..mid, lags, parts / 2),
        || split_core_sums(channels, shift, mid..range.end, lags, parts / 2),
    );
    for (x, y) in a.iter_mut().zip(b) {
        *x += y;
    }
    a
}

/// Adds the rows of block `b` to `sums.g` and `sums.col`, row by row.
fn gram_direct(channels: &[&[f64]], shift: &[f64], b: Range<usize>, lags: usize, sums: &mut Sums) {
    let p = channels.len() * lags;
    let mut phi = vec![0.0; p];
    for t in b.start + lags..b.end {
        for (c, x) in channels.iter().enumerate() {
            for l in 1..=lags {
                phi[col(c, l, lags)] = x[t - l] - shift[c];
            }
        }
        for u in 0..p {
            sums.col[u] += phi[u];
            for v in u..p {
                sums.g[u * p + v] += phi[u] * phi[v];
            }
        }
    }
}

/// Adds the rows of block `b = [a, e)` to `sums` using the lag structure,
/// and the block's moments.
///
/// Entry `((i, l), (j, m))` is `Σ_{t=a+L}^{e−1} a_i(t−l) a_j(t−m)`
/// `= Σ_{s ∈ [a+L−l, e−l)} a_i(s) a_j(s+δ)` with `δ = l − m`. All windows
/// share the core `[a+L−1, e−L)`: its sums `D_ij(δ)` are computed once per
/// channel pair and `δ ∈ −(L−1)..=L−1` (chunked, vectorised dot products),
/// with the core's `Σ a_i`; each entry adds its `< L` head and tail terms.
fn gram_structured(
    channels: &[&[f64]],
    shift: &[f64],
    b: Range<usize>,
    lags: usize,
    sums: &mut Sums,
) {
    let nc = channels.len();
    let p = nc * lags;
    let nd = 2 * lags - 1; // δ + (L − 1) ∈ 0..nd
    let margin = lags - 1;
    let (core_start, core_end) = (b.start + lags - 1, b.end - lags);
    let a = |c: usize, s: usize| channels[c][s] - shift[c];

    // Core sums D[(i·nc + j)·nd + δ + L − 1] for i ≤ j (δ ≤ 0 when i = j),
    // then Σ a per channel; the halves of a long core (split at a chunk
    // boundary: sizes only) on two threads, then added.
    let n_chunks = (core_end - core_start).div_ceil(CHUNK);
    let parts = ((core_end - core_start).saturating_mul(nc) / PARALLEL_SAMPLES).clamp(1, 4);
    let core = if parts >= 2 && n_chunks >= 2 {
        split_core_sums(
            channels,
            shift,
            core_start..core_end,
            lags,
            1 << parts.ilog2(),
        )
    } else {
        core_sums(channels, shift, core_start..core_end, lags)
    };
    let core_sum = &core[nc * nc * nd..];

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
                        val += a(i, s) * a(j, s + l - m);
                    }
                    sums.g[u * p + v] += val;
                }
            }
        }
        for l in 1..=lags {
            let head = b.start + lags - l..core_start;
            let tail = core_end..b.end - l;
            sums.col[col(i, l, lags)] +=
                core_sum[i] + head.chain(tail).map(|s| a(i, s)).sum::<f64>();
        }
        // The moments: the core's, then the samples before and after it.
        let (mut s1, mut s2) = (core_sum[i], core[(i * nc + i) * nd + margin]);
        for s in (b.start..core_start).chain(core_end..b.end) {
            let v = a(i, s);
            s1 += v;
            s2 += v * v;
        }
        sums.s1[i] += s1;
        sums.s2[i] += s2;
    }
}

/// The core sums `D_ij(δ)` of [`gram_structured`] over the rows `rows`
/// (`s ∈ rows`, channel j shifted by δ), chunk by chunk:
/// `[(i·nc + j)·nd + δ + L − 1]` for `i ≤ j` (`δ ≤ 0` when `i = j`), then
/// `Σ_{s ∈ rows} a_i(s)` for each channel i at `nc·nc·nd + i`.
fn core_sums(channels: &[&[f64]], shift: &[f64], rows: Range<usize>, lags: usize) -> Vec<f64> {
    let nc = channels.len();
    let nd = 2 * lags - 1;
    let margin = lags - 1;
    let (core_start, core_end) = (rows.start, rows.end);
    let mut core = vec![0.0; nc * nc * nd + nc];
    let width = CHUNK + 2 * margin;
    let mut buf = vec![0.0; nc * width];
    let mut s0 = core_start;
    while s0 < core_end {
        let w = CHUNK.min(core_end - s0);
        let lo = s0 - margin;
        // The next chunk's samples are asked into the cache meanwhile, a
        // line per line copied: the pass is bound by memory, not by the
        // arithmetic.
        let next = (lo + w + 2 * margin)..(lo + 2 * w + 2 * margin).min(core_end + margin);
        for (c, x) in channels.iter().enumerate() {
            let ahead = x.get(next.clone()).unwrap_or(&[]);
            let src = &x[lo..lo + w + 2 * margin];
            let dst = &mut buf[c * width..c * width + w + 2 * margin];
            for (k, (d, v)) in dst.iter_mut().zip(src).enumerate() {
                if k % 8 == 0
                    && let Some(p) = ahead.get(k)
                {
                    prefetch_line(p);
                }
                *d = v - shift[c];
            }
        }
        for i in 0..nc {
            let xi = &buf[i * width + margin..i * width + margin + w];
            core[nc * nc * nd + i] += super::record::sum(xi);
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
    use super::*;

    /// Mean and RMS about it over `blocks`, in two passes.
    fn mean_rms(x: &[f64], blocks: &[Range<usize>]) -> (f64, f64) {
        let vals: Vec<f64> = blocks
            .iter()
            .flat_map(|b| x[b.clone()].iter().copied())
            .collect();
        if vals.is_empty() {
            return (0.0, 0.0);
        }
        let n = vals.len() as f64;
        let mean = vals.iter().sum::<f64>() / n;
        let var = vals.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
        (mean, var.sqrt())
    }

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

    /// The Gram matrix to 1e-12 of the explicit one, the statistics to
    /// 1e-12 of the two-pass ones.
    fn assert_matches_explicit(refs: &[&[f64]], blocks: &[Range<usize>], lags: usize) {
        let (got, stats) = normalized_gram(refs, blocks, lags);
        for (x, &(mean, rms)) in refs.iter().zip(&stats) {
            let (m, r) = mean_rms(x, blocks);
            assert!(
                (mean - m).abs() < 1e-12 * m.abs().max(1.0),
                "mean {mean} vs {m}"
            );
            assert!((rms - r).abs() < 1e-12 * r, "rms {rms} vs {r}");
        }
        let want = gram_reference(refs, blocks, lags);
        let err = (&got - &want).amax();
        assert!(err < 1e-12, "lags {lags}: max error {err:e}");
    }

    #[test]
    fn structured_gram_matches_explicit_regressor() {
        let chans = signals(2000);
        let refs: Vec<&[f64]> = chans.iter().map(Vec::as_slice).collect();
        // Long blocks (structured path), a short one (direct path) and one
        // too short for a row.
        let blocks = vec![0..700, 705..760, 800..802, 810..2000];
        for lags in [1, 2, 3, 5] {
            assert_matches_explicit(&refs, &blocks, lags);
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
            assert_matches_explicit(&refs, &blocks, lags);
        }
    }

    /// The statistics from the Gram pass equal the two-pass ones, on long
    /// (structured), short (direct) and row-less blocks; a constant is
    /// exact, no samples give zeros, a NaN gives non-finite statistics.
    #[test]
    fn statistics_match_two_pass() {
        let x: Vec<f64> = (0..10_001)
            .map(|i| 1e6 + 0.25 * (i as f64 * 0.37).sin() + 1e-3 * i as f64)
            .collect();
        let y: Vec<f64> = (0..10_001).map(|i| ((i * 7) % 11) as f64).collect();
        let refs = [x.as_slice(), y.as_slice()];
        for blocks in [vec![0..10_001], vec![3..4000, 4100..4150, 9000..9001]] {
            for lags in [1, 3] {
                let (_, stats) = normalized_gram(&refs, &blocks, lags);
                for (c, z) in refs.iter().enumerate() {
                    let (mean, rms) = mean_rms(z, &blocks);
                    let (m, r) = stats[c];
                    assert!(
                        (m - mean).abs() < 1e-14 * mean.abs().max(1.0),
                        "{m} vs {mean}"
                    );
                    assert!((r / rms - 1.0).abs() < 1e-9, "{r} vs {rms}");
                }
            }
        }
        let (g, stats) = normalized_gram(&refs, &[5..5], 1);
        assert_eq!(stats, vec![(0.0, 0.0); 2]);
        assert_eq!(g.amax(), 0.0);
        let c = [2.5; 90];
        let (_, stats) = normalized_gram(&[&c], &[0..90], 1);
        assert_eq!(stats, vec![(2.5, 0.0)]);
        let mut bad = y.clone();
        bad[5000] = f64::NAN;
        let (_, stats) = normalized_gram(&[&bad], &[0..10_001], 2);
        assert!(stats[0].0.is_nan() && stats[0].1.is_nan());
    }

    /// A channel whose mean lies far from its first sample (a step from
    /// rest to a steady force with small noise: (mean − x₀)/σ ≈ 500): the
    /// shift's cancellation stays ~1e-16 · 500² relative.
    #[test]
    fn centring_after_the_pass_holds_for_a_step_from_rest() {
        let n = 20_000;
        let step: Vec<f64> = (0..n)
            .map(|t| {
                if t < 10 {
                    0.0
                } else {
                    500.0 + ((t * 13) % 7) as f64 / 3.0 - 1.0
                }
            })
            .collect();
        let other: Vec<f64> = (0..n).map(|t| (0.01 * t as f64).sin()).collect();
        let refs = [step.as_slice(), other.as_slice()];
        let blocks = vec![0..n];
        for lags in [1, 2] {
            let (got, _) = normalized_gram(&refs, &blocks, lags);
            let want = gram_reference(&refs, &blocks, lags);
            let err = (&got - &want).amax();
            assert!(err < 1e-10, "lags {lags}: max error {err:e}");
        }
    }
}
