//! The segments of a multichannel Welch estimate in batches, and where a
//! large estimate is split between two threads.

use std::ops::Range;

use super::accumulators::{Accumulators, BATCH};
use super::engine::SegmentFft;
use super::multichannel::require_finite_channel;
use super::{SpectraError, WelchConfig};

/// Work (samples transformed, `n_segments × channels × nperseg`) from
/// which an estimate is split over two threads: below it, a thread's start
/// (~50 µs) would not pay for itself.
const PARALLEL_WORK: usize = 1 << 18;

/// One batch: up to [`BATCH`] consecutive segments `first..first + count`
/// of a block.
#[derive(Clone)]
pub(super) struct Batch {
    block: Range<usize>,
    first: usize,
    count: usize,
}

/// The batches of every block, in order: a block's segments from its
/// start, [`BATCH`] at a time, and a batch ends at the segment `cut`
/// (counted over all blocks) when there is one, so that the estimate can
/// be split there.
pub(super) fn batches(
    blocks: &[Range<usize>],
    cfg: &WelchConfig,
    cut: Option<usize>,
) -> Vec<Batch> {
    let mut out = Vec::new();
    let mut before = 0;
    for block in blocks {
        let n_block = cfg.n_segments(block.len());
        // The cut within this block, if it falls strictly inside it.
        let inner = cut
            .and_then(|c| c.checked_sub(before))
            .filter(|&c| c > 0 && c < n_block);
        let mut first = 0;
        while first < n_block {
            let end = match inner {
                Some(c) if first < c => (first + BATCH).min(c),
                _ => (first + BATCH).min(n_block),
            };
            out.push(Batch {
                block: block.clone(),
                first,
                count: end - first,
            });
            first = end;
        }
        before += n_block;
    }
    out
}

/// Most parts an estimate is split into (see [`run_parts`]).
const MAX_PARTS: usize = 4;

/// Parts an estimate of `work` samples transformed (`n_segments ×
/// channels × nperseg`) is split into: 1 below [`PARALLEL_WORK`], else
/// the largest power of two up to one per [`PARALLEL_WORK`], 2 to
/// [`MAX_PARTS`] (halves of halves stay even when the pool steals them).
/// More parts than cores let the pool balance the spectra against the
/// report's other work. Depends on the sizes only.
pub(super) fn parts(work: usize) -> usize {
    if work < PARALLEL_WORK {
        return 1;
    }
    let whole = (work / PARALLEL_WORK).clamp(2, MAX_PARTS);
    1 << whole.ilog2()
}

/// Index of the first batch after the first `share.0 / share.1` of the
/// segments: the batch boundary nearest that share (the earlier on a
/// tie), strictly inside the list (`batches.len()` when there are fewer
/// than two batches). Depends on the sizes only.
pub(super) fn split_point(batches: &[Batch], share: (usize, usize)) -> usize {
    if batches.len() < 2 {
        return batches.len();
    }
    let n_segments: usize = batches.iter().map(|b| b.count).sum();
    // In segments × share.1, to stay in integers.
    let target = n_segments * share.0;
    let mut seen = 0;
    let mut best = (usize::MAX, 1);
    for (i, b) in batches[..batches.len() - 1].iter().enumerate() {
        seen += b.count;
        let miss = (seen * share.1).abs_diff(target);
        if miss < best.0 {
            best = (miss, i + 1);
        }
    }
    best.1
}

