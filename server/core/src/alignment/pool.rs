//! One clock offset for a campaign, pooled from its runs' own estimates.
//!
//! The two computers of a campaign keep the same offset from run to run, so
//! runs whose shared channel moves well (excitation runs) can lend their
//! offset to runs where it barely moves (static holds). The pool:
//!
//! 1. takes the *informative* estimates only (see
//!    [`super::OffsetEstimate::informative`]), each with its calibrated σ;
//! 2. finds the consensus: the largest group of runs consistent (|z| ≤ 4)
//!    with one of them, so a run whose clock really differs (a computer
//!    rebooted, a log from another day) or whose estimate is confidently
//!    wrong cannot drag the others; when two groups are equally large there
//!    is no consensus, every run is kept and the σ widened;
//! 3. within it, rejects one at a time the run farthest from the
//!    inverse-variance mean of the others (leave-one-out z > 4);
//! 4. reports the inverse-variance mean `Σ(x/σ²)/Σ(1/σ²)` with
//!    σ = `1/√Σ(1/σ²)`, widened by the Birge ratio `√(χ²/(n−1))` when the
//!    runs scatter more than their σ say, and which runs were used,
//!    rejected (with their z) or left out as uninformative.
//!
//! One constant offset per campaign: a slow drift between the computers'
//! clocks across a campaign (crystal clocks differ by tens of ppm) is not
//! modelled; the pool's χ² flags it when it matters, and each run's own
//! within-run drift check (`drift.rs`) still applies.

use serde::{Deserialize, Serialize};

/// Leave-one-out |z| beyond which a run is inconsistent with the others.
pub const OUTLIER_Z: f64 = 4.0;

/// One run's own offset estimate, as the pool sees it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct RunOffset {
    /// Run id.
    pub run_id: String,
    /// Run name, for messages.
    pub name: String,
    /// The run's own estimate (s, added to navigation stamps).
    pub offset_s: f64,
    /// Its calibrated standard deviation (s).
    pub std_s: f64,
    /// Whether the estimate stands on its own.
    pub informative: bool,
}

/// An informative run left out of the pool, and why.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct RejectedRun {
    /// Run id.
    pub run_id: String,
    /// Its own estimate (s).
    pub offset_s: f64,
    /// Its standard deviation (s).
    pub std_s: f64,
    /// Its distance from the pooled offset in combined standard deviations.
    pub z: f64,
}

/// The campaign's clock offset pooled from its runs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct PooledOffset {
    /// Seconds to add to navigation stamps to put them on the control clock.
    pub offset_s: f64,
    /// Its standard deviation (s), widened by `birge_ratio`.
    pub std_s: f64,
    /// Runs pooled (ids).
    pub runs_used: Vec<String>,
    /// Informative runs left out as inconsistent with the others.
    pub runs_rejected: Vec<RejectedRun>,
    /// Runs whose own estimate is not informative (ids): not pooled.
    pub runs_uninformative: Vec<String>,
    /// χ² of the pooled runs about the pooled offset.
    pub chi2: f64,
    /// Its degrees of freedom (pooled runs − 1).
    pub dof: usize,
    /// `max(1, √(χ²/dof))`: how much the runs scatter beyond their σ.
    pub birge_ratio: f64,
    /// Plain-language cautions (rejected runs, scatter, no consensus).
    pub warnings: Vec<String>,
}

/// Inverse-variance mean and its σ of `(x, σ)` pairs.
fn weighted(runs: &[&RunOffset]) -> (f64, f64) {
    let (sw, swx) = runs.iter().fold((0.0, 0.0), |(sw, swx), r| {
        let w = 1.0 / (r.std_s * r.std_s);
        (sw + w, swx + w * r.offset_s)
    });
    (swx / sw, 1.0 / sw.sqrt())
}

fn z_between(a: &RunOffset, b: &RunOffset) -> f64 {
    (a.offset_s - b.offset_s) / (a.std_s * a.std_s + b.std_s * b.std_s).sqrt()
}

