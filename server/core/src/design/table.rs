//! The predicted-precision table: per parameter the expected value, the
//! predicted std and its relative size; the determined count, the weakest
//! parameters and the campaign-level criteria.

use serde::{Deserialize, Serialize};

use super::{DETERMINED_RELATIVE_STD, PriorSource, STRUCTURE_LIMITED, WEAKEST_SHOWN};
use crate::identification::document::ParameterRow;

/// One parameter's predicted precision.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct ParameterPrecision {
    /// Group: `M`, `D̄`, `b`, `g(η)`, `θ″`.
    pub group: String,
    /// Symbol in the papers' notation, e.g. `M[surge,pitch]`, `θ″3 (A_h23)`.
    pub symbol: String,
    /// LPV grid speed (m/s) it belongs to.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub grid_speed_mps: Option<f64>,
    /// Unit of value and std.
    pub unit: String,
    /// The value the identification returns on the plan flown by the prior.
    pub expected_value: f64,
    /// Predicted standard deviation: the spread of the estimates over the
    /// noise realisations; none when it could not be had (the parameter is
    /// then not determined).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub predicted_std: Option<f64>,
    /// The std the identification will report (median over the
    /// realisations): the noise's share and the misfit of the model's
    /// structure to the prior.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reported_std: Option<f64>,
    /// The reported std is more than [`STRUCTURE_LIMITED`] times the
    /// predicted one: the model's structure, not the noise, limits this
    /// parameter, and more runs of this plan will not sharpen it.
    pub structure_limited: bool,
    /// Predicted std relative to `reference` (see the module docs).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub relative_std: Option<f64>,
    /// What the relative std is measured against, in words.
    pub relative_to: String,
    /// relative std ≤ 10 %.
    pub determined: bool,
}

/// What a plan will determine, predicted before it is flown.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct PrecisionPrediction {
    /// Identification method predicted: `lambda_kf` or `parallel_ekf`.
    pub method: String,
    /// The prior the plan was flown with.
    pub prior: PriorSource,
    /// Ship time of the plan (h): runs plus set-up.
    pub ship_hours: f64,
    /// Experiments flown in the prediction.
    pub runs: usize,
    /// Noise realisations of the plan flown and identified.
    pub realisations: usize,
    /// Every identified parameter.
    pub parameters: Vec<ParameterPrecision>,
    /// Parameters predicted to be determined (relative std ≤ 10 %).
    pub determined: usize,
    /// Parameters in the table.
    pub total: usize,
    /// The least precise parameters, worst first, in words (symbol, grid
    /// speed, std and relative std), whether determined or not.
    pub weakest: Vec<String>,
    /// Geometric mean of the relative stds (a D-type figure on the
    /// diagonal: lower is better; parameters without a relative std left out).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub geometric_mean_relative_std: Option<f64>,
    /// Mean relative std (an A-type figure).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mean_relative_std: Option<f64>,
    /// How the prediction was made, and what it assumes.
    pub notes: Vec<String>,
}

/// A row with the magnitude its std is compared with.
pub(crate) struct Scaled<'a> {
    pub row: &'a ParameterRow,
    /// What the identification reports for it (median over realisations).
    pub reported_std: Option<f64>,
    /// Reference magnitude (> 0) and its description.
    pub reference: Option<(f64, String)>,
}

impl PrecisionPrediction {
    /// The table of `rows`, with the counts and criteria.
    pub(crate) fn tabulate(
        method: &str,
        prior: PriorSource,
        ship_hours: f64,
        runs: usize,
        realisations: usize,
        rows: &[Scaled<'_>],
        notes: Vec<String>,
    ) -> Self {
        let parameters: Vec<ParameterPrecision> = rows
            .iter()
            .map(|s| {
                let std = s.row.std.filter(|v| v.is_finite() && *v >= 0.0);
                let (relative_std, relative_to) = match (&s.reference, std) {
                    (Some((r, what)), Some(sd)) if *r > 0.0 && r.is_finite() => {
                        (Some(sd / r), what.clone())
                    }
                    (Some((_, what)), _) => (None, what.clone()),
                    (None, _) => (None, "no scale (expected value 0)".into()),
                };
                ParameterPrecision {
                    group: s.row.group.clone(),
                    symbol: s.row.symbol.clone(),
                    grid_speed_mps: s.row.grid_speed_mps,
                    unit: s.row.unit.clone(),
                    expected_value: finite_or_zero(s.row.value),
                    predicted_std: std,
                    reported_std: s.reported_std.filter(|v| v.is_finite()),
                    structure_limited: matches!((std, s.reported_std), (Some(p), Some(r)) if r > STRUCTURE_LIMITED * p),
                    relative_std,
                    relative_to,
                    determined: relative_std.is_some_and(|r| r <= DETERMINED_RELATIVE_STD),
                }
            })
            .collect();
        let rel: Vec<f64> = parameters.iter().filter_map(|p| p.relative_std).collect();
        let positive: Vec<f64> = rel.iter().copied().filter(|r| *r > 0.0).collect();
        let geometric_mean_relative_std = (!positive.is_empty())
            .then(|| (positive.iter().map(|r| r.ln()).sum::<f64>() / positive.len() as f64).exp());
        let mean_relative_std =
            (!rel.is_empty()).then(|| rel.iter().sum::<f64>() / rel.len() as f64);
        let mut order: Vec<&ParameterPrecision> = parameters.iter().collect();
        order.sort_by(|a, b| weakness(b).total_cmp(&weakness(a)));
        let weakest = order
            .iter()
            .take(WEAKEST_SHOWN)
            .map(|p| describe(p))
            .collect();
        PrecisionPrediction {
            method: method.into(),
            prior,
            ship_hours,
            runs,
            realisations,
            determined: parameters.iter().filter(|p| p.determined).count(),
            total: parameters.len(),
            parameters,
            weakest,
            geometric_mean_relative_std,
            mean_relative_std,
            notes,
        }
    }
}

/// Ordering key: relative std, with a parameter that has none counted weakest.
fn weakness(p: &ParameterPrecision) -> f64 {
    p.relative_std.unwrap_or(f64::MAX)
}

fn describe(p: &ParameterPrecision) -> String {
    let at = p
        .grid_speed_mps
        .map(|u| format!(" at {u:.2} m/s"))
        .unwrap_or_default();
    let limited = match (p.structure_limited, p.reported_std) {
        (true, Some(r)) => format!(
            "; limited by the model's structure: reported ±{} {}",
            crate::numbers::sig3(r),
            p.unit
        ),
        _ => String::new(),
    };
    match (p.predicted_std, p.relative_std) {
        (Some(sd), Some(r)) => format!(
            "{}{at}: ±{} {} ({:.0} % of {}){limited}",
            p.symbol,
            crate::numbers::sig3(sd),
            p.unit,
            100.0 * r,
            p.relative_to
        ),
        (Some(sd), None) => format!(
            "{}{at}: ±{} {} around {}",
            p.symbol,
            crate::numbers::sig3(sd),
            p.unit,
            crate::numbers::sig3(p.expected_value)
        ),
        (None, _) => format!("{}{at}: no std (not identifiable from this plan)", p.symbol),
    }
}

fn finite_or_zero(v: f64) -> f64 {
    if v.is_finite() { v } else { 0.0 }
}