/// Transforms the segments of `batches` in `parts` consecutive parts (on
/// the pool, see `crate::par`) and adds them to `acc` (zeroed): each part
/// sums into its own accumulators, added in order afterwards, so the
/// result depends on `parts` and the sizes, not on the threads.
/// `share` is the share of the segments in the first part of the first
/// split (further splits halve): the batches should end at that segment
/// (see [`batches`]).
#[allow(clippy::too_many_arguments)]
pub(super) fn run_parts(
    engine: &SegmentFft,
    acc: &mut Accumulators,
    batches: &[Batch],
    parts: usize,
    share: (usize, usize),
    channels: &[&[f64]],
    cfg: &WelchConfig,
    own_mean: bool,
    check_finite: bool,
) -> Result<(), SpectraError> {
    let split = if parts < 2 {
        batches.len()
    } else {
        split_point(batches, share)
    };
    if split >= batches.len() {
        let mut engine = engine.clone();
        return run_batches(
            &mut engine,
            acc,
            batches,
            channels,
            cfg,
            own_mean,
            check_finite,
        );
    }
    let (head, tail) = batches.split_at(split);
    let first = parts / 2;
    // Taken on this thread, so that its buffers return to this thread's
    // kept ones in `absorb`.
    let mut second = acc.sibling();
    let (a, b) = crate::par::join(
        true,
        || {
            run_parts(
                engine,
                acc,
                head,
                first,
                (1, 2),
                channels,
                cfg,
                own_mean,
                check_finite,
            )
        },
        || {
            second.zero();
            run_parts(
                engine,
                &mut second,
                tail,
                parts - first,
                (1, 2),
                channels,
                cfg,
                own_mean,
                check_finite,
            )
        },
    );
    // The first part's error first: a serial run would meet it first.
    a?;
    b?;
    acc.absorb(second);
    Ok(())
}

/// Transforms the segments of `batches` and adds them to `acc`.
pub(super) fn run_batches(
    engine: &mut SegmentFft,
    acc: &mut Accumulators,
    batches: &[Batch],
    channels: &[&[f64]],
    cfg: &WelchConfig,
    own_mean: bool,
    check_finite: bool,
) -> Result<(), SpectraError> {
    let step = cfg.step();
    for Batch {
        block,
        first,
        count,
    } in batches
    {
        let (first, count) = (*first, *count);
        // Up to BATCH consecutive segments of one channel after another:
        // the samples they share are read while still in cache.
        for (c, channel) in channels.iter().enumerate() {
            // The channel's last segment mean: the next segment's shift.
            let mut mean = f64::NAN;
            for slot in 0..count {
                let m = first + slot;
                let start = block.start + m * step;
                let end = start + cfg.nperseg;
                if own_mean {
                    let samples = &channel[start..end];
                    let shift = if mean.is_finite() { mean } else { samples[0] };
                    // The samples the next segment adds (within the block).
                    let ahead = end.min(block.end)..(end + step).min(block.end);
                    let out = acc.slot_mut(slot, c);
                    let offset = engine.transform_centred(samples, shift, &channel[ahead], out)?;
                    if check_finite && !offset.is_finite() {
                        require_finite_channel(c, channel, std::slice::from_ref(&(start..end)))?;
                    }
                    mean = shift + offset;
                } else {
                    engine.transform(&channel[block.clone()], m, acc.slot_mut(slot, c))?;
                }
                acc.add_channel(slot, c);
            }
        }
        acc.add_segments(count);
    }
    Ok(())
}

#[cfg(test)]
#[allow(clippy::single_range_in_vec_init)] // vectors of blocks
mod tests {
    use super::super::multichannel::multi_welch_finite;
    use super::super::test_support::{Gaussian, assert_rel_close};
    use super::super::{Complex, Detrend, csd, multi_welch, welch};
    use super::*;

    #[test]
    fn splits_land_on_batch_boundaries_by_share() {
        let cfg = WelchConfig::hann(1.0, 4096);
        let one = batches(&[0..36_000], &cfg, None);
        assert_eq!(one.iter().map(|b| b.count).sum::<usize>(), 16);
        assert_eq!(split_point(&one, (1, 2)), 2);
        assert_eq!(split_point(&one, (1, 4)), 1);
        assert_eq!(split_point(&one, (1, 3)), 1);
        assert_eq!(split_point(&one, (1, 1)), 3);
        assert_eq!(split_point(&one[..1], (1, 2)), 1);
        assert_eq!(parts(PARALLEL_WORK - 1), 1);
        assert_eq!(parts(PARALLEL_WORK), 2);
        assert_eq!(parts(16 * 12 * 4096), 2);
        assert_eq!(parts(usize::MAX), MAX_PARTS);
        let two = batches(&[0..20_480, 30_000..50_480], &cfg, None);
        let counts: Vec<usize> = two.iter().map(|b| b.count).collect();
        assert_eq!(counts, vec![4, 4, 1, 4, 4, 1]);
        assert_eq!(split_point(&two, (1, 2)), 3);
    }

