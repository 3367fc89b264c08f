//! Checks a record and a spec against each other and gathers what the
//! analyses need: the channels by role, the valid blocks, the Welch
//! segment length and per-channel statistics over the valid samples.

use std::collections::HashSet;
use std::ops::Range;

use super::regressor::MAX_REGRESSOR_COLUMNS;
use super::report::default_quality_nperseg;
use super::{QualityError, QualitySpec};
use crate::timeseries::UniformRecord;

/// Most values per spectrum of the report (pairs × frequencies): 4 Mi, i.e.
/// ≈ 170 MB for the five spectra of every pair. A 6 × 6 report with
/// `nperseg = 4096` holds 74 k.
pub const MAX_PAIR_BINS: usize = 1 << 22;

/// Valid samples (all channels) from which the statistics are computed
/// on two threads: ~0.2 ms of reading, several times a thread's start.
const PARALLEL_SAMPLES: usize = 1 << 18;

/// A validated request: borrowed channels, the non-empty valid blocks and
/// the resolved parameters.
pub(crate) struct Prepared<'a> {
    /// Sample rate of the log (Hz).
    pub fs: f64,
    /// Samples in the log.
    pub n_samples: usize,
    /// Valid blocks, ascending, disjoint, non-empty.
    pub blocks: Vec<Range<usize>>,
    /// Input names and samples, in spec order.
    pub input_names: Vec<&'a str>,
    /// Input samples.
    pub inputs: Vec<&'a [f64]>,
    /// Output names, in spec order.
    pub output_names: Vec<&'a str>,
    /// Output samples.
    pub outputs: Vec<&'a [f64]>,
    /// Mean and RMS about it of each input over the valid samples.
    pub input_stats: Vec<(f64, f64)>,
    /// Mean and RMS about it of each output over the valid samples.
    pub output_stats: Vec<(f64, f64)>,
    /// `(input index, output index)` of each DOF of the spec.
    pub dof_pairs: Vec<(usize, usize)>,
    /// Welch segment length.
    pub nperseg: usize,
}

impl Prepared<'_> {
    /// Samples inside the valid blocks.
    pub fn n_valid(&self) -> usize {
        self.blocks.iter().map(|b| b.len()).sum()
    }
}

/// Mean and RMS about the mean of `x` over `blocks` (0, 0 without samples;
/// non-finite when a sample is), in one pass: sums of `x − x₀` and
/// `(x − x₀)²` about the first valid sample `x₀`, eight partial sums each
/// (vectorised). The shift keeps the variance accurate unless the mean
/// lies ~10⁶ standard deviations from `x₀` (relative error ≈ 1e-16 ·
/// ((mean − x₀)/σ)²).
pub(crate) fn mean_rms(x: &[f64], blocks: &[Range<usize>]) -> (f64, f64) {
    let n: usize = blocks.iter().map(|b| b.len()).sum();
    let Some(x0) = blocks.iter().find(|b| !b.is_empty()).map(|b| x[b.start]) else {
        return (0.0, 0.0);
    };
    let (mut s1, mut s2) = (0.0, 0.0);
    for b in blocks {
        let (a, c) = shifted_sums(&x[b.clone()], x0);
        s1 += a;
        s2 += c;
    }
    let nf = n as f64;
    let d = s1 / nf;
    // Rounding can leave a tiny negative; a NaN must stay (max would drop it).
    let var = s2 / nf - d * d;
    let var = if var < 0.0 { 0.0 } else { var };
    (x0 + d, var.sqrt())
}

/// `(Σ (x − c), Σ (x − c)²)` with eight independent partial sums each.
fn shifted_sums(x: &[f64], c: f64) -> (f64, f64) {
    let (mut a1, mut a2) = ([0.0f64; 8], [0.0f64; 8]);
    let chunks = x.chunks_exact(8);
    let (mut t1, mut t2) = (0.0, 0.0);
    for v in chunks.remainder() {
        t1 += v - c;
        t2 += (v - c) * (v - c);
    }
    for ch in chunks {
        for k in 0..8 {
            let d = ch[k] - c;
            a1[k] += d;
            a2[k] += d * d;
        }
    }
    let fold = |a: [f64; 8]| ((a[0] + a[1]) + (a[2] + a[3])) + ((a[4] + a[5]) + (a[6] + a[7]));
    (fold(a1) + t1, fold(a2) + t2)
}

