//! Identifiability of the ARX regressor Φ = (Φ_y Φ_x) (thesis eq. 1.11):
//! how many parameters can the log determine?
//!
//! Row t of Φ is φ(t) = [y(t−1) … y(t−na), x(t−1) … x(t−nb)] over all
//! outputs y and inputs x, with `na = nb = lags`; rows are taken only where
//! every lag lies inside the same valid block. Each column is the channel's
//! deviation from its mean over the valid samples, divided by its RMS over
//! the rows, so that units (N against m/s) do not decide which direction
//! looks small: the singular values then measure collinearity, not scale. A
//! constant channel gives zero columns (left unscaled).
//!
//! The singular values σᵢ of Φ are the square roots of the eigenvalues of
//! the p × p Gram matrix ΦᵀΦ, accumulated row-block by row-block in
//! O(N·p²) (in fact O(N·C²·(2·lags − 1)) for C channels: the entries of two
//! lagged columns of the same channel pair differ only by edge terms) and
//! decomposed with a symmetric eigen-solver; no N × N (or N × p) matrix is
//! ever formed.

use std::ops::Range;

use nalgebra::{DMatrix, SymmetricEigen};

use super::gram::normalized_gram;
use super::record::checked_stats;
use super::{ColumnWeight, DeficientDirection, QualityError, RegressorReport};

/// Lags `na = nb` when the spec gives none. One lag: the identified model is first order in ν (ν̇ = Aν + Bτ, thesis
/// eq. 2.10), so Φ = (Φ_y Φ_x) holds ν(t−1) and τ(t−1). Two lags on
/// first-order data are collinear by construction (y(t−1) = a·y(t−2) + b·x(t−2)).
pub const DEFAULT_REGRESSOR_LAGS: usize = 1;

/// A direction of Φ counts as identifiable when `σᵢ/σ₁ > 1e-3`.
///
/// Why 1e-3: the least-squares error along direction i is amplified by
/// `σ₁/σᵢ` relative to the best-determined direction, so at 1e-3 a noise
/// of 0.1 % of the signal RMS — below any sea-trial sensor — already puts
/// an error as large as the signal on that parameter combination; below it
/// the data do not determine it. The threshold is also far above rounding:
/// an exactly collinear pair of columns leaves `σᵢ/σ₁ ≈ 1e-8` (the square
/// root of the Gram matrix's rounding, ~1e-16), so it is never counted.
pub const SINGULAR_VALUE_THRESHOLD: f64 = 1e-3;

/// Most regressor columns (`lags × channels`) accepted; the eigen-solver is
/// cubic in it. Typical: 12 channels × 2 lags = 24.
pub const MAX_REGRESSOR_COLUMNS: usize = 256;

/// A column takes part in a group of dependent columns when at least
/// `DIRECTION_WEIGHT² = 1 %` of it lies in the deficient subspace, and two
/// columns are grouped when their coupling in that subspace is at least as
/// large (see [`DeficientDirection`]).
pub const DIRECTION_WEIGHT: f64 = 0.1;

/// The analysis, the normalized Gram matrix (unit-RMS columns, `ΦᵀΦ /
/// n_rows`), kept for sub-regressors, and each channel's mean and RMS
/// about it over the valid samples (same order as the channels).
pub(crate) struct Analysis {
    pub report: RegressorReport,
    pub gram: DMatrix<f64>,
    pub stats: Vec<(f64, f64)>,
}

/// Singular values and identifiable-parameter count of the ARX regressor
/// built from `channels` named `names` — the first `n_outputs` are the
/// outputs, the rest the inputs, as in Φ = (Φ_y Φ_x) — with `lags` lags of
/// each, over the valid `blocks`.
///
/// # Errors
/// [`QualityError::InvalidSpec`] for `names` not matching `channels`,
/// `lags` zero or more than [`MAX_REGRESSOR_COLUMNS`] columns;
/// [`QualityError::InvalidRecord`] for ragged channels or a block outside
/// them; [`QualityError::NonFinite`] for a NaN or infinite sample inside a
/// block.
pub fn regressor_analysis(
    names: &[&str],
    channels: &[&[f64]],
    n_outputs: usize,
    blocks: &[Range<usize>],
    lags: usize,
) -> Result<RegressorReport, QualityError> {
    if names.len() != channels.len() {
        return Err(QualityError::spec(
            "names",
            format!("{} names for {} channels", names.len(), channels.len()),
        ));
    }
    if n_outputs > channels.len() {
        return Err(QualityError::spec(
            "n_outputs",
            format!("{n_outputs} outputs among {} channels", channels.len()),
        ));
    }
    if lags == 0 || lags.saturating_mul(channels.len()) > MAX_REGRESSOR_COLUMNS {
        return Err(QualityError::spec(
            "lags",
            format!(
                "must be ≥ 1 with lags × channels ≤ {MAX_REGRESSOR_COLUMNS}, got {lags} × {}",
                channels.len()
            ),
        ));
    }
    let n = channels.first().map_or(0, |c| c.len());
    for (i, c) in channels.iter().enumerate() {
        if c.len() != n {
            return Err(QualityError::record(
                format!("channels[{i}]"),
                format!("{} samples, channels[0] has {n}", c.len()),
            ));
        }
    }
    for (i, b) in blocks.iter().enumerate() {
        if b.start > b.end || b.end > n {
            return Err(QualityError::record(
                format!("blocks[{i}]"),
                format!("{}..{} is not within {n} samples", b.start, b.end),
            ));
        }
        for (name, c) in names.iter().zip(channels) {
            if let Some(k) = c[b.clone()].iter().position(|v| !v.is_finite()) {
                return Err(QualityError::NonFinite {
                    field: (*name).to_owned(),
                    index: b.start + k,
                    message: format!("{name}[{}] is not finite", b.start + k),
                });
            }
        }
    }
    analyse(names, channels, n_outputs, blocks, lags).map(|a| a.report)
}

