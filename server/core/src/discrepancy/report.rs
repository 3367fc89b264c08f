//! The discovery report: what a control engineer reads and a web page
//! plots. Every public type is serde-serializable.

use serde::{Deserialize, Serialize};

use super::candidates::{Effect, Family};
use super::data::Restoring;
use super::experiment::ExperimentProposal;
use super::lines::SpectralLine;
use super::locate::LocationReport;
use super::model::ModelTerm;
use super::residual::{BandPower, Whiteness};
use crate::planning::Dof;

/// A coefficient estimate with its uncertainty.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct Estimate {
    /// Name and unit.
    pub name: String,
    /// Estimate.
    pub value: f64,
    /// Standard deviation (HAC, or profile curvature for shapes); `None`
    /// when the fit gives none (no covariance, a flat profile).
    #[serde(default)]
    pub std: Option<f64>,
}

/// Whether a hypothesis made it into the model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[cfg_attr(feature = "openapi", schema(as = HypothesisVerdict))]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// Chosen: significant and improves held-out simulations.
    Chosen,
    /// Significant in the equation but no better on held-out runs.
    NotConfirmed,
    /// Not significant.
    NotSignificant,
}

/// One tested hypothesis (first selection step, plus every chosen term).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct HypothesisReport {
    /// The effect.
    pub effect: Effect,
    /// Its family.
    pub family: Family,
    /// Label in words.
    pub label: String,
    /// Selection step it was scored in (1 = on the baseline alone).
    pub step: usize,
    /// Linear coefficients.
    pub coefficients: Vec<Estimate>,
    /// Shape parameter of an actuator effect.
    pub shape: Option<Estimate>,
    /// ΔBIC against the model without it (negative favours it).
    pub delta_bic: f64,
    /// Significance: Wald z of the coefficients (HAC), or √LR for a shape.
    pub z: f64,
    /// Held-out free-run fit gained, summed over channels (if evaluated).
    pub cv_gain: Option<f64>,
    /// Size of its force: RMS over the RMS of the command in its DOF
    /// (λ-filtered, estimation runs; the largest over the DOFs it enters).
    #[serde(default)]
    pub force_share: Option<f64>,
    /// Outcome.
    pub verdict: Verdict,
}

/// A chosen term in words.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct Finding {
    /// The effect.
    pub effect: Effect,
    /// Label.
    pub label: String,
    /// DOFs whose equations it enters.
    pub dofs: Vec<Dof>,
    /// Coefficients ± std.
    pub coefficients: Vec<Estimate>,
    /// Shape parameter ± std.
    pub shape: Option<Estimate>,
    /// What it does, in plain words.
    pub effect_text: String,
    /// The evidence, one sentence each.
    pub evidence: Vec<String>,
}

/// NRMSE fits of one channel (thesis eq. 1.13).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct Fits {
    /// 1-step prediction.
    pub one_step: Option<f64>,
    /// k-step prediction.
    pub k_step: Option<f64>,
    /// Free-run simulation.
    pub free_run: Option<f64>,
}

/// Before/after on the validation runs for one channel.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct ChannelComparison {
    /// The DOF.
    pub dof: Dof,
    /// Baseline fits (mean over validation runs).
    pub before: Fits,
    /// Augmented-model fits.
    pub after: Fits,
    /// 1-step residual whiteness, baseline.
    pub whiteness_before: Whiteness,
    /// 1-step residual whiteness, augmented model.
    pub whiteness_after: Whiteness,
}

/// A decimated before/after series for plotting.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct PlotSeries {
    /// Run name.
    pub run: String,
    /// DOF.
    pub dof: Dof,
    /// Time (s).
    pub t: Vec<f64>,
    /// Measured ν_i.
    pub measured: Vec<f64>,
    /// Baseline free run.
    pub before: Vec<f64>,
    /// Augmented free run.
    pub after: Vec<f64>,
}

