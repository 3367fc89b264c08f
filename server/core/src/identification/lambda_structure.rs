//! The coupling structure of a λ-filter identification: diagonal, fully
//! coupled, the user's pattern, or proposed from the partial coherence
//! between DOFs (`auto`).

use nalgebra::DMatrix;

use super::error::IdentifyError;
use super::lambda_campaign::{LambdaCampaignSettings, StructureChoice};
use crate::estimation::Progress;
use crate::estimation::lambda::{CouplingMask, Experiment, Structure, propose_coupling};
use crate::planning::dof::Dof;

/// The structure to estimate, its mask and its name in the document.
pub(crate) struct ChosenStructure {
    pub structure: Structure,
    pub mask: CouplingMask,
    pub name: &'static str,
}

/// Port–starboard symmetry: DOFs couple within the longitudinal (surge,
/// heave, pitch) and lateral (sway, roll, yaw) subsystems.
pub(crate) fn symmetric_pattern(dofs: &[Dof]) -> DMatrix<bool> {
    let lateral = |d: Dof| matches!(d, Dof::Sway | Dof::Roll | Dof::Yaw);
    DMatrix::from_fn(dofs.len(), dofs.len(), |i, j| {
        lateral(dofs[i]) == lateral(dofs[j])
    })
}

/// True for the DOF sets whose symmetric structure is standard: the full
/// 6-DOF set and the 3-DOF horizontal one.
fn has_symmetric_form(dofs: &[Dof]) -> bool {
    dofs == Dof::ALL || dofs == [Dof::Surge, Dof::Sway, Dof::Yaw]
}

/// Chooses the structure from the settings; `auto` proposes it from
/// `all` (every estimation experiment) and says why in `notes`.
pub(crate) fn choose_structure(
    settings: &LambdaCampaignSettings,
    dofs: &[Dof],
    all: &[Experiment],
    progress: &mut dyn Progress,
    notes: &mut Vec<String>,
) -> Result<ChosenStructure, IdentifyError> {
    let n = dofs.len();
    let coupled = |mask: CouplingMask| ChosenStructure {
        structure: Structure::Coupled(mask.clone()),
        mask,
        name: "coupled",
    };
    Ok(match settings.structure {
        StructureChoice::Diagonal => ChosenStructure {
            structure: Structure::Diagonal,
            mask: CouplingMask::diagonal(n),
            name: "diagonal",
        },
        StructureChoice::Coupled => coupled(CouplingMask::full(n)),
        StructureChoice::Symmetric => coupled(CouplingMask::from_pattern(&symmetric_pattern(dofs))),
        StructureChoice::Custom => {
            let rows = settings.coupling.as_ref().ok_or_else(|| {
                IdentifyError::invalid(
                    "settings.coupling",
                    "structure 'custom' needs the coupling pattern",
                )
            })?;
            if rows.len() != n || rows.iter().any(|r| r.len() != n) {
                return Err(IdentifyError::invalid(
                    "settings.coupling",
                    format!("must be {n} × {n} booleans in the order {dofs:?}"),
                ));
            }
            let mut p = DMatrix::from_fn(n, n, |i, j| rows[i][j]);
            for i in 0..n {
                p[(i, i)] = true;
            }
            coupled(CouplingMask::from_pattern(&p))
        }
        StructureChoice::Auto => {
            progress.update(0.04, "proposing coupling from partial coherence")?;
            let proposal = propose_coupling(all, settings.coupling_threshold).map_err(|e| {
                IdentifyError::invalid(format!("settings.{}", e.field()), e.to_string())
            })?;
            // The proposed pairs outside `skip`, in words.
            let described = |skip: &dyn Fn(usize, usize) -> bool| -> Vec<String> {
                proposal
                    .evidence
                    .iter()
                    .filter(|p| proposal.mask.a[(p.output, p.input)] && !skip(p.output, p.input))
                    .map(|p| {
                        format!(
                            "{}←{} (partial coherence {:.2})",
                            dofs[p.output].name(),
                            dofs[p.input].name(),
                            p.median_partial_coherence
                        )
                    })
                    .collect()
            };
            if has_symmetric_form(dofs) {
                let base = symmetric_pattern(dofs);
                let extra = described(&|i, j| base[(i, j)]);
                notes.push(if extra.is_empty() {
                    "structure: port–starboard symmetry (surge–heave–pitch and sway–roll–yaw coupled); the data propose no coupling across the two".into()
                } else {
                    format!(
                        "structure: port–starboard symmetry plus couplings the data propose: {}",
                        extra.join(", ")
                    )
                });
                let pattern =
                    DMatrix::from_fn(n, n, |i, j| base[(i, j)] || proposal.mask.a[(i, j)]);
                return Ok(coupled(CouplingMask::from_pattern(&pattern)));
            }
            let pairs = described(&|_, _| false);
            notes.push(if pairs.is_empty() {
                "coupling proposal: no DOF pair is coupled above the threshold; diagonal model"
                    .into()
            } else {
                format!("coupling proposed from the data: {}", pairs.join(", "))
            });
            coupled(proposal.mask)
        }
    })
}