/// The analysis on validated channels and blocks (samples may be
/// non-finite: that is the error returned, inputs — channels from
/// `n_outputs` on — searched first).
pub(crate) fn analyse(
    names: &[&str],
    channels: &[&[f64]],
    n_outputs: usize,
    blocks: &[Range<usize>],
    lags: usize,
) -> Result<Analysis, QualityError> {
    let p = channels.len() * lags;
    let columns: Vec<String> = names
        .iter()
        .flat_map(|n| (1..=lags).map(move |l| format!("{n}(t-{l})")))
        .collect();
    let (gram, stats) = normalized_gram(channels, blocks, lags);
    // Before any use of the matrix: it is meaningless if a sample is not
    // finite (and the eigen-solver need not converge on it).
    let nc = channels.len();
    for c in (n_outputs..nc).chain(0..n_outputs.min(nc)) {
        checked_stats(names[c], channels[c], blocks, stats[c])?;
    }
    let n_rows = blocks.iter().map(|b| b.len().saturating_sub(lags)).sum();

    let (sigma, vectors) = singular_values(&gram)?;
    let s1 = sigma.first().copied().unwrap_or(0.0);
    let singular_values: Vec<f64> = sigma
        .iter()
        .map(|s| if s1 > 0.0 { s / s1 } else { 0.0 })
        .collect();
    let identifiable = singular_values
        .iter()
        .filter(|&&s| s > SINGULAR_VALUE_THRESHOLD)
        .count();
    let null: Vec<usize> = (0..p)
        .filter(|&i| singular_values[i] <= SINGULAR_VALUE_THRESHOLD)
        .collect();
    let deficient_directions = dependency_groups(
        &vectors,
        &null,
        &singular_values,
        &columns,
        n_outputs * lags,
    );
    Ok(Analysis {
        report: RegressorReport {
            lags,
            columns,
            n_rows,
            singular_values,
            threshold: SINGULAR_VALUE_THRESHOLD,
            identifiable,
            n_columns: p,
            deficient_directions,
        },
        gram,
        stats,
    })
}

/// Groups of (nearly) dependent columns from the deficient directions
/// `null` (indices into the columns of `vectors`, the unit eigenvectors).
///
/// Eigenvectors of a repeated (near-)zero singular value are any rotation
/// of one another, so single directions can mix unrelated dependencies
/// (a dead input with two collinear ones). The projector `P = V₀V₀ᵀ` onto
/// the whole deficient subspace does not depend on that choice: column k
/// takes part when `P_kk ≥ DIRECTION_WEIGHT²` (share of the column lying in
/// the subspace), and columns k, l belong to the same group when
/// `|P_kl| ≥ DIRECTION_WEIGHT²` (connected components). Each group gets the
/// number of deficient directions it holds (its trace of `P`, rounded), the
/// largest normalized singular value among the directions mostly inside it,
/// and the share of its trace on input columns (index ≥ `first_input`).
fn dependency_groups(
    vectors: &DMatrix<f64>,
    null: &[usize],
    sigma: &[f64],
    columns: &[String],
    first_input: usize,
) -> Vec<DeficientDirection> {
    let p = vectors.nrows();
    if null.is_empty() {
        return Vec::new();
    }
    let proj = |k: usize, l: usize| {
        null.iter()
            .map(|&i| vectors[(k, i)] * vectors[(l, i)])
            .sum::<f64>()
    };
    let min = DIRECTION_WEIGHT * DIRECTION_WEIGHT;
    let members: Vec<usize> = (0..p).filter(|&k| proj(k, k) >= min).collect();
    // Connected components over |P_kl| ≥ min.
    let mut group = vec![usize::MAX; p];
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for &start in &members {
        if group[start] != usize::MAX {
            continue;
        }
        let g = groups.len();
        let mut stack = vec![start];
        let mut cols = Vec::new();
        group[start] = g;
        while let Some(k) = stack.pop() {
            cols.push(k);
            for &l in &members {
                if group[l] == usize::MAX && proj(k, l).abs() >= min {
                    group[l] = g;
                    stack.push(l);
                }
            }
        }
        cols.sort_unstable();
        groups.push(cols);
    }
    groups
        .into_iter()
        .map(|cols| {
            let diag: Vec<f64> = cols.iter().map(|&k| proj(k, k)).collect();
            let trace: f64 = diag.iter().sum();
            let on_inputs: f64 = cols
                .iter()
                .zip(&diag)
                .filter(|(k, _)| **k >= first_input)
                .map(|(_, d)| d)
                .sum();
            let energy = |i: usize| cols.iter().map(|&k| vectors[(k, i)].powi(2)).sum::<f64>();
            let singular_value = null
                .iter()
                .filter(|&&i| energy(i) >= 0.5)
                .map(|&i| sigma[i])
                .fold(f64::NAN, f64::max);
            let singular_value = if singular_value.is_nan() {
                null.iter().map(|&i| sigma[i]).fold(0.0, f64::max)
            } else {
                singular_value
            };
            let weights: Vec<ColumnWeight> = cols
                .iter()
                .zip(&diag)
                .map(|(&k, &d)| ColumnWeight {
                    column: columns[k].clone(),
                    weight: d,
                })
                .collect();
            DeficientDirection {
                dimension: trace.round().max(1.0) as usize,
                singular_value,
                input_share: if trace > 0.0 { on_inputs / trace } else { 0.0 },
                columns: weights,
            }
        })
        .collect()
}