/// Two hypotheses the data cannot tell apart.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct Ambiguity {
    /// The chosen one.
    pub chosen: Effect,
    /// Its look-alike.
    pub alternative: Effect,
    /// Held-out gains of both.
    pub cv_gains: [f64; 2],
    /// In words.
    pub text: String,
    /// The run that separates them, if a vessel profile was given.
    pub experiment: Option<ExperimentProposal>,
}

/// Structure no candidate explains.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct Unexplained {
    /// The DOF.
    pub dof: Dof,
    /// The band and its excess over the noise floor.
    pub band: BandPower,
    /// Low-frequency slope of the residual PSD.
    pub low_slope: f64,
    /// Spectral signature in words.
    pub signature: String,
    /// The sentence.
    pub text: String,
    /// The narrow line this entry reports, if it is one (then `band` is
    /// the line's main lobe).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub line: Option<SpectralLine>,
}

/// The augmented model as numbers (row-major matrices).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct ModelReport {
    /// DOFs.
    pub dofs: Vec<Dof>,
    /// M.
    pub m: Vec<Vec<f64>>,
    /// D̄.
    pub d_bar: Vec<Vec<f64>>,
    /// g(η).
    pub restoring: Restoring,
    /// Added terms with coefficients and covariances.
    pub terms: Vec<ModelTerm>,
    /// M that a C(ν)ν term is built from.
    pub m_ref: Vec<Vec<f64>>,
    /// D̄ a current acts through.
    pub d_ref: Vec<Vec<f64>>,
}

impl ModelReport {
    /// The report of a fitted model.
    pub fn of(model: &super::AugmentedModel) -> Self {
        let rows = |m: &nalgebra::DMatrix<f64>| {
            (0..m.nrows())
                .map(|i| m.row(i).iter().copied().collect())
                .collect()
        };
        ModelReport {
            dofs: model.dofs.clone(),
            m: rows(&model.m),
            d_bar: rows(&model.d_bar),
            restoring: model.restoring,
            terms: model.terms.clone(),
            m_ref: rows(&model.m_ref),
            d_ref: rows(&model.d_ref),
        }
    }
}

/// Everything discovery found.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct DiscoveryReport {
    /// Modeled DOFs.
    pub dofs: Vec<Dof>,
    /// The story in a few sentences.
    pub summary: Vec<String>,
    /// Where baseline and recordings part.
    pub location: LocationReport,
    /// Tested hypotheses, best first.
    pub hypotheses: Vec<HypothesisReport>,
    /// Chosen terms, in the order chosen.
    pub findings: Vec<Finding>,
    /// Whether a chosen current is constant (window by window), if one was
    /// chosen.
    #[serde(default)]
    pub current_drift: Option<super::drift::CurrentDrift>,
    /// The augmented model.
    pub model: ModelReport,
    /// Before/after on validation runs, per channel.
    pub validation: Vec<ChannelComparison>,
    /// Before/after series of the first validation run.
    pub plots: Vec<PlotSeries>,
    /// Look-alikes the data cannot separate, with the deciding experiment.
    pub ambiguities: Vec<Ambiguity>,
    /// Structure left unexplained.
    pub unexplained: Vec<Unexplained>,
    /// Terms the examined model already carried (an earlier discovery's):
    /// kept and refitted, not tested again. Empty for a baseline.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub carried: Vec<super::candidates::Effect>,
}

#[cfg(test)]
mod tests {
    use super::Estimate;

    #[test]
    fn an_unavailable_std_travels_as_null_and_comes_back_none() {
        let e = Estimate {
            name: "T_a (s)".into(),
            value: 0.73,
            std: None,
        };
        let v = serde_json::to_value(&e).unwrap();
        assert!(v["std"].is_null(), "{v}");
        let back: Estimate = serde_json::from_value(v).unwrap();
        assert!(back.std.is_none() && back.value == 0.73);
        let known: Estimate =
            serde_json::from_str(r#"{"name":"d","value":1.0,"std":0.5}"#).unwrap();
        assert_eq!(known.std, Some(0.5));
    }
}
