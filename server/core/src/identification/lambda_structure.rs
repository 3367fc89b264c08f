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
            let pairs: Vec<String> = proposal
                .evidence
                .iter()
                .filter(|p| proposal.mask.a[(p.output, p.input)])
                .map(|p| {
                    format!(
                        "{}←{} (partial coherence {:.2})",
                        dofs[p.output].name(),
                        dofs[p.input].name(),
                        p.median_partial_coherence
                    )
                })
                .collect();
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
