//! The terms missing-physics discovery added to an LPV sub-model, flattened
//! for exports: each coefficient (and an actuator effect's shape parameter)
//! with its name, value, standard deviation, SI unit and DOF, so a Fossen
//! or NumPy consumer sees every term the augmented model predicts with.

use serde::Serialize;

use super::document::{LpvPoint, ModelDocument};
use crate::discrepancy::candidates::ShapeKind;
use crate::discrepancy::{Effect, ModelTerm};

/// One number of a discovered term.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct TermCoefficient {
    /// Name in the term's notation, without the unit (`d_u|u|`, `V_N`, `T_a`).
    pub name: String,
    /// Estimate (SI).
    pub value: f64,
    /// Standard deviation (from the HAC covariance, or the profile's
    /// curvature for a shape parameter), when known.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub std: Option<f64>,
    /// SI unit (`-` for a scale factor, `samples` for a delay).
    pub unit: String,
}

/// A discovered term at one grid speed.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct ExportedTerm {
    /// What it is, in words (`quadratic damping |u|u in surge`).
    pub label: String,
    /// The effect as stored (machine-readable kind and DOFs).
    pub effect: Effect,
    /// The DOF whose equation it enters (absent for effects spanning DOFs:
    /// C(ν)ν from M, current, a common input delay).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dof: Option<String>,
    /// Its linear coefficients.
    pub coefficients: Vec<TermCoefficient>,
    /// The shape parameter of an actuator effect (lag T_a, delay, τ_max, δ).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shape: Option<TermCoefficient>,
}

/// `d_u|u| (N·s²/m²)` → (`d_u|u|`, `N·s²/m²`).
fn split_unit(name: &str) -> (String, Option<String>) {
    if let Some(open) = name.rfind(" (")
        && name.ends_with(')')
    {
        return (
            name[..open].to_string(),
            Some(name[open + 2..name.len() - 1].to_string()),
        );
    }
    (name.to_string(), None)
}

fn coefficient_units(effect: &Effect, names: &[String]) -> Vec<(String, String)> {
    names
        .iter()
        .enumerate()
        .map(|(p, n)| {
            let (symbol, unit) = split_unit(n);
            let unit = unit.unwrap_or_else(|| match *effect {
                // M_ij ν̇_j and D̄_ij ν_j in equation i.
                Effect::Coupling { dof, from } if p == 0 => {
                    format!("{}/({}²)", dof.force_unit(), from.velocity_unit())
                }
                Effect::Coupling { dof, from } => {
                    format!("{}/({})", dof.force_unit(), from.velocity_unit())
                }
                _ => "-".into(),
            });
            (symbol, unit)
        })
        .collect()
}

fn shape_of(term: &ModelTerm) -> Option<TermCoefficient> {
    let kind = term.effect.shape()?;
    let force = term.effect.dof().map_or("N", |d| d.force_unit());
    let (name, unit) = match kind {
        ShapeKind::LagTime => ("T_a", "s".to_string()),
        ShapeKind::DelaySamples => ("delay", "samples".to_string()),
        ShapeKind::SaturationLevel => ("tau_max", force.to_string()),
        ShapeKind::DeadZoneWidth => ("delta", force.to_string()),
    };
    Some(TermCoefficient {
        name: name.into(),
        value: term.shape?,
        std: term.shape_std,
        unit,
    })
}

/// One stored term, flattened.
pub fn exported_term(term: &ModelTerm) -> ExportedTerm {
    let names = term.effect.coefficient_names();
    let coefficients = coefficient_units(&term.effect, &names)
        .into_iter()
        .zip(&term.coefficients)
        .enumerate()
        .map(|(p, ((name, unit), value))| TermCoefficient {
            name,
            value: *value,
            std: term
                .covariance
                .get(p)
                .and_then(|r| r.get(p))
                .filter(|v| v.is_finite() && **v >= 0.0)
                .map(|v| v.sqrt()),
            unit,
        })
        .collect();
    ExportedTerm {
        label: term.effect.label(),
        effect: term.effect,
        dof: term.effect.dof().map(|d| d.name().to_string()),
        coefficients,
        shape: shape_of(term),
    }
}

/// The discovered terms of a sub-model (empty for a baseline point).
pub fn point_terms(point: &LpvPoint) -> Vec<ExportedTerm> {
    point
        .augmentation
        .as_ref()
        .map(|a| a.terms.iter().map(exported_term).collect())
        .unwrap_or_default()
}

/// Every sub-model's terms with its grid speed (empty for a model without
/// discovered physics).
pub fn model_terms(doc: &ModelDocument) -> Vec<(f64, Vec<ExportedTerm>)> {
    doc.lpv
        .as_ref()
        .map(|l| {
            l.points
                .iter()
                .filter(|p| p.augmentation.is_some())
                .map(|p| (p.speed_mps, point_terms(p)))
                .collect()
        })
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::planning::dof::Dof;

    #[test]
    fn coefficients_carry_value_std_unit_and_dof() {
        let t = exported_term(&ModelTerm {
            effect: Effect::QuadraticDamping { dof: Dof::Surge },
            coefficients: vec![120.0],
            covariance: vec![vec![4.0]],
            shape: None,
            shape_std: None,
        });
        assert_eq!(t.dof.as_deref(), Some("surge"));
        assert_eq!(t.coefficients[0].name, "d_u|u|");
        assert_eq!(t.coefficients[0].unit, "N·s²/m²");
        assert_eq!(
            (t.coefficients[0].value, t.coefficients[0].std),
            (120.0, Some(2.0))
        );
        assert!(t.shape.is_none());

        let c = exported_term(&ModelTerm {
            effect: Effect::Coupling {
                dof: Dof::Sway,
                from: Dof::Yaw,
            },
            coefficients: vec![30.0, 5.0],
            covariance: vec![vec![1.0, 0.0], vec![0.0, 0.25]],
            shape: None,
            shape_std: None,
        });
        assert_eq!(c.coefficients[0].unit, "N/(rad/s²)");
        assert_eq!(c.coefficients[1].unit, "N/(rad/s)");
        assert_eq!(c.coefficients[1].std, Some(0.5));

        let lag = exported_term(&ModelTerm {
            effect: Effect::ActuatorLag { dof: Dof::Yaw },
            coefficients: vec![],
            covariance: vec![],
            shape: Some(0.4),
            shape_std: Some(0.05),
        });
        let s = lag.shape.unwrap();
        assert_eq!(
            (s.name.as_str(), s.unit.as_str(), s.value),
            ("T_a", "s", 0.4)
        );
        assert_eq!(lag.effect, Effect::ActuatorLag { dof: Dof::Yaw });
    }
}
