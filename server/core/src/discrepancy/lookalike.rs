//! Look-alikes: a rival term of another family that explains the same
//! rows about as well as a chosen one, and the run that would separate
//! the two.

use super::discover::DiscoverySettings;
use super::experiment::propose;
use super::fit::{Prepared, Spec};
use super::locate::capital;
use super::report::Ambiguity;
use super::select::Scored;

/// The outcome of forward selection that look-alikes are judged against.
pub(super) struct Selection<'a> {
    /// Terms chosen, in order (after the carried ones).
    pub winners: &'a [Scored],
    /// Every step's scored candidates.
    pub steps: &'a [Vec<Scored>],
    /// Carried terms, then the winners' specs.
    pub chosen: &'a [Spec],
    /// How many of `chosen` the examined model carried.
    pub n_carried: usize,
}

/// For each chosen term, the first rival of another family on a shared row
/// whose held-out gain reaches `ambiguity_ratio` of the winner's, with a
/// deciding run designed within the vessel's limits when one exists
/// (`noise_sigma`: 1-step residual std per DOF; `heading`: ψ at the start).
#[allow(clippy::too_many_arguments)]
pub(super) fn look_alikes(
    prep: &Prepared<'_>,
    sel: &Selection<'_>,
    runs: &[usize],
    settings: &DiscoverySettings,
    noise_sigma: &[f64],
    heading: f64,
    h: f64,
) -> Vec<Ambiguity> {
    let mut ambiguities = Vec::new();
    for (si, w) in sel.winners.iter().enumerate() {
        let wg = w.cv_gain.unwrap_or(0.0);
        let w_rows = prep.rows_of(&[w.spec], &[]);
        let rival = sel.steps[si]
            .iter()
            .filter(|o| o.spec.effect.family() != w.spec.effect.family())
            .filter(|o| !sel.chosen.iter().any(|c| c.effect == o.spec.effect))
            .filter(|o| {
                o.cv_gain
                    .is_some_and(|g| g >= settings.ambiguity_ratio * wg)
            })
            .find(|o| {
                prep.rows_of(&[o.spec], &[])
                    .iter()
                    .any(|r| w_rows.contains(r))
            });
        if let Some(o) = rival {
            let before_terms = &sel.chosen[..sel.n_carried + si];
            let fit_with = |s: Spec| {
                let mut v = before_terms.to_vec();
                v.push(s);
                prep.fit(&v, &[], runs, false)
                    .map(|f| prep.model(&v, &f, &[]))
            };
            let labels = [w.spec.effect.label(), o.spec.effect.label()];
            let mut focus: Vec<_> = prep
                .rows_of(&[w.spec, o.spec], &[])
                .iter()
                .map(|&r| prep.baseline.dofs[r])
                .collect();
            focus.dedup();
            let (experiment, why_none) = match (
                &settings.vessel,
                fit_with(w.spec),
                fit_with(o.spec),
            ) {
                (None, _, _) => (
                    None,
                    "no vessel profile was given to design the run that separates them.",
                ),
                (Some(v), Some(ma), Some(mb)) => (
                    propose(v, &ma, &mb, labels.clone(), &focus, noise_sigma, heading, h),
                    "no run within the vessel profile's force and velocity limits separates them.",
                ),
                _ => (
                    None,
                    "one of the two could not be fitted on its own, so no run was designed to separate them.",
                ),
            };
            let og = o.cv_gain.unwrap_or(0.0);
            ambiguities.push(Ambiguity {
                chosen: w.spec.effect,
                alternative: o.spec.effect,
                cv_gains: [wg, og],
                text: format!(
                    "{} and {} explain these runs about equally well (held-out fit gained {:.3} vs {:.3}); {}",
                    capital(&labels[0]),
                    labels[1],
                    wg,
                    og,
                    match &experiment {
                        Some(e) => format!("a deciding run: {}", e.instruction),
                        None => why_none.into(),
                    }
                ),
                experiment,
            });
        }
    }
    ambiguities
}
