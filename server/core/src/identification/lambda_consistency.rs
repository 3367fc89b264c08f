//! M = M_RB + M_A is one vehicle's inertia: it does not change with forward
//! speed (Fossen 2011, ch. 6). Each grid point estimates it on its own, with
//! a σ from its own residuals. When one entry's estimates disagree across
//! the grid by more than those σ allow, the σ understate the error
//! (unmodelled dynamics, closed-loop bias), so each is inflated by the Birge
//! ratio R = √(χ²/(k − 1)) of the k estimates about their weighted mean.

use crate::estimation::lambda::LambdaEstimate;
use crate::numbers::sig3;
use crate::planning::dof::Dof;

/// The Birge ratio of `values` with standard deviations `stds` (≥ 1; 1 when
/// fewer than two entries have a positive, finite σ).
pub(crate) fn birge_ratio(values: &[f64], stds: &[f64]) -> f64 {
    let pairs: Vec<(f64, f64)> = values
        .iter()
        .zip(stds)
        .filter(|(v, s)| v.is_finite() && s.is_finite() && **s > 0.0)
        .map(|(v, s)| (*v, *s))
        .collect();
    if pairs.len() < 2 {
        return 1.0;
    }
    let w: f64 = pairs.iter().map(|(_, s)| 1.0 / (s * s)).sum();
    let mean = pairs.iter().map(|(v, s)| v / (s * s)).sum::<f64>() / w;
    let chi2: f64 = pairs.iter().map(|(v, s)| ((v - mean) / s).powi(2)).sum();
    (chi2 / (pairs.len() - 1) as f64).sqrt().max(1.0)
}

/// Inflates σ of every M entry by its Birge ratio across the grid points of
/// `estimates`; says so in `notes` when any factor exceeds 1.5.
pub(crate) fn inflate_inertia_std(
    estimates: &mut [(f64, LambdaEstimate)],
    dofs: &[Dof],
    notes: &mut Vec<String>,
) {
    let n = dofs.len();
    if estimates.len() < 2 {
        return;
    }
    let mut factors = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let values: Vec<f64> = estimates.iter().map(|(_, e)| e.m[(i, j)]).collect();
            let stds: Vec<f64> = estimates.iter().map(|(_, e)| e.std_m[(i, j)]).collect();
            let r = birge_ratio(&values, &stds);
            if r > 1.0 {
                for (_, e) in estimates.iter_mut() {
                    e.std_m[(i, j)] *= r;
                }
            }
            factors.push((r, i, j));
        }
    }
    factors.sort_by(|a, b| b.0.total_cmp(&a.0));
    let large: Vec<String> = factors
        .iter()
        .filter(|(r, _, _)| *r > 1.5)
        .take(3)
        .map(|(r, i, j)| format!("M[{},{}] ×{}", dofs[*i].name(), dofs[*j].name(), sig3(*r)))
        .collect();
    if !large.is_empty() {
        notes.push(format!(
            "M does not change with speed, but its estimates at the grid speeds disagree beyond their σ; each σ of M is inflated by that spread (Birge ratio; largest: {})",
            large.join(", ")
        ));
    }
}

/// Says that M was estimated under M = Mᵀ and how far the unconstrained
/// rows were from it, per grid speed (χ² per constrained pair: about 1 when
/// the asymmetry is noise, far above when the rows are biased).
pub(crate) fn symmetry_note(estimates: &[(f64, LambdaEstimate)], notes: &mut Vec<String>) {
    let parts: Vec<String> = estimates
        .iter()
        .filter_map(|(speed, e)| {
            e.symmetry.map(|s| {
                let r = s.inflation();
                let scaled = if r > 1.0 {
                    format!(" (σ ×{})", sig3(r))
                } else {
                    String::new()
                };
                format!(
                    "{speed:.2} m/s {} on {}{scaled}",
                    sig3(s.chi2 / s.constraints as f64),
                    s.constraints
                )
            })
        })
        .collect();
    if !parts.is_empty() {
        notes.push(format!(
            "M was estimated symmetric: the rows were re-fitted under M = Mᵀ by least squares over their joint uncertainty, so each coupling comes from the row that determines it best and D̄ moves with it; the unconstrained rows' asymmetry in χ² per pair: {}; where it exceeds 1 the σ at that speed understate the error and are scaled by its square root",
            parts.join(", ")
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn agreement_within_sigma_keeps_sigma_and_spread_inflates_it() {
        // χ² = 2 on 2 degrees of freedom: R = 1.
        assert_eq!(birge_ratio(&[10.0, 10.1, 9.9], &[0.1, 0.1, 0.1]), 1.0);
        // Mean 10, χ² = (4 + 0 + 4)/0.01 = 800 on 2: R = 20.
        let r = birge_ratio(&[12.0, 10.0, 8.0], &[0.1, 0.1, 0.1]);
        assert!((r - 20.0).abs() < 1e-9, "{r}");
        // NaN is skipped; 10 and 11 with σ 0.5: χ² = 2 on 1 degree of freedom.
        let r = birge_ratio(&[10.0, 11.0, f64::NAN], &[0.5, 0.5, 0.1]);
        assert!((r - (2.0f64).sqrt()).abs() < 1e-12, "{r}");
        assert_eq!(birge_ratio(&[3.0], &[0.1]), 1.0);
        assert_eq!(birge_ratio(&[3.0, 5.0], &[0.0, 0.0]), 1.0);
    }
}
