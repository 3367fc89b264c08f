//! How well each input excites the vessel: persistence-of-excitation order,
//! usable band, RMS, and power near the log's Nyquist frequency.

use std::ops::Range;

use super::record::sum;
use super::words::{band, num, pct};
use super::{InputQuality, NyquistCheck};
use crate::planning::analysis::usable_band;
use crate::signals::{DEFAULT_PE_TOL, pe_order};
use crate::spectra::Spectrum;

/// Cap of the persistence-of-excitation order computed per input. An ARX
/// model of a DOF with `na = nb = 2` needs PE ≥ 2 per input; 24 leaves room
/// for the richer models of the later identification steps (e.g. 12 lags
/// of a coupled MIMO model) while keeping the `cap × cap` covariance cheap.
pub const PE_CAP: usize = 24;

/// Share of the band below the log's Nyquist frequency checked for power:
/// the top 20 %, `[0.8 · fs/2, fs/2]`.
pub const NYQUIST_TOP_FRACTION: f64 = 0.2;

/// Largest fraction of an input's power (DC excluded) allowed in the top
/// band before the Nyquist warning fires. A planned PRBS clocked at ≥ 2
/// samples puts ≈ 1–2 % there, a signal that alternates from sample to
/// sample (a faster controller seen by a slower logger) ≈ 100 %, and white
/// noise at the log rate 20 %, which also warns: nothing in such a log
/// tells whether the input changed between samples.
pub const NYQUIST_POWER_LIMIT: f64 = 0.05;

/// Samples of the first window tried by [`pe_over_blocks`] before the
/// whole block (see there).
const PE_WINDOW: usize = 2048;

/// Persistence-of-excitation order of `x` over the valid blocks: the
/// largest [`pe_order`] of any block's deviation from that block's mean
/// (each block's own operating point), capped at [`PE_CAP`] and, for a
/// block of `n` samples, at `n / 2`. Returns `(order, cap used)`. The
/// blocks are not concatenated: a jump across a gap would count as
/// excitation.
///
/// Shortcut (exact up to the rank tolerance): the block's first
/// [`PE_WINDOW`] samples are tried first. Their regressors are a subset of
/// the block's, and the covariance of the block is the sum of positive
/// semi-definite terms, so its rank is at least the window's; when the
/// window already reaches the cap, so does the block, and the block's
/// O(n · cap) covariance is skipped. Any excited input (PRBS, multisine,
/// noise) reaches the cap of 24 within 2048 samples; a constant or poorly
/// excited one falls through to the whole block.
///
/// `block_mean`: the mean of `x` over the blocks, when known — with a single
/// block it is that block's mean, and the sum is skipped.
pub(crate) fn pe_over_blocks(
    x: &[f64],
    blocks: &[Range<usize>],
    block_mean: Option<f64>,
) -> (usize, usize) {
    let mut best = (0, 0);
    let mut dev = Vec::new();
    for b in blocks {
        let cap = PE_CAP.min(b.len() / 2);
        if cap == 0 {
            continue;
        }
        let seg = &x[b.clone()];
        let mean = match block_mean {
            Some(m) if blocks.len() == 1 => m,
            _ => sum(seg) / seg.len() as f64,
        };
        // Valid input by construction (finite, long enough, cap in range).
        let mut pe = |u: &[f64]| {
            dev.clear();
            dev.extend(u.iter().map(|v| v - mean));
            pe_order(&dev, cap, DEFAULT_PE_TOL).unwrap_or(0)
        };
        let order = if seg.len() > PE_WINDOW && pe(&seg[..PE_WINDOW]) == cap {
            cap
        } else {
            pe(seg)
        };
        if (order, cap) > best {
            best = (order, cap);
        }
        if order == PE_CAP {
            break;
        }
    }
    best
}

/// Fraction of the power of `psd` (DC excluded) in the top
/// [`NYQUIST_TOP_FRACTION`] of the band below the Nyquist frequency of a
/// log at `fs`, and the warning when it exceeds [`NYQUIST_POWER_LIMIT`].
pub(crate) fn nyquist_check(
    name: &str,
    freqs: &[f64],
    psd: &[f64],
    fs: f64,
    controller_rate_hz: Option<f64>,
) -> NyquistCheck {
    let nyquist_hz = fs / 2.0;
    let low = (1.0 - NYQUIST_TOP_FRACTION) * nyquist_hz;
    let (mut total, mut top) = (0.0, 0.0);
    for (f, p) in freqs.iter().zip(psd).skip(1) {
        total += p;
        if *f >= low {
            top += p;
        }
    }
    let power_fraction = if total > 0.0 { top / total } else { 0.0 };
    let warning = (power_fraction > NYQUIST_POWER_LIMIT).then(|| {
        let example = match controller_rate_hz {
            Some(c) if c > fs => format!("the controller ran at {} Hz", num(c)),
            _ => format!("e.g. a {} Hz controller logged at {} Hz", num(2.0 * fs), num(fs)),
        };
        format!(
            "{name} has power near the {} Hz Nyquist frequency of the log ({} of its power above {} Hz): \
             it may have been logged slower than the controller ran ({example}); \
             inputs between samples are unknown",
            num(nyquist_hz),
            pct(power_fraction),
            num(low)
        )
    });
    NyquistCheck {
        nyquist_hz,
        band_hz: [low, nyquist_hz],
        power_fraction,
        warning,
    }
}

/// Everything the report says about one input, from its statistics, its
/// PE order and cap ([`pe_over_blocks`]) and its PSD.
pub(crate) fn input_quality(
    name: &str,
    (mean, rms): (f64, f64),
    (pe_order, pe_cap): (usize, usize),
    freqs: &[f64],
    psd: Vec<f64>,
    fs: f64,
    controller_rate_hz: Option<f64>,
) -> InputQuality {
    let spectrum = Spectrum {
        freqs: freqs.to_vec(),
        values: psd,
    };
    let usable_band_hz = usable_band(&spectrum);
    let nyquist = nyquist_check(name, freqs, &spectrum.values, fs, controller_rate_hz);
    InputQuality {
        name: name.to_owned(),
        mean,
        rms,
        psd: spectrum.values,
        pe_order,
        pe_cap,
        usable_band_hz,
        nyquist,
    }
}

/// Description of an input's excitation for messages: operating point,
/// RMS about it, PE order (with "≥" at the cap) and usable band.
pub(crate) fn describe(q: &InputQuality) -> String {
    let pe = if q.pe_order >= q.pe_cap && q.pe_cap > 0 {
        format!("PE order ≥ {}", q.pe_order)
    } else {
        format!("PE order {}", q.pe_order)
    };
    let level = format!("mean {}, RMS {}", num(q.mean), num(q.rms));
    match q.usable_band_hz {
        Some(b) => format!("{pe}, {level}, usable band {}", band(b)),
        None => format!("{pe}, {level}"),
    }
}