/// `Σ x` with eight independent partial sums (vectorised).
pub(crate) fn sum(x: &[f64]) -> f64 {
    let mut acc = [0.0f64; 8];
    let chunks = x.chunks_exact(8);
    let tail: f64 = chunks.remainder().iter().sum();
    for ch in chunks {
        for (a, v) in acc.iter_mut().zip(ch) {
            *a += v;
        }
    }
    ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7])) + tail
}

/// Validates `rec` and `spec` and resolves the channels.
pub(crate) fn prepare<'a>(
    rec: &'a UniformRecord,
    spec: &'a QualitySpec,
) -> Result<Prepared<'a>, QualityError> {
    let fs = rec.sample_rate_hz;
    if !fs.is_finite() || fs <= 0.0 {
        return Err(QualityError::record(
            "sample_rate_hz",
            format!("must be finite and > 0, got {fs}"),
        ));
    }
    if rec.names.len() != rec.data.len() {
        return Err(QualityError::record(
            "names",
            format!(
                "{} names for {} data columns",
                rec.names.len(),
                rec.data.len()
            ),
        ));
    }
    let n = rec.len();
    if let Some(i) = rec.data.iter().position(|c| c.len() != n) {
        return Err(QualityError::record(
            format!("data[{i}]"),
            format!(
                "column `{}` has {} samples, the first column {n}",
                rec.names[i],
                rec.data[i].len()
            ),
        ));
    }
    let blocks = valid_blocks(rec)?;

    let (input_names, inputs) = columns(rec, &spec.inputs, "inputs")?;
    let (output_names, outputs) = columns(rec, &spec.outputs, "outputs")?;
    let dof_pairs = dof_pairs(spec)?;

    let longest = blocks.iter().map(|b| b.len()).max().unwrap_or(0);
    let nperseg = match spec.nperseg {
        None => default_quality_nperseg(longest),
        Some(0) => return Err(QualityError::spec("nperseg", "must be at least 1")),
        Some(p) if p > longest => {
            return Err(QualityError::spec(
                "nperseg",
                format!(
                    "segment length {p} exceeds the longest block of valid samples ({longest})"
                ),
            ));
        }
        Some(p) => p,
    };
    if let Some(c) = spec.controller_rate_hz
        && (!c.is_finite() || c <= 0.0)
    {
        return Err(QualityError::spec(
            "controller_rate_hz",
            format!("must be finite and > 0, got {c}"),
        ));
    }
    let n_cols = spec
        .regressor_lags
        .saturating_mul(inputs.len() + outputs.len());
    if spec.regressor_lags == 0 || n_cols > MAX_REGRESSOR_COLUMNS {
        return Err(QualityError::spec(
            "regressor_lags",
            format!(
                "must be ≥ 1 with (inputs + outputs) × lags ≤ {MAX_REGRESSOR_COLUMNS}, got {} lags for {} channels",
                spec.regressor_lags,
                inputs.len() + outputs.len()
            ),
        ));
    }
    let bins = nperseg / 2 + 1;
    if inputs
        .len()
        .saturating_mul(outputs.len())
        .saturating_mul(bins)
        > MAX_PAIR_BINS
    {
        return Err(QualityError::spec(
            "nperseg",
            format!(
                "{} pairs × {bins} frequencies exceed the report's limit of {MAX_PAIR_BINS} values \
                 per spectrum: use a shorter nperseg or fewer channels",
                inputs.len() * outputs.len()
            ),
        ));
    }
    validate_plan(rec, spec)?;

    // The statistics double as the finiteness check: a NaN or ±∞ makes
    // them non-finite, and only then are the samples searched.
    let stats = |name: &str, x: &[f64]| -> Result<(f64, f64), QualityError> {
        let (mean, rms) = mean_rms(x, &blocks);
        if !(mean.is_finite() && rms.is_finite()) {
            require_finite(name, x, &blocks)?;
            return Err(QualityError::record(
                name.to_owned(),
                "values too large: their sum of squares overflows",
            ));
        }
        Ok((mean, rms))
    };
    // One pass over every valid sample, memory-bound: the channels spread
    // over the pool for long logs. The first channel's error (inputs
    // first) is the one reported, as in one pass.
    let n_valid: usize = blocks.iter().map(|b| b.len()).sum();
    let names: Vec<&str> = input_names.iter().chain(&output_names).copied().collect();
    let cols: Vec<&[f64]> = inputs.iter().chain(&outputs).copied().collect();
    let all: Vec<Result<(f64, f64), QualityError>> =
        if n_valid.saturating_mul(cols.len()) >= PARALLEL_SAMPLES {
            use rayon::prelude::*;
            names
                .par_iter()
                .zip(&cols)
                .map(|(name, x)| stats(name, x))
                .collect()
        } else {
            names
                .iter()
                .zip(&cols)
                .map(|(name, x)| stats(name, x))
                .collect()
        };
    let mut all = all.into_iter().collect::<Result<Vec<_>, _>>()?;
    let output_stats = all.split_off(inputs.len());
    let input_stats = all;
    Ok(Prepared {
        fs,
        n_samples: n,
        blocks,
        input_names,
        inputs,
        output_names,
        outputs,
        input_stats,
        output_stats,
        dof_pairs,
        nperseg,
    })
}

