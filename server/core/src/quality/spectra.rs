//! The report's spectra: every input and output PSD and, for every
//! input → output pair, |CSD|, coherence and the H1 Bode data, from one
//! [`multi_welch`] pass.

use super::fastmath::{atan2_into, log10_into};
use super::record::Prepared;
use super::{PairSpectra, QualityError, WelchSummary};
use crate::spectra::WelchConfig;
use crate::spectra::multichannel::multi_welch_finite;
use crate::spectra::{cross_from_parts, unwrap_into};

/// Pair bins (pairs × frequencies) from which the pairs' Bode data are
/// spread over the pool: 8 pairs of 2049 bins take ~0.2 ms, many times a
/// hand-off.
const PARALLEL_BINS: usize = 1 << 14;

/// The share of the Welch segments summed by the report's first thread:
/// the other thread first computes the time-domain analyses (about 30 %
/// of the spectra's work on a 6 × 6 log), then the rest of the segments.
pub(crate) const TIME_DOMAIN_SHARE: (usize, usize) = (5, 8);

/// Pairs per task on the pool: small tasks (~0.05 ms for 2049 bins), so
/// that a thread that comes late to the pairs still takes its share.
const PAIRS_PER_TASK: usize = 2;

/// The spectral part of the report.
pub(crate) struct SpectralPart {
    /// Welch parameters used.
    pub welch: WelchSummary,
    /// Frequency grid (Hz).
    pub freqs: Vec<f64>,
    /// PSD of each input.
    pub input_psd: Vec<Vec<f64>>,
    /// PSD of each output.
    pub output_psd: Vec<Vec<f64>>,
    /// Input-major pairs: `pairs[i · n_outputs + o]` is input i → output o.
    pub pairs: Vec<PairSpectra>,
}

/// Index of the pair input `i` → output `o` in [`SpectralPart::pairs`].
pub(crate) fn pair_index(i: usize, o: usize, n_outputs: usize) -> usize {
    i * n_outputs + o
}

/// Computes all spectra: channels are the inputs then the outputs, pairs
/// every (input, output). Samples are not checked for finiteness here (a
/// NaN gives NaN spectra, never a panic): the caller's statistics do.
pub(crate) fn compute(prep: &Prepared<'_>) -> Result<SpectralPart, QualityError> {
    let cfg = WelchConfig::hann(prep.fs, prep.nperseg);
    let ni = prep.inputs.len();
    let no = prep.outputs.len();
    let channels: Vec<&[f64]> = prep.inputs.iter().chain(&prep.outputs).copied().collect();
    let pairs: Vec<(usize, usize)> = (0..ni)
        .flat_map(|i| (0..no).map(move |o| (i, ni + o)))
        .collect();
    let mut ms = multi_welch_finite(&channels, &prep.blocks, &pairs, &cfg, TIME_DOMAIN_SHARE)?;

    // Pairs are independent: spread over the pool when there are enough
    // of them (each pair's result is the same on any thread).
    // 1/P per channel, 0 where P = 0: shared by the channel's pairs.
    let inv: Vec<Vec<f64>> = ms
        .auto
        .iter()
        .map(|p| {
            p.iter()
                .map(|&v| if v == 0.0 { 0.0 } else { 1.0 / v })
                .collect()
        })
        .collect();
    let one = |scratch: &mut Scratch, p: usize| {
        let (i, o) = pairs[p];
        pair_spectra(
            prep.input_names[i],
            prep.output_names[o - ni],
            ms.pair_sums(p),
            (&ms.auto[i], &inv[i]),
            &inv[o],
            scratch,
        )
    };
    let pair_spectra: Vec<PairSpectra> =
        if pairs.len().saturating_mul(cfg.n_freqs()) >= PARALLEL_BINS {
            use rayon::prelude::*;
            (0..pairs.len())
                .into_par_iter()
                .with_max_len(PAIRS_PER_TASK)
                .map_init(Scratch::default, one)
                .collect()
        } else {
            let mut scratch = Scratch::default();
            (0..pairs.len()).map(|p| one(&mut scratch, p)).collect()
        };
    let welch = WelchSummary {
        nperseg: cfg.nperseg,
        noverlap: cfg.noverlap,
        n_segments: ms.n_segments,
        df_hz: cfg.df(),
        segment_s: cfg.nperseg as f64 / prep.fs,
    };
    let freqs = std::mem::take(&mut ms.freqs);
    let mut auto = std::mem::take(&mut ms.auto);
    let output_psd = auto.split_off(ni);
    Ok(SpectralPart {
        welch,
        freqs,
        input_psd: auto,
        output_psd,
        pairs: pair_spectra,
    })
}

