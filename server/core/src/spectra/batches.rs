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
/// start, [`BATCH`] at a time.
pub(super) fn batches(blocks: &[Range<usize>], cfg: &WelchConfig) -> Vec<Batch> {
    blocks
        .iter()
        .flat_map(|block| {
            let n_block = cfg.n_segments(block.len());
            (0..n_block).step_by(BATCH).map(move |first| Batch {
                block: block.clone(),
                first,
                count: BATCH.min(n_block - first),
            })
        })
        .collect()
}

/// Index of the first batch of the second half: the first batch boundary
/// at or after half of the `n_segments` segments, or `batches.len()` (no
/// split) below [`PARALLEL_WORK`] samples transformed or with one batch.
/// Depends on the sizes only.
pub(super) fn split_point(batches: &[Batch], n_segments: usize, work: usize) -> usize {
    if work < PARALLEL_WORK || batches.len() < 2 {
        return batches.len();
    }
    let mut seen = 0;
    batches
        .iter()
        .position(|b| {
            seen += b.count;
            2 * seen >= n_segments
        })
        .map_or(batches.len(), |i| (i + 1).min(batches.len() - 1))
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
    let mut spec = engine.make_output();
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
                    let offset =
                        engine.transform_centred(samples, shift, &channel[ahead], &mut spec)?;
                    if check_finite && !offset.is_finite() {
                        require_finite_channel(c, channel, std::slice::from_ref(&(start..end)))?;
                    }
                    mean = shift + offset;
                } else {
                    engine.transform(&channel[block.clone()], m, &mut spec)?;
                }
                acc.add_channel(slot, c, &spec);
            }
        }
        acc.add_segments(count);
    }
    Ok(())
}

#[cfg(test)]
#[allow(clippy::single_range_in_vec_init)] // vectors of blocks
mod tests {
    use super::super::test_support::{Gaussian, assert_rel_close};
    use super::super::{Complex, Detrend, csd, multi_welch, welch};
    use super::*;

    #[test]
    fn split_lands_on_a_batch_boundary_near_the_middle() {
        let cfg = WelchConfig::hann(1.0, 4096);
        let one = batches(&[0..36_000], &cfg);
        assert_eq!(one.iter().map(|b| b.count).sum::<usize>(), 16);
        assert_eq!(split_point(&one, 16, 16 * 12 * 4096), 2);
        assert_eq!(split_point(&one, 16, PARALLEL_WORK - 1), one.len());
        let two = batches(&[0..20_480, 30_000..50_480], &cfg);
        let counts: Vec<usize> = two.iter().map(|b| b.count).collect();
        assert_eq!(counts, vec![4, 4, 1, 4, 4, 1]);
        assert_eq!(split_point(&two, 18, usize::MAX), 3);
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
            let list = batches(&[0..n], &cfg);
            assert!(split_point(&list, n_seg, n_seg * 6 * 256) < list.len());
            let s = multi_welch(&refs, &[0..n], &pairs, &cfg).unwrap();
            for (c, x) in refs.iter().enumerate() {
                let w = welch(x, &cfg).unwrap().values;
                assert_rel_close(&s.auto[c], &w, 1e-12, "auto");
            }
            for (p, &(i, j)) in pairs.iter().enumerate() {
                let e = csd(refs[i], refs[j], &cfg).unwrap().values;
                let scale = e.iter().fold(0.0f64, |m, v| m.max(v.norm()));
                for (a, e) in s.cross[p].iter().zip(&e) {
                    let d: Complex<f64> = a - e;
                    assert!(d.norm() <= 1e-12 * scale, "pair {p}: {a} vs {e}");
                }
            }
        }
    }
}
