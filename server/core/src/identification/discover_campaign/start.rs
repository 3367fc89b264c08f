//! The model discovery starts from. A surface vessel's λ model may carry a
//! current fixed in NED (`lpv.current`, acting through D̄ on the velocity
//! through the water); discovery's library sees it as the term
//! [`Effect::Current`] with coefficients [V_N, V_E], so the start model
//! carries it as that term: the candidates are then judged in the relative
//! velocity, the current is refitted with them, and the augmented model
//! keeps it.

use std::borrow::Cow;

use crate::discrepancy::{Effect, ModelTerm};
use crate::identification::augmented::is_augmented;
use crate::identification::document::{ModelDocument, NedCurrentDoc, PointAugmentation};
use crate::logs::schema::pose_column;
use crate::planning::Dof;

/// `doc` with its NED current carried as a discovery term at every grid
/// point (borrowed unchanged without a current, or when the model is
/// already augmented: its terms then hold the current).
pub fn with_current_as_term(doc: &ModelDocument) -> Cow<'_, ModelDocument> {
    let Some(current) = doc.lpv.as_ref().and_then(|l| l.current.clone()) else {
        return Cow::Borrowed(doc);
    };
    if is_augmented(doc) {
        return Cow::Borrowed(doc);
    }
    let mut out = doc.clone();
    // An augmented model is driven by [τ | η] (see `augmented`).
    for d in Dof::ALL {
        let c = pose_column(d);
        if !out.inputs.iter().any(|i| i == c) {
            out.inputs.push(c.to_string());
        }
    }
    let term = current_term(&current);
    for p in &mut out.lpv.as_mut().expect("checked: LPV").points {
        p.augmentation = Some(PointAugmentation {
            m_ref: p.m.clone(),
            d_ref: p.d_bar.clone(),
            terms: vec![term.clone()],
        });
        // The term is now the current's one representation: an augmented
        // model is predicted from its terms, never from F.
        p.current_force = None;
    }
    Cow::Owned(out)
}

/// [V_N, V_E] with the covariance of (V_c, β_c) carried through
/// V_N = V_c cos β_c, V_E = V_c sin β_c.
fn current_term(c: &NedCurrentDoc) -> ModelTerm {
    let (s, b) = (c.speed_mps, c.direction_deg.to_radians());
    let (ss, sb) = (c.speed_std_mps, c.direction_std_deg.to_radians());
    let j = [[b.cos(), -s * b.sin()], [b.sin(), s * b.cos()]];
    let var = [ss * ss, sb * sb];
    let covariance = (0..2)
        .map(|r| {
            (0..2)
                .map(|q| j[r][0] * j[q][0] * var[0] + j[r][1] * j[q][1] * var[1])
                .collect()
        })
        .collect();
    ModelTerm {
        effect: Effect::Current,
        coefficients: c.ned_mps.to_vec(),
        covariance,
        shape: None,
        shape_std: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A current of 0.3 m/s towards 90° with σ 0.01 m/s and 2°: V = (0,
    /// 0.3); var V_N = (0.3·σ_β)², var V_E = σ_V², uncorrelated.
    #[test]
    fn the_current_term_carries_the_speed_and_direction_uncertainty() {
        let t = current_term(&NedCurrentDoc {
            speed_mps: 0.3,
            speed_std_mps: 0.01,
            direction_deg: 90.0,
            direction_std_deg: 2.0,
            ned_mps: [0.0, 0.3],
            evidence: String::new(),
        });
        assert_eq!(t.coefficients, vec![0.0, 0.3]);
        let sn = 0.3 * 2f64.to_radians();
        assert!((t.covariance[0][0] - sn * sn).abs() < 1e-12);
        assert!((t.covariance[1][1] - 1e-4).abs() < 1e-12);
        assert!(t.covariance[0][1].abs() < 1e-12);
    }
}