/// The plotted spectra of one pair from its Welch sums (the parts, added
/// in order, times the density factors: its CSD), its input PSD and the
/// reciprocals of both PSDs (0 where a PSD is 0).
///
/// Same definitions as [`crate::spectra::CrossSpectra::coherence`] and
/// [`crate::spectra::TransferEstimate`] (H1 = Pxy / Pxx, 0 where Pxx = 0;
/// numpy's `unwrap(angle(H1))`), computed without `hypot`, with
/// `|H1| = |Pxy| / Pxx` and `arg H1 = arg Pxy` (`Pxx > 0`), and with the
/// vectorised `atan2`/`log10` and the fast (bit-identical) unwrap of
/// [`super::fastmath`]. Results may differ from those functions in the
/// last bits (≤ 2–3 ulp before unwrapping). On CPUs with AVX2 the
/// element-wise loops run in 4-lane registers (no fused multiply–adds: the
/// same values bit for bit).
fn pair_spectra(
    input: &str,
    output: &str,
    sums: (Vec<&[f64]>, &[f64]),
    pxx: (&[f64], &[f64]),
    inv_pyy: &[f64],
    scratch: &mut Scratch,
) -> PairSpectra {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has the feature the function is compiled for.
        return unsafe { pair_spectra_avx2(input, output, sums, pxx, inv_pyy, scratch) };
    }
    pair_spectra_body(input, output, sums, pxx, inv_pyy, scratch)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn pair_spectra_avx2(
    input: &str,
    output: &str,
    sums: (Vec<&[f64]>, &[f64]),
    pxx: (&[f64], &[f64]),
    inv_pyy: &[f64],
    scratch: &mut Scratch,
) -> PairSpectra {
    pair_spectra_body(input, output, sums, pxx, inv_pyy, scratch)
}

#[inline(always)]
fn pair_spectra_body(
    input: &str,
    output: &str,
    (parts, factors): (Vec<&[f64]>, &[f64]),
    (pxx, inv_pxx): (&[f64], &[f64]),
    inv_pyy: &[f64],
    scratch: &mut Scratch,
) -> PairSpectra {
    let Scratch {
        re,
        im,
        log10,
        phase,
    } = scratch;
    cross_from_parts(&parts, factors, re, im);
    let (re_all, im_all) = (&re[..], &im[..]);
    let nf = re_all.len();
    // |Pxy|² as `Complex::norm_sqr` (re² + im²); collected, not zeroed
    // and then written.
    let n = nf.min(inv_pxx.len()).min(inv_pyy.len());
    let (re, im) = (&re_all[..n], &im_all[..n]);
    let csd_magnitude: Vec<f64> = re
        .iter()
        .zip(im)
        .map(|(r, i)| (r * r + i * i).sqrt())
        .collect();
    let coherence: Vec<f64> = re
        .iter()
        .zip(im)
        .zip(inv_pxx.iter().zip(inv_pyy))
        .map(|((r, i), (&a, &b))| (r * r + i * i) * a * b)
        .collect();
    let h1_magnitude: Vec<f64> = csd_magnitude
        .iter()
        .zip(inv_pxx)
        .map(|(m, &a)| m * a)
        .collect();
    log10.resize(n, 0.0);
    log10_into(&h1_magnitude, log10);
    let h1_magnitude_db: Vec<f64> = log10.iter().map(|d| d * 20.0).collect();
    phase.resize(nf, 0.0);
    atan2_into(im_all, re_all, phase);
    for (p, &a) in phase.iter_mut().zip(pxx) {
        if a == 0.0 {
            *p = 0.0;
        }
    }
    let mut h1_phase_unwrapped_rad = Vec::with_capacity(nf);
    unwrap_into(phase, &mut h1_phase_unwrapped_rad);
    PairSpectra {
        input: input.to_owned(),
        output: output.to_owned(),
        csd_magnitude,
        coherence,
        h1_magnitude,
        h1_magnitude_db,
        h1_phase_unwrapped_rad,
    }
}

/// Buffers reused from pair to pair.
#[derive(Default)]
struct Scratch {
    /// `Re P_xy`, `Im P_xy`.
    re: Vec<f64>,
    im: Vec<f64>,
    log10: Vec<f64>,
    phase: Vec<f64>,
}
