//! [`quality_report`]: runs every analysis of the module on one log and
//! assembles the report.

use super::MIN_INPUT_SHARE;
use super::adherence::adherence;
use super::excitation::{input_quality, pe_over_blocks};
use super::record::prepare;
use super::regressor::{analyse, sub_identifiable};
use super::spectra::{compute, pair_index};
use super::verdict::{DofContext, and_list, judge};
use super::{OutputQuality, QualityError, QualityReport, QualitySpec};
use crate::spectra::default_nperseg;
use crate::timeseries::UniformRecord;

/// Welch segment length of the report when the spec gives none:
/// [`default_nperseg`] of the longest valid block — the largest power of
/// two ≤ a quarter of it, within 64..=4096 samples.
///
/// Why: segments live inside one block, so the longest block bounds them;
/// a quarter of it gives ≥ 7 half-overlapping segments there (coherence
/// from fewer is biased upwards), and 4096 samples at 10 Hz resolve
/// 0.0024 Hz, fine enough for the slowest DP-ship dynamics (time constants
/// of minutes), while any longer log only adds segments. A 1-hour log at
/// 10 Hz (36,000 samples) gets 4096 (16 segments), a 10-minute run 1024
/// (10 segments at 0.0098 Hz).
pub fn default_quality_nperseg(longest_block: usize) -> usize {
    default_nperseg(longest_block)
}

