//! Shape parameters the campaign shares. An actuator's lag T_a, the command
//! link's delay, a thruster's saturation level τ_max or dead zone δ belong
//! to the actuators, not to the forward speed: where two or more grid
//! speeds chose the same such effect, their estimates are pooled by inverse
//! variance and every one of those speeds is refitted with the shape held
//! at the pooled value — its coefficients, M and D̄ fitted around it. Where
//! the estimates scatter more than their standard deviations allow, the
//! shape is not one value in the data's eyes (at some speed it trades
//! against another term: a lag against a delay), and each speed keeps its
//! own; the report says so.

use super::shared::{CampaignEstimate, chi2_95};
use super::{PointDiscovery, speeds_text};
use crate::discrepancy::locate::capital;
use crate::discrepancy::report::{Estimate, ModelReport};
use crate::discrepancy::{
    AugmentedModel, DiscoverySettings, Effect, ModelTerm, Record, refit_holding,
};
use crate::numbers::sig3;

/// One shape parameter pooled over the grid speeds that chose its effect.
pub(super) struct PooledShape {
    pub effect: Effect,
    pub value: f64,
    pub std: f64,
    /// Whether the speeds' estimates agree within their standard
    /// deviations (χ² below its 95 % point): only then is the shape held
    /// at the pooled value.
    pub agree: bool,
    pub estimate: CampaignEstimate,
}

/// The pooled shape of every shaped effect at least two grid speeds chose
/// with a standard deviation.
pub(super) fn pool_shapes(points: &[PointDiscovery]) -> Vec<PooledShape> {
    let mut effects: Vec<Effect> = Vec::new();
    for p in points {
        for t in &p.report.model.terms {
            if t.effect.shape().is_some() && !effects.contains(&t.effect) {
                effects.push(t.effect);
            }
        }
    }
    effects
        .into_iter()
        .filter_map(|e| {
            // The speeds that chose it, with their estimate of it.
            let terms: Vec<(f64, &ModelTerm)> = points
                .iter()
                .filter(|p| p.report.findings.iter().any(|f| f.effect == e))
                .filter_map(|p| {
                    let t = p.report.model.terms.iter().find(|t| t.effect == e)?;
                    Some((p.grid_speed_mps, t))
                })
                .collect();
            pool(e, &terms)
        })
        .collect()
}

/// The inverse-variance pool of `effect`'s shape over the grid speeds'
/// terms (speed, term) with a standard deviation; `None` from fewer than
/// two.
fn pool(effect: Effect, terms: &[(f64, &ModelTerm)]) -> Option<PooledShape> {
    let kind = effect.shape()?;
    let mut speeds = Vec::new();
    let mut ests: Vec<(f64, f64)> = Vec::new();
    for &(speed, t) in terms {
        if let (Some(v), Some(s)) = (t.shape, t.shape_std)
            && v.is_finite()
            && s.is_finite()
            && s > 0.0
        {
            speeds.push(speed);
            ests.push((v, 1.0 / (s * s)));
        }
    }
    if ests.len() < 2 {
        return None;
    }
    let w_sum: f64 = ests.iter().map(|(_, w)| w).sum();
    let mean = ests.iter().map(|(v, w)| v * w).sum::<f64>() / w_sum;
    let chi2: f64 = ests.iter().map(|(v, w)| (v - mean).powi(2) * w).sum();
    let dof = ests.len() - 1;
    let disagree = chi2 > chi2_95(dof);
    let var = 1.0 / w_sum;
    let value = mean;
    let std = var.sqrt();
    if !(value.is_finite() && std.is_finite()) {
        return None;
    }
    let each: Vec<String> = ests.iter().map(|(v, _)| sig3(*v)).collect();
    let text = if disagree {
        format!(
            "{}: the estimates of {} at {} grid speeds ({} m/s: {}) scatter more than their standard deviations allow (χ² {} on {dof} degrees of freedom), so each speed keeps its own: at some speed it trades against another term, or it changed during the campaign.",
            capital(&effect.label()),
            kind.name(),
            ests.len(),
            speeds_text(&speeds),
            each.join(", "),
            sig3(chi2)
        )
    } else {
        format!(
            "{}: {} {} ± {} for the campaign, pooled from the estimates at {} grid speeds ({} m/s: {}), which agree within their standard deviations (χ² {} on {dof} degrees of freedom). It belongs to the actuators, not to the speed: each of those speeds is refitted with it held there.",
            capital(&effect.label()),
            kind.name(),
            sig3(value),
            sig3(std),
            ests.len(),
            speeds_text(&speeds),
            each.join(", "),
            sig3(chi2)
        )
    };
    Some(PooledShape {
        effect,
        value,
        std,
        agree: !disagree,
        estimate: CampaignEstimate {
            coefficients: vec![Estimate {
                name: kind.name().to_owned(),
                value,
                std: Some(std),
            }],
            grid_speeds_mps: speeds,
            chi2,
            dof,
            text,
        },
    })
}

