//! A campaign's coverage by good runs: per planned experiment of the newest
//! plan, the runs flown for it and the verdict that says whether to fly it
//! again.

use seatrial_core::planning::Dof;
use serde::Serialize;

use crate::storage::plans::StoredPlan;
use crate::storage::runs::Run;

/// Coverage state of a planned experiment.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, utoipa::ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum CoverageStatus {
    /// A run with a good verdict in every excited DOF.
    Covered,
    /// Best run is weak in some excited DOF.
    Weak,
    /// Runs exist, the best one's units look wrong (milliseconds,
    /// degrees): fix the log and upload it again before deciding to fly.
    CheckUnits,
    /// Runs exist but none is usable: fly it again.
    Repeat,
    /// Not flown yet.
    Missing,
}

/// One run as seen from the coverage table.
#[derive(Debug, Clone, Serialize, utoipa::ToSchema)]
pub struct CoveredRun {
    /// Run id.
    pub run_id: String,
    /// Name.
    pub name: String,
    /// Worst verdict over the experiment's DOFs (`good`, `weak`, `insufficient`), or `rejected`.
    pub verdict: String,
    /// The reason of that verdict.
    pub reason: String,
}

/// Coverage of one planned experiment.
#[derive(Debug, Clone, Serialize, utoipa::ToSchema)]
pub struct ExperimentCoverage {
    /// Experiment id.
    pub experiment_id: String,
    /// Run order.
    pub seq: u32,
    /// Code.
    pub code: String,
    /// Family.
    pub family: String,
    /// State.
    pub status: CoverageStatus,
    /// Runs flown for it.
    pub runs: Vec<CoveredRun>,
}

/// Coverage of a campaign's newest plan.
#[derive(Debug, Clone, Serialize, utoipa::ToSchema)]
pub struct Coverage {
    /// Plan version.
    pub plan_version: i64,
    /// Experiments covered by a good run.
    pub covered: usize,
    /// Experiments whose best run is weak.
    pub weak: usize,
    /// Experiments whose best run's units look wrong (fix, upload again).
    pub check_units: usize,
    /// Experiments to fly again.
    pub repeat: usize,
    /// Experiments not flown.
    pub missing: usize,
    /// Per experiment, in run order.
    pub experiments: Vec<ExperimentCoverage>,
    /// Runs not assigned to any experiment of this plan.
    pub unassigned_runs: Vec<String>,
}

fn rank(v: &str) -> u8 {
    match v {
        "good" => 4,
        "weak" => 3,
        "check_units" => 2,
        "insufficient" => 1,
        _ => 0,
    }
}

/// The worst verdict of a run over some DOFs, with its reason.
fn run_verdict(run: &Run, dofs: &[Dof]) -> (String, String) {
    if run.status != "accepted" {
        let why = run
            .error
            .as_ref()
            .and_then(|e| e["message"].as_str())
            .unwrap_or("not processed")
            .to_string();
        return ("rejected".into(), why);
    }
    let verdicts = run
        .summary
        .as_ref()
        .and_then(|s| s["verdicts"].as_array().cloned())
        .unwrap_or_default();
    verdicts
        .iter()
        .filter(|v| dofs.is_empty() || dofs.iter().any(|d| Some(d.name()) == v["dof"].as_str()))
        .min_by_key(|v| rank(v["verdict"].as_str().unwrap_or("")))
        .map(|v| {
            (
                v["verdict"].as_str().unwrap_or("insufficient").to_string(),
                v["reason"].as_str().unwrap_or("").to_string(),
            )
        })
        .unwrap_or_else(|| {
            (
                "insufficient".into(),
                "no verdict for the experiment's DOFs".into(),
            )
        })
}

/// Coverage of a plan by runs.
pub fn coverage(plan: &StoredPlan, runs: &[Run]) -> Coverage {
    let mut out = Coverage {
        plan_version: plan.version,
        covered: 0,
        weak: 0,
        check_units: 0,
        repeat: 0,
        missing: 0,
        experiments: Vec::new(),
        unassigned_runs: Vec::new(),
    };
    for e in &plan.experiments {
        let mine: Vec<CoveredRun> = runs
            .iter()
            .filter(|r| r.experiment_id.as_deref() == Some(e.id.as_str()))
            .map(|r| {
                let (verdict, reason) = run_verdict(r, &e.experiment.dofs);
                CoveredRun {
                    run_id: r.id.clone(),
                    name: r.name.clone(),
                    verdict,
                    reason,
                }
            })
            .collect();
        let best = mine.iter().map(|r| rank(&r.verdict)).max();
        let status = match best {
            None => CoverageStatus::Missing,
            Some(4) => CoverageStatus::Covered,
            Some(3) => CoverageStatus::Weak,
            Some(2) => CoverageStatus::CheckUnits,
            Some(_) => CoverageStatus::Repeat,
        };
        match status {
            CoverageStatus::Covered => out.covered += 1,
            CoverageStatus::Weak => out.weak += 1,
            CoverageStatus::CheckUnits => out.check_units += 1,
            CoverageStatus::Repeat => out.repeat += 1,
            CoverageStatus::Missing => out.missing += 1,
        }
        out.experiments.push(ExperimentCoverage {
            experiment_id: e.id.clone(),
            seq: e.experiment.seq,
            code: e.experiment.code.clone(),
            family: e.experiment.family.name().into(),
            status,
            runs: mine,
        });
    }
    out.unassigned_runs = runs
        .iter()
        .filter(|r| {
            r.experiment_id
                .as_ref()
                .is_none_or(|id| !plan.experiments.iter().any(|e| &e.id == id))
        })
        .map(|r| r.id.clone())
        .collect();
    out
}
