//! The autopilot of an ROV whose profile declares none, inferred from the
//! campaign's flown runs of planned experiments (good and weak ones), so a
//! prediction after the first dive flies the plan through the loops that
//! flew it ([`seatrial_core::identification::autopilot_fit`]).

use std::collections::HashMap;

use seatrial_core::estimation::Progress;
use seatrial_core::identification::autopilot_fit::{InferredAutopilot, infer_autopilot};
use seatrial_core::planning::vessel::VesselKind;
use seatrial_core::planning::{Plan, VesselProfile};

use super::handler::{JobContext, JobFailure};
use super::run_inputs::{self, StoredRun};
use crate::coverage::coverage;
use crate::storage::plans::StoredPlan;
use crate::storage::runs;

/// The flown runs of `plan`'s experiments, each with its experiment code,
/// when `profile` is an ROV without a declared autopilot (else none).
pub(super) async fn flown_planned(
    cx: &JobContext,
    campaign_id: &str,
    profile: &VesselProfile,
    plan: &StoredPlan,
) -> Result<Vec<(String, StoredRun)>, JobFailure> {
    if profile.kind != VesselKind::Rov6 || profile.autopilot.is_some() {
        return Ok(Vec::new());
    }
    let all = runs::list(&cx.db, campaign_id).await?;
    let cov = coverage(plan, &all);
    let code_of: HashMap<String, String> = cov
        .experiments
        .iter()
        .flat_map(|e| {
            e.runs
                .iter()
                .filter(|r| r.verdict == "good" || r.verdict == "weak")
                .map(|r| (r.run_id.clone(), e.code.clone()))
        })
        .collect();
    let chosen: Vec<_> = all
        .into_iter()
        .filter(|r| r.status == "accepted" && !r.excluded && code_of.contains_key(&r.id))
        .collect();
    let stored = run_inputs::describe(cx, campaign_id, chosen).await?;
    Ok(stored
        .into_iter()
        .map(|s| (code_of[&s.id].clone(), s))
        .collect())
}

/// Infers the autopilot from `flown` (on the worker thread): the fit, or
/// why there is none, in words. Unreadable runs are left out.
pub(super) fn infer(
    profile: &VesselProfile,
    plan: &Plan,
    flown: &[(String, StoredRun)],
    progress: &mut dyn Progress,
) -> Result<Result<InferredAutopilot, String>, JobFailure> {
    progress.update(0.0, "inferring the autopilot from the flown runs")?;
    let mut inputs = Vec::new();
    for (code, s) in flown {
        if let Ok((mut i, _)) = run_inputs::read(profile, std::slice::from_ref(s))
            && let Some(p) = plan.experiments.iter().find(|p| p.experiment.code == *code)
            && let Some(input) = i.pop()
        {
            inputs.push((p, input));
        }
    }
    let pairs: Vec<_> = inputs.iter().map(|(p, i)| (*p, i)).collect();
    Ok(infer_autopilot(profile, &pairs).map_err(|e| {
        format!(
            "the profile declares no autopilot and none could be inferred from the {} flown runs ({e}), so the plan is flown through generic PI loops",
            pairs.len()
        )
    }))
}