/// Point `p` refitted on `est` with every pooled shape it carries held at
/// the campaign's value (the start model's terms too, when it carries the
/// effect), its findings showing that value. `None` when it carries none,
/// or the refit fails (it then stays as discovery fitted it).
pub(super) fn held_shapes(
    p: &PointDiscovery,
    start: &AugmentedModel,
    est: &[Record],
    settings: &DiscoverySettings,
    pooled: &[PooledShape],
) -> Option<PointDiscovery> {
    let hold = |terms: &[ModelTerm]| -> Vec<ModelTerm> {
        terms
            .iter()
            .map(|t| match pooled.iter().find(|s| s.effect == t.effect) {
                Some(s) => ModelTerm {
                    shape: Some(s.value),
                    shape_std: Some(s.std),
                    ..t.clone()
                },
                None => t.clone(),
            })
            .collect()
    };
    let terms = &p.report.model.terms;
    if !terms
        .iter()
        .any(|t| pooled.iter().any(|s| s.effect == t.effect))
    {
        return None;
    }
    let mut start = start.clone();
    start.terms = hold(&start.terms);
    let model = refit_holding(&start, est, settings, &hold(terms), &[]).ok()?;
    if !model.inertia_positive() {
        return None;
    }
    let mut out = p.clone();
    for f in &mut out.report.findings {
        if let Some(s) = pooled.iter().find(|s| s.effect == f.effect) {
            if let Some(shape) = &mut f.shape {
                shape.value = s.value;
                shape.std = Some(s.std);
            }
            f.evidence.push(s.estimate.text.clone());
        }
    }
    out.report.model = ModelReport::of(&model);
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::planning::dof::Dof;

    fn term(effect: Effect, shape: f64, std: f64) -> ModelTerm {
        ModelTerm {
            effect,
            coefficients: vec![],
            covariance: vec![],
            shape: Some(shape),
            shape_std: Some(std),
        }
    }

    #[test]
    fn agreeing_lags_pool_to_their_inverse_variance_mean() {
        // 0.30 ± 0.01 and 0.31 ± 0.02: weights 10⁴ and 2500, mean
        // (3000 + 775)/12500 = 0.302, χ² = 0.04 + 0.16 = 0.2 on 1 dof (below
        // 3.84), std 1/√12500.
        let (a, b) = (
            term(Effect::CommonActuatorLag, 0.30, 0.01),
            term(Effect::CommonActuatorLag, 0.31, 0.02),
        );
        let p = pool(Effect::CommonActuatorLag, &[(0.5, &a), (1.0, &b)]).unwrap();
        assert!((p.value - 0.302).abs() < 1e-12, "{}", p.value);
        assert!((p.std - 12500f64.sqrt().recip()).abs() < 1e-12);
        assert!(p.agree && (p.estimate.chi2 - 0.2).abs() < 1e-9);
        assert!(
            p.estimate.text.contains("which agree"),
            "{}",
            p.estimate.text
        );
    }

    #[test]
    fn scattered_lags_are_not_one_value() {
        // 0.30 and 0.40, each ± 0.01: χ² = 50 on 1 dof, above 3.84.
        let (a, b) = (
            term(Effect::CommonActuatorLag, 0.30, 0.01),
            term(Effect::CommonActuatorLag, 0.40, 0.01),
        );
        let p = pool(Effect::CommonActuatorLag, &[(0.5, &a), (1.0, &b)]).unwrap();
        assert!(!p.agree);
        assert!((p.estimate.chi2 - 50.0).abs() < 1e-9);
        assert!(
            p.estimate.text.contains("each speed keeps its own"),
            "{}",
            p.estimate.text
        );
    }

    #[test]
    fn a_delay_pools_to_its_fraction_of_a_sample_and_one_estimate_is_not_pooled() {
        let e = Effect::InputDelay { dof: Dof::Sway };
        // 2.4 ± 0.5 and 2.8 ± 0.25 samples: weights 4 and 16.
        let (a, b) = (term(e, 2.4, 0.5), term(e, 2.8, 0.25));
        let p = pool(e, &[(0.5, &a), (1.0, &b)]).unwrap();
        assert!((p.value - 2.72).abs() < 1e-12, "{}", p.value);
        assert!(pool(e, &[(0.5, &a)]).is_none());
    }
}
