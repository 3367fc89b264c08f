//! The report's spectra: every input and output PSD and, for every
//! input → output pair, |CSD|, coherence and the H1 Bode data, from one
//! [`multi_welch`] pass.

use super::fastmath::{arg_into, log10_into};
use super::record::Prepared;
use super::{PairSpectra, QualityError, WelchSummary};
use crate::spectra::multichannel::multi_welch_finite;
use crate::spectra::unwrap_into;
use crate::spectra::{Complex, WelchConfig};

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
/// every (input, output).
pub(crate) fn compute(prep: &Prepared<'_>) -> Result<SpectralPart, QualityError> {
    let cfg = WelchConfig::hann(prep.fs, prep.nperseg);
    let ni = prep.inputs.len();
    let no = prep.outputs.len();
    let channels: Vec<&[f64]> = prep.inputs.iter().chain(&prep.outputs).copied().collect();
    let pairs: Vec<(usize, usize)> = (0..ni)
        .flat_map(|i| (0..no).map(move |o| (i, ni + o)))
        .collect();
    // Finite inside the blocks: checked by `prepare`.
    let ms = multi_welch_finite(&channels, &prep.blocks, &pairs, &cfg)?;

    let mut scratch = Scratch::default();
    let pair_spectra = pairs
        .iter()
        .enumerate()
        .map(|(p, &(i, o))| {
            pair_spectra(
                prep.input_names[i],
                prep.output_names[o - ni],
                &ms.cross[p],
                &ms.auto[i],
                &ms.auto[o],
                &mut scratch,
            )
        })
        .collect();
    let welch = WelchSummary {
        nperseg: cfg.nperseg,
        noverlap: cfg.noverlap,
        n_segments: ms.n_segments,
        df_hz: cfg.df(),
        segment_s: cfg.nperseg as f64 / prep.fs,
    };
    let mut auto = ms.auto;
    let output_psd = auto.split_off(ni);
    Ok(SpectralPart {
        welch,
        freqs: ms.freqs,
        input_psd: auto,
        output_psd,
        pairs: pair_spectra,
    })
}

/// The plotted spectra of one pair from its CSD and the two PSDs.
///
/// Same definitions as [`crate::spectra::CrossSpectra::coherence`] and
/// [`crate::spectra::TransferEstimate`] (H1 = Pxy / Pxx, 0 where Pxx = 0;
/// numpy's `unwrap(angle(H1))`), computed without `hypot`, with
/// `|H1| = |Pxy| / Pxx` and `arg H1 = arg Pxy` (`Pxx > 0`), and with the
/// vectorised `atan2`/`log10` and the fast (bit-identical) unwrap of
/// [`super::fastmath`]. Results may differ from those functions in the
/// last bits (≤ 2–3 ulp before unwrapping).
fn pair_spectra(
    input: &str,
    output: &str,
    pxy: &[Complex<f64>],
    pxx: &[f64],
    pyy: &[f64],
    scratch: &mut Scratch,
) -> PairSpectra {
    let nf = pxy.len();
    let inv = |p: f64| if p == 0.0 { 0.0 } else { 1.0 / p };
    let csd_magnitude: Vec<f64> = pxy.iter().map(|c| c.norm_sqr().sqrt()).collect();
    let coherence = pxy
        .iter()
        .zip(pxx.iter().zip(pyy))
        .map(|(c, (&a, &b))| c.norm_sqr() * inv(a) * inv(b))
        .collect();
    let h1_magnitude: Vec<f64> = csd_magnitude
        .iter()
        .zip(pxx)
        .map(|(m, &a)| m * inv(a))
        .collect();
    let mut h1_magnitude_db = vec![0.0; nf];
    log10_into(&h1_magnitude, &mut h1_magnitude_db);
    h1_magnitude_db.iter_mut().for_each(|d| *d *= 20.0);
    let phase = &mut scratch.phase;
    phase.resize(nf, 0.0);
    arg_into(pxy, &mut scratch.re, &mut scratch.im, phase);
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
    re: Vec<f64>,
    im: Vec<f64>,
    phase: Vec<f64>,
}
