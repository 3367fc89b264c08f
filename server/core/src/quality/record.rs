//! Checks a record and a spec against each other and gathers what the
//! analyses need: the channels by role, the valid blocks and the Welch
//! segment length; the per-channel statistics' arithmetic (the sums
//! themselves come with the regressor's Gram matrix, in the same pass).

use std::collections::HashSet;
use std::ops::Range;

use super::regressor::MAX_REGRESSOR_COLUMNS;
use super::report::default_quality_nperseg;
use super::{QualityError, QualitySpec};
use crate::kernels::fold8;
use crate::timeseries::UniformRecord;

/// Most values per spectrum of the report (pairs × frequencies): 4 Mi, i.e.
/// ≈ 170 MB for the five spectra of every pair. A 6 × 6 report with
/// `nperseg = 4096` holds 74 k.
pub const MAX_PAIR_BINS: usize = 1 << 22;

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

/// Mean and RMS about it from `n` samples' sums `s1 = Σ (x − x₀)` and
/// `s2 = Σ (x − x₀)²` (0, 0 without samples; non-finite when a sum is).
pub(crate) fn from_shifted_sums(x0: f64, n: usize, s1: f64, s2: f64) -> (f64, f64) {
    if n == 0 {
        return (0.0, 0.0);
    }
    let nf = n as f64;
    let d = s1 / nf;
    // Rounding can leave a tiny negative; a NaN must stay (max would drop it).
    let var = s2 / nf - d * d;
    let var = if var < 0.0 { 0.0 } else { var };
    (x0 + d, var.sqrt())
}

/// `(Σ (x − c), Σ (x − c)²)` with eight independent partial sums each.
pub(crate) fn shifted_sums(x: &[f64], c: f64) -> (f64, f64) {
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
    (fold8(a1) + t1, fold8(a2) + t2)
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
    fold8(acc) + tail
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

    Ok(Prepared {
        fs,
        n_samples: n,
        blocks,
        input_names,
        inputs,
        output_names,
        outputs,
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

/// A channel's `(mean, rms)` as computed, or the error a non-finite one
/// stands for: the first non-finite sample, else sums that overflow.
pub(crate) fn checked_stats(
    name: &str,
    x: &[f64],
    blocks: &[Range<usize>],
    (mean, rms): (f64, f64),
) -> Result<(f64, f64), QualityError> {
    if mean.is_finite() && rms.is_finite() {
        return Ok((mean, rms));
    }
    require_finite(name, x, blocks)?;
    Err(QualityError::record(
        name.to_owned(),
        "values too large: their sum of squares overflows",
    ))
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
    fn partial_sums_match_the_plain_sums() {
        let x: Vec<f64> = (0..10_001).map(|i| 1e6 + (i as f64 * 0.37).sin()).collect();
        assert!((sum(&x[..17]) - x[..17].iter().sum::<f64>()).abs() < 1e-6);
        let (a1, a2) = shifted_sums(&x[3..42], 1e6);
        let want1: f64 = x[3..42].iter().map(|v| v - 1e6).sum();
        let want2: f64 = x[3..42].iter().map(|v| (v - 1e6).powi(2)).sum();
        assert!((a1 - want1).abs() < 1e-9 && (a2 - want2).abs() < 1e-9);
        assert_eq!(from_shifted_sums(7.0, 0, 1.0, 1.0), (0.0, 0.0));
    }
}
