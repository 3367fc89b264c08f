//! Re-planning a campaign: which experiments of a new plan are the ones an
//! earlier plan already holds, so that uploaded runs stay matched to them.
//!
//! An experiment has an *identity* — what it is for: family, grid speed,
//! excited DOFs, sign of a static run and repetition — and a *content* —
//! how it is flown: its description, channels and every sample of its
//! schedule (the caller fingerprints it). Between two plans an experiment
//! is
//!
//! - **unchanged** when both identity and content agree: it keeps its id;
//! - **changed** when the identity agrees but the content does not (a new
//!   amplitude, duration or seed): a new id replaces the old, and runs
//!   flown for the old schedule are not runs of the new one;
//! - **added** / **removed** when only one plan has the identity.
//!
//! The identity holds the grid speed, not the grid index: adding a speed
//! to the grid leaves the static runs of the other speeds unchanged. The
//! run order is not part of either: a re-ordered experiment is unchanged.

use super::plan::Experiment;

/// The identity of an experiment across plan versions, e.g.
/// `static|0.771667|pitch|-|r1` (grid speed in m/s to the µm/s; `-` for
/// the validation run that spans the grid).
pub fn identity(e: &Experiment) -> String {
    if e.separates.is_some() {
        // Deciding runs: their code holds the proposal's place and heading.
        return format!("deciding|{}", e.code);
    }
    let speed = e
        .grid_speed_mps
        .map_or_else(|| "-".to_string(), |v| format!("{v:.6}"));
    let dofs: Vec<&str> = e.dofs.iter().map(|d| d.name()).collect();
    let sign = match e.sign {
        Some(s) if s > 0 => "+",
        Some(_) => "-",
        None => "",
    };
    format!(
        "{}|{speed}|{}|{sign}|r{}",
        e.family.name(),
        dofs.join("+"),
        e.repetition
    )
}

/// An experiment as the comparison sees it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Keyed<'a> {
    /// [`identity`].
    pub identity: &'a str,
    /// A fingerprint of the content (description and schedule).
    pub fingerprint: &'a str,
}

/// How a new plan's experiments relate to an earlier plan's, by index into
/// the two lists.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Revision {
    /// (new, old): same identity and content.
    pub unchanged: Vec<(usize, usize)>,
    /// (new, old): same identity, different content.
    pub changed: Vec<(usize, usize)>,
    /// New experiments with an identity the earlier plan lacks.
    pub added: Vec<usize>,
    /// Earlier experiments with an identity the new plan lacks.
    pub removed: Vec<usize>,
}

impl Revision {
    /// True when the new plan holds exactly the earlier plan's experiments.
    pub fn is_identity(&self) -> bool {
        self.changed.is_empty() && self.added.is_empty() && self.removed.is_empty()
    }
}

/// Compares `new` with `old`. Identities are unique within a plan; should
/// one repeat, its occurrences pair up in order.
pub fn revise(old: &[Keyed<'_>], new: &[Keyed<'_>]) -> Revision {
    let mut taken = vec![false; old.len()];
    let mut out = Revision::default();
    // Unchanged first, so that a repeated identity pairs equal contents.
    let mut pending = Vec::new();
    for (i, n) in new.iter().enumerate() {
        match (0..old.len()).find(|&j| !taken[j] && old[j] == *n) {
            Some(j) => {
                taken[j] = true;
                out.unchanged.push((i, j));
            }
            None => pending.push(i),
        }
    }
    for i in pending {
        match (0..old.len()).find(|&j| !taken[j] && old[j].identity == new[i].identity) {
            Some(j) => {
                taken[j] = true;
                out.changed.push((i, j));
            }
            None => out.added.push(i),
        }
    }
    out.removed = (0..old.len()).filter(|&j| !taken[j]).collect();
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::planning::examples::{surveyor_campaign, surveyor_rov};
    use crate::planning::generate_plan;

    fn k<'a>(identity: &'a str, fingerprint: &'a str) -> Keyed<'a> {
        Keyed {
            identity,
            fingerprint,
        }
    }

    #[test]
    fn experiments_pair_by_identity_then_content() {
        let old = [k("a", "1"), k("b", "2"), k("c", "3")];
        let new = [k("c", "3"), k("b", "9"), k("d", "4")];
        let r = revise(&old, &new);
        assert_eq!(r.unchanged, [(0, 2)]);
        assert_eq!(r.changed, [(1, 1)]);
        assert_eq!(r.added, [2]);
        assert_eq!(r.removed, [0]);
        assert!(!r.is_identity());
        assert!(revise(&old, &old).is_identity());
    }

    #[test]
    fn identities_are_unique_within_a_plan() {
        let plan = generate_plan(&surveyor_rov(), &surveyor_campaign(7)).unwrap();
        let mut ids: Vec<String> = plan
            .experiments
            .iter()
            .map(|p| identity(&p.experiment))
            .collect();
        let n = ids.len();
        ids.sort();
        ids.dedup();
        assert_eq!(ids.len(), n);
        let pitch_down = plan
            .experiments
            .iter()
            .find(|p| p.experiment.code.starts_with("STA-0.5kn-pitch-"))
            .unwrap();
        assert_eq!(
            identity(&pitch_down.experiment),
            "static|0.257222|pitch|-|r1"
        );
    }
}