/// The non-empty valid blocks, checked to lie in the record, ascending and
/// disjoint.
fn valid_blocks(rec: &UniformRecord) -> Result<Vec<Range<usize>>, QualityError> {
    let n = rec.len();
    let mut end = 0;
    for (i, b) in rec.valid.iter().enumerate() {
        if b.start > b.end || b.end > n || b.start < end {
            return Err(QualityError::record(
                format!("valid[{i}]"),
                format!(
                    "block {}..{} must lie within the {n} samples, after the previous block",
                    b.start, b.end
                ),
            ));
        }
        end = b.end;
    }
    let blocks: Vec<Range<usize>> = rec
        .valid
        .iter()
        .filter(|b| !b.is_empty())
        .cloned()
        .collect();
    if blocks.is_empty() {
        return Err(QualityError::record(
            "valid",
            "the log has no valid samples",
        ));
    }
    Ok(blocks)
}

/// Looks up named columns; names must be distinct and present.
fn columns<'a>(
    rec: &'a UniformRecord,
    names: &'a [String],
    field: &str,
) -> Result<(Vec<&'a str>, Vec<&'a [f64]>), QualityError> {
    if names.is_empty() {
        return Err(QualityError::spec(field, "at least one column is needed"));
    }
    let mut seen = HashSet::new();
    let mut cols = Vec::with_capacity(names.len());
    for (i, name) in names.iter().enumerate() {
        if !seen.insert(name.as_str()) {
            return Err(QualityError::spec(
                format!("{field}[{i}]"),
                format!("column `{name}` is listed twice"),
            ));
        }
        let col = rec
            .column(name)
            .ok_or_else(|| QualityError::MissingColumn {
                field: format!("{field}[{i}]"),
                name: name.clone(),
            })?;
        cols.push(col);
    }
    Ok((names.iter().map(String::as_str).collect(), cols))
}

/// The input and output index of each DOF.
fn dof_pairs(spec: &QualitySpec) -> Result<Vec<(usize, usize)>, QualityError> {
    spec.dofs
        .iter()
        .enumerate()
        .map(|(k, d)| {
            let i = spec
                .inputs
                .iter()
                .position(|n| *n == d.input)
                .ok_or_else(|| {
                    QualityError::spec(
                        format!("dofs[{k}].input"),
                        format!("`{}` is not one of the inputs", d.input),
                    )
                })?;
            let o = spec
                .outputs
                .iter()
                .position(|n| *n == d.output)
                .ok_or_else(|| {
                    QualityError::spec(
                        format!("dofs[{k}].output"),
                        format!("`{}` is not one of the outputs", d.output),
                    )
                })?;
            Ok((i, o))
        })
        .collect()
}