/// The data-quality report of `rec` for `spec` (see the
/// [module documentation](super)).
///
/// Cost, for N valid samples of C = inputs + outputs channels, I × O pairs
/// and segment length S: C·N/S·2 real FFTs of length S and
/// O(N·(C + I·O)) spectral multiply-adds; O(N·C²·lags) for the regressor's
/// Gram matrix; O(N·24) per input for the PE order; and per planned column
/// 7 FFTs of the log plus schedule length.
///
/// # Errors
/// [`QualityError`] naming the field: a record without valid samples, bad
/// sample rate, ragged columns or blocks out of range; a spec with no
/// inputs or outputs, a duplicated or missing column, a DOF whose input or
/// output is not listed, `nperseg` 0 or longer than the longest valid
/// block, a non-positive controller rate, zero or too many regressor lags,
/// or an invalid plan; a NaN or infinite sample inside a valid block.
pub fn quality_report(
    rec: &UniformRecord,
    spec: &QualitySpec,
) -> Result<QualityReport, QualityError> {
    // On a thread of rayon's pool from the start, so that the buffers the
    // spectra keep per thread are taken and given back on the same one
    // (from a thread outside the pool, each hand-off would land elsewhere
    // and every call would fault fresh pages in).
    if rayon::current_thread_index().is_none() {
        return rayon::join(|| quality_report(rec, spec), || ()).0;
    }
    let prep = prepare(rec, spec)?;
    let fs = prep.fs;
    let no = prep.outputs.len();

    // Φ = (Φ_y Φ_x): outputs first.
    let names: Vec<&str> = prep
        .output_names
        .iter()
        .chain(&prep.input_names)
        .copied()
        .collect();
    let channels: Vec<&[f64]> = prep.outputs.iter().chain(&prep.inputs).copied().collect();
    let lags = spec.regressor_lags;
    // The spectra and the time-domain analyses (the regressor's Gram
    // matrix with every channel's statistics, in one pass; then the PE
    // orders, which centre on the means) read the same samples and nothing
    // of each other: on two threads. The time-domain part starts at once
    // on the other thread, which then takes the Welch estimate's second
    // part (the smaller, see `spectra::TIME_DOMAIN_SHARE`); the pairs' plotted
    // spectra split finely, so the threads end together. A non-finite
    // sample is found by the statistics (the spectra do not look; they are
    // then dropped).
    let (spectral, time_domain) = crate::par::join(
        true,
        || compute(&prep),
        || {
            let regressor = analyse(&names, &channels, no, &prep.blocks, lags)?;
            let pe: Vec<_> = prep
                .inputs
                .iter()
                .zip(&regressor.stats[no..])
                .map(|(x, &(mean, _))| pe_over_blocks(x, &prep.blocks, Some(mean)))
                .collect();
            Ok::<_, QualityError>((regressor, pe))
        },
    );
    let (mut regressor, pe) = time_domain?;
    let spectral = spectral?;
    let in_stats = regressor.stats.split_off(no);
    let out_stats = std::mem::take(&mut regressor.stats);

    let inputs: Vec<_> = prep
        .input_names
        .iter()
        .zip(spectral.input_psd)
        .zip(&in_stats)
        .zip(pe)
        .map(|(((name, psd), &stats), pe)| {
            input_quality(
                name,
                stats,
                pe,
                &spectral.freqs,
                psd,
                fs,
                spec.controller_rate_hz,
            )
        })
        .collect();
    let outputs: Vec<OutputQuality> = prep
        .output_names
        .iter()
        .zip(spectral.output_psd)
        .zip(&out_stats)
        .map(|((name, psd), &(mean, rms))| OutputQuality {
            name: (*name).to_owned(),
            mean,
            rms,
            psd,
        })
        .collect();

    let mut adherences = Vec::new();
    if let Some(plan) = &spec.planned {
        for (log_col, sched, values) in &plan.columns {
            // Present and finite: checked by `prepare`.
            let log = rec.column(log_col).unwrap_or_default();
            adherences.push(adherence(
                log_col,
                sched,
                log,
                &prep.blocks,
                fs,
                values,
                plan.sample_rate_hz,
            )?);
        }
    }

    let mut dofs = Vec::with_capacity(spec.dofs.len());
    for (d, &(i, o)) in spec.dofs.iter().zip(&prep.dof_pairs) {
        // Columns of the DOF's output (channel o) and input (channel no + i).
        let own: Vec<usize> = (0..lags)
            .map(|l| o * lags + l)
            .chain((0..lags).map(|l| (no + i) * lags + l))
            .collect();
        let own_rank = (sub_identifiable(&regressor.gram, &own)?, own.len());
        dofs.push(judge(&DofContext {
            dof: d,
            input: &inputs[i],
            freqs: &spectral.freqs,
            coherence: &spectral.pairs[pair_index(i, o, no)].coherence,
            welch: &spectral.welch,
            fs,
            adherence: &adherences,
            regressor: &regressor.report,
            own_rank,
            planned: spec.planned.is_some(),
        }));
    }

    let r = &regressor.report;
    let mut warnings: Vec<String> = inputs
        .iter()
        .filter_map(|q| q.nyquist.warning.clone())
        .collect();
    warnings.extend(
        adherences
            .iter()
            .filter(|a| !a.followed)
            .map(|a| a.message.clone()),
    );
    let by_inputs: Vec<String> = r
        .deficient_directions
        .iter()
        .filter(|d| d.input_share >= MIN_INPUT_SHARE)
        .map(|d| {
            let cols: Vec<&str> = d.columns.iter().map(|c| c.column.as_str()).collect();
            format!("{} ({} lost)", and_list(&cols), d.dimension)
        })
        .collect();
    if !by_inputs.is_empty() {
        warnings.push(format!(
            "the regressor determines {} of its {} parameters; dead or collinear input columns: {}",
            r.identifiable,
            r.n_columns,
            by_inputs.join("; ")
        ));
    }

    Ok(QualityReport {
        sample_rate_hz: fs,
        n_samples: prep.n_samples,
        n_valid_samples: prep.n_valid(),
        valid_duration_s: prep.n_valid() as f64 / fs,
        welch: spectral.welch,
        freqs_hz: spectral.freqs,
        inputs,
        outputs,
        pairs: spectral.pairs,
        regressor: regressor.report,
        adherence: adherences,
        dofs,
        warnings,
    })
}