/// Pools the informative estimates of `runs` into one campaign offset;
/// `None` when no run is informative. See the module documentation.
pub fn pool_offsets(runs: &[RunOffset]) -> Option<PooledOffset> {
    let usable = |r: &&RunOffset| {
        r.informative && r.offset_s.is_finite() && r.std_s.is_finite() && r.std_s > 0.0
    };
    let candidates: Vec<&RunOffset> = runs.iter().filter(usable).collect();
    let runs_uninformative: Vec<String> = runs
        .iter()
        .filter(|r| !usable(r))
        .map(|r| r.run_id.clone())
        .collect();
    if candidates.is_empty() {
        return None;
    }
    let mut warnings = Vec::new();
    // Consensus: the largest group consistent with one of its members.
    let groups: Vec<Vec<usize>> = candidates
        .iter()
        .map(|seed| {
            (0..candidates.len())
                .filter(|&j| z_between(candidates[j], seed).abs() <= OUTLIER_Z)
                .collect()
        })
        .collect();
    let largest = groups.iter().map(Vec::len).max().unwrap_or(0);
    let mut distinct: Vec<&Vec<usize>> = groups.iter().filter(|g| g.len() == largest).collect();
    distinct.sort();
    distinct.dedup();
    let mut used: Vec<&RunOffset> = if distinct.len() == 1 {
        distinct[0].iter().map(|&j| candidates[j]).collect()
    } else {
        warnings.push(format!(
            "no consensus: the informative runs fall into {} groups of {largest} that disagree; all are pooled and the standard deviation widened — set the campaign's offset by hand if you know it",
            distinct.len()
        ));
        candidates.clone()
    };
    // Leave-one-out rejection within the consensus.
    while used.len() >= 3 {
        let worst = (0..used.len())
            .map(|i| {
                let others: Vec<&RunOffset> = used
                    .iter()
                    .enumerate()
                    .filter(|(j, _)| *j != i)
                    .map(|(_, r)| *r)
                    .collect();
                let (m, s) = weighted(&others);
                let r = used[i];
                (i, (r.offset_s - m) / (r.std_s * r.std_s + s * s).sqrt())
            })
            .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()));
        match worst {
            Some((i, z)) if z.abs() > OUTLIER_Z => {
                used.remove(i);
            }
            _ => break,
        }
    }
    let (offset_s, std_raw) = weighted(&used);
    let chi2: f64 = used
        .iter()
        .map(|r| ((r.offset_s - offset_s) / r.std_s).powi(2))
        .sum();
    let dof = used.len() - 1;
    let birge_ratio = if dof > 0 {
        (chi2 / dof as f64).sqrt().max(1.0)
    } else {
        1.0
    };
    let std_s = std_raw * birge_ratio;
    if birge_ratio > 2.0 {
        warnings.push(format!(
            "the pooled runs scatter {birge_ratio:.1} times more than their standard deviations say (χ² = {chi2:.1} for {dof} degrees of freedom): the σ is widened accordingly; the clocks may drift across the campaign"
        ));
    }
    let runs_rejected: Vec<RejectedRun> = candidates
        .iter()
        .filter(|r| !used.iter().any(|u| u.run_id == r.run_id))
        .map(|r| RejectedRun {
            run_id: r.run_id.clone(),
            offset_s: r.offset_s,
            std_s: r.std_s,
            z: (r.offset_s - offset_s) / (r.std_s * r.std_s + std_s * std_s).sqrt(),
        })
        .collect();
    for (r, name) in runs_rejected.iter().map(|r| {
        let name = candidates
            .iter()
            .find(|c| c.run_id == r.run_id)
            .map_or("?", |c| c.name.as_str());
        (r, name)
    }) {
        warnings.push(format!(
            "run “{name}” is left out: its offset {:.3} ± {:.3} s disagrees with the pooled {offset_s:.3} s (z = {:.1}); its computers' clocks may have been reset",
            r.offset_s, r.std_s, r.z
        ));
    }
    Some(PooledOffset {
        offset_s,
        std_s,
        runs_used: used.iter().map(|r| r.run_id.clone()).collect(),
        runs_rejected,
        runs_uninformative,
        chi2,
        dof,
        birge_ratio,
        warnings,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(id: &str, offset_s: f64, std_s: f64, informative: bool) -> RunOffset {
        RunOffset {
            run_id: id.into(),
            name: format!("run {id}"),
            offset_s,
            std_s,
            informative,
        }
    }

    #[test]
    fn inverse_variance_mean_of_the_informative_runs() {
        let p = pool_offsets(&[
            run("a", 7.0, 0.1, true),
            run("b", 7.2, 0.2, true),
            run("c", 50.0, 0.001, false),
        ])
        .unwrap();
        // Weights 100 and 25.
        assert!((p.offset_s - 7.04).abs() < 1e-12, "{p:?}");
        assert!((p.std_s - 1.0 / 125f64.sqrt()).abs() < 1e-12);
        assert_eq!(p.runs_used, ["a", "b"]);
        assert_eq!(p.runs_uninformative, ["c"]);
        assert!(p.runs_rejected.is_empty());
        assert_eq!(p.dof, 1);
        assert_eq!(pool_offsets(&[run("c", 1.0, 0.1, false)]), None);
    }

    #[test]
    fn a_confident_outlier_is_rejected_and_named() {
        let p = pool_offsets(&[
            run("a", 7.430, 0.002, true),
            run("b", 7.431, 0.003, true),
            run("c", 7.428, 0.002, true),
            run("d", 19.2, 0.0005, true),
        ])
        .unwrap();
        assert!((p.offset_s - 7.4297).abs() < 1e-3, "{p:?}");
        assert_eq!(p.runs_rejected.len(), 1);
        assert_eq!(p.runs_rejected[0].run_id, "d");
        assert!(p.runs_rejected[0].z > 1000.0);
        assert!(
            p.warnings.iter().any(|w| w.contains("run “run d”")),
            "{p:?}"
        );
    }

    #[test]
    fn two_disagreeing_runs_widen_the_sigma() {
        let p = pool_offsets(&[run("a", 7.43, 0.01, true), run("b", 7.63, 0.01, true)]).unwrap();
        assert!((p.offset_s - 7.53).abs() < 1e-9);
        // χ² = 200 for one degree of freedom: Birge ratio ≈ 14.
        assert!(p.birge_ratio > 10.0, "{p:?}");
        assert!(p.std_s > 0.09, "{p:?}");
        assert!(
            p.warnings.iter().any(|w| w.contains("no consensus")),
            "{p:?}"
        );
    }
}