/// Checks the planned reference: rate, and per column a present, finite
/// log column and at least two finite schedule samples.
fn validate_plan(rec: &UniformRecord, spec: &QualitySpec) -> Result<(), QualityError> {
    let Some(plan) = &spec.planned else {
        return Ok(());
    };
    let r = plan.sample_rate_hz;
    if !r.is_finite() || r <= 0.0 {
        return Err(QualityError::spec(
            "planned.sample_rate_hz",
            format!("must be finite and > 0, got {r}"),
        ));
    }
    for (i, (log_col, sched, values)) in plan.columns.iter().enumerate() {
        let col = rec
            .column(log_col)
            .ok_or_else(|| QualityError::MissingColumn {
                field: format!("planned.columns[{i}]"),
                name: log_col.clone(),
            })?;
        require_finite(log_col, col, &rec.valid)?;
        let log_samples = (values.len() - 1) as f64 / r * rec.sample_rate_hz + 1.0;
        if values.len() >= 2 && log_samples > (10 * rec.len() + 10_000) as f64 {
            return Err(QualityError::spec(
                format!("planned.columns[{i}]"),
                format!(
                    "schedule `{sched}` lasts {:.0} s, more than ten times the log ({:.0} s)",
                    (values.len() - 1) as f64 / r,
                    rec.len() as f64 / rec.sample_rate_hz
                ),
            ));
        }
        if values.len() < 2 {
            return Err(QualityError::spec(
                format!("planned.columns[{i}]"),
                format!("schedule `{sched}` needs at least 2 samples"),
            ));
        }
        if let Some(k) = values.iter().position(|v| !v.is_finite()) {
            return Err(QualityError::spec(
                format!("planned.columns[{i}]"),
                format!("schedule `{sched}` sample {k} is not finite"),
            ));
        }
    }
    Ok(())
}

fn require_finite(name: &str, x: &[f64], blocks: &[Range<usize>]) -> Result<(), QualityError> {
    for b in blocks {
        if let Some(k) = x[b.clone()].iter().position(|v| !v.is_finite()) {
            let index = b.start + k;
            return Err(QualityError::NonFinite {
                field: name.to_owned(),
                index,
                message: format!(
                    "{name}[{index}] = {} inside a valid block is not finite",
                    x[index]
                ),
            });
        }
    }
    Ok(())
}

#[cfg(test)]
#[allow(clippy::single_range_in_vec_init)] // vectors of blocks
mod tests {
    use super::*;

    #[test]
    fn one_pass_statistics_match_two_pass() {
        let x: Vec<f64> = (0..10_001)
            .map(|i| 1e6 + 0.25 * (i as f64 * 0.37).sin() + 1e-3 * i as f64)
            .collect();
        for blocks in [vec![0..10_001], vec![3..4000, 4100..9000, 9000..9001]] {
            let vals: Vec<f64> = blocks
                .iter()
                .flat_map(|b| x[b.clone()].iter().copied())
                .collect();
            let n = vals.len() as f64;
            let mean = vals.iter().sum::<f64>() / n;
            let rms = (vals.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt();
            let (m, r) = mean_rms(&x, &blocks);
            assert!((m - mean).abs() < 1e-14 * mean, "{m} vs {mean}");
            assert!((r / rms - 1.0).abs() < 1e-9, "{r} vs {rms}");
        }
        assert_eq!(mean_rms(&x, &[5..5]), (0.0, 0.0));
        assert_eq!(mean_rms(&[2.5; 9], &[0..9]), (2.5, 0.0));
        let (m, r) = mean_rms(&[1.0, f64::NAN], &[0..2]);
        assert!(m.is_nan() && r.is_nan());
        assert!((sum(&x[..17]) - x[..17].iter().sum::<f64>()).abs() < 1e-6);
    }
}