/// Identifiable parameters of the sub-regressor made of the columns `cols`
/// (a principal submatrix of the normalized Gram matrix).
pub(crate) fn sub_identifiable(gram: &DMatrix<f64>, cols: &[usize]) -> Result<usize, QualityError> {
    let sub = DMatrix::from_fn(cols.len(), cols.len(), |i, j| gram[(cols[i], cols[j])]);
    let (sigma, _) = singular_values(&sub)?;
    let s1 = sigma.first().copied().unwrap_or(0.0);
    Ok(if s1 > 0.0 {
        sigma
            .iter()
            .filter(|&&s| s / s1 > SINGULAR_VALUE_THRESHOLD)
            .count()
    } else {
        0
    })
}

/// Singular values of Φ (square roots of the Gram eigenvalues, negatives
/// from rounding clamped to 0), descending, with the matching eigenvectors
/// as columns.
fn singular_values(gram: &DMatrix<f64>) -> Result<(Vec<f64>, DMatrix<f64>), QualityError> {
    let p = gram.nrows();
    if p == 0 {
        return Ok((Vec::new(), DMatrix::zeros(0, 0)));
    }
    let eig =
        SymmetricEigen::try_new(gram.clone(), f64::EPSILON, 1000 * p.max(10)).ok_or_else(|| {
            QualityError::record(
                "data",
                "the eigen-decomposition of the regressor's Gram matrix did not converge",
            )
        })?;
    let mut order: Vec<usize> = (0..p).collect();
    order.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]));
    let sigma = order
        .iter()
        .map(|&i| eig.eigenvalues[i].max(0.0).sqrt())
        .collect();
    let vectors = DMatrix::from_fn(p, p, |r, c| eig.eigenvectors[(r, order[c])]);
    Ok((sigma, vectors))
}

#[cfg(test)]
#[allow(clippy::single_range_in_vec_init)] // vectors of blocks
mod tests {
    use super::*;

    /// Gram matrix of the explicitly built, unit-RMS Φ.
    #[test]
    fn validation_errors_name_fields() {
        let x = vec![1.0, 2.0, 3.0, 4.0];
        let field = |r: Result<RegressorReport, QualityError>| r.unwrap_err().field().to_owned();
        assert_eq!(
            field(regressor_analysis(&["a"], &[], 0, &[0..4], 1)),
            "names"
        );
        assert_eq!(
            field(regressor_analysis(&["a"], &[&x], 0, &[0..4], 0)),
            "lags"
        );
        assert_eq!(
            field(regressor_analysis(&["a"], &[&x], 0, &[0..4], 257)),
            "lags"
        );
        assert_eq!(
            field(regressor_analysis(
                &["a", "b"],
                &[&x, &x[..3]],
                0,
                &[0..3],
                1
            )),
            "channels[1]"
        );
        assert_eq!(
            field(regressor_analysis(&["a"], &[&x], 0, &[0..5], 1)),
            "blocks[0]"
        );
        assert_eq!(
            field(regressor_analysis(&["a"], &[&x], 2, &[0..4], 1)),
            "n_outputs"
        );
        let bad = [1.0, f64::NAN, 3.0];
        assert_eq!(
            field(regressor_analysis(&["a"], &[&bad], 0, &[0..3], 1)),
            "a"
        );
        // Empty data: no rows, nothing identifiable, no panic.
        let r = regressor_analysis(&["a"], &[&x], 0, &[0..1], 2).unwrap();
        assert_eq!((r.n_rows, r.identifiable, r.n_columns), (0, 0, 2));
    }
}