    /// A cut ends a batch at that segment, in whichever block it falls, so
    /// that the split by its share lands exactly on it.
    #[test]
    fn a_cut_ends_a_batch_where_the_share_splits() {
        let cfg = WelchConfig::hann(1.0, 4096);
        let counts = |b: &[Batch]| b.iter().map(|b| b.count).collect::<Vec<_>>();
        let one = batches(&[0..36_000], &cfg, Some(10));
        assert_eq!(counts(&one), vec![4, 4, 2, 4, 2]);
        assert_eq!(split_point(&one, (5, 8)), 3);
        let two = batches(&[0..20_480, 30_000..50_480], &cfg, Some(12));
        assert_eq!(counts(&two), vec![4, 4, 1, 3, 4, 2]);
        assert_eq!(two[3].first, 0);
        assert_eq!(two[4].first, 3);
        assert_eq!(split_point(&two, (2, 3)), 4);
        // A cut at a block's edge or beyond the end changes nothing.
        for cut in [0, 9, 18, 40] {
            let b = batches(&[0..20_480, 30_000..50_480], &cfg, Some(cut));
            assert_eq!(counts(&b), vec![4, 4, 1, 4, 4, 1], "cut {cut}");
        }
    }

    /// The two-thread estimate (large enough to be split) equals the
    /// single-channel functions, which sum every segment in one running
    /// sum, to 1e-12 relative.
    #[test]
    fn split_estimate_equals_one_running_sum() {
        let mut g = Gaussian::new(77);
        let n = 30_000;
        let chans: Vec<Vec<f64>> = (0..6)
            .map(|c| {
                (0..n)
                    .map(|i| g.sample() + c as f64 + 1e-4 * i as f64)
                    .collect()
            })
            .collect();
        let refs: Vec<&[f64]> = chans.iter().map(Vec::as_slice).collect();
        let pairs = [(0, 3), (1, 4), (5, 2), (2, 2)];
        for cfg in [
            WelchConfig::hann(10.0, 256),
            WelchConfig::hann(10.0, 256).with_detrend(Detrend::Linear),
        ] {
            let n_seg = cfg.n_segments(n);
            let list = batches(&[0..n], &cfg, None);
            assert!(parts(n_seg * 6 * 256) >= 2);
            assert!(split_point(&list, (1, 2)) < list.len());
            let s = multi_welch(&refs, &[0..n], &pairs, &cfg).unwrap();
            // The quality report's uneven split, left as summed.
            let summed = multi_welch_finite(&refs, &[0..n], &pairs, &cfg, (5, 8)).unwrap();
            for (c, x) in refs.iter().enumerate() {
                let w = welch(x, &cfg).unwrap().values;
                assert_rel_close(&s.auto[c], &w, 1e-12, "auto");
                assert_rel_close(&summed.auto[c], &w, 1e-12, "auto, 5/8 split");
            }
            for (p, &(i, j)) in pairs.iter().enumerate() {
                let e = csd(refs[i], refs[j], &cfg).unwrap().values;
                let scale = e.iter().fold(0.0f64, |m, v| m.max(v.norm()));
                let (mut re, mut im) = (Vec::new(), Vec::new());
                summed.cross_into(p, &mut re, &mut im);
                for (k, (a, e)) in s.cross[p].iter().zip(&e).enumerate() {
                    let d: Complex<f64> = a - e;
                    assert!(d.norm() <= 1e-12 * scale, "pair {p}: {a} vs {e}");
                    let d = Complex::new(re[k], im[k]) - e;
                    assert!(d.norm() <= 1e-12 * scale, "pair {p}, 5/8 split, bin {k}");
                }
            }
        }
    }
}
