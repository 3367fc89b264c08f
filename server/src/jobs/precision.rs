//! The `precision` job: a campaign's current plan and a prior model →
//! the precision each identified parameter is predicted to reach, before
//! the runs are flown. The numerics are the core's
//! [`seatrial_core::design`]; this file loads, calls and returns the table
//! as the job's result (read back by `GET /api/campaigns/{id}/precision`).

use seatrial_core::design::{
    DesignError, MAX_REALISATIONS, PrecisionPrediction, PredictSettings, Prior, PriorSource,
    predict_precision,
};
use seatrial_core::estimation::Progress;
use seatrial_core::identification::autopilot_fit::InferredAutopilot;
use seatrial_core::identification::document::ModelDocument;
use seatrial_core::planning::{ExperimentFamily, Plan, PlannedExperiment};
use serde::{Deserialize, Serialize};

use super::flown_autopilot;
use super::handler::{BoxFuture, Compute, JobContext, JobFailure, JobHandler, compute};
use super::identify::parse_settings;
use crate::error::ApiError;
use crate::storage::jobs::{Job, JobRequest};
use crate::storage::{campaigns, models, plans, vessels};

/// The prior a plan is flown with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, utoipa::ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum PriorChoice {
    /// The stored model named by the job's `model_id` (its vessel's).
    Model,
    /// The vessel profile's limits and time constants (rough).
    Profile,
    /// The source documents' vessel: the thesis's Surveyor-like ROV, or the
    /// supply vessel's identified θ″ (Fossen et al. 1995, eq. 48–49).
    Reference,
}

/// Settings of a `precision` job.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, utoipa::ToSchema)]
#[serde(deny_unknown_fields)]
pub struct PrecisionSettings {
    /// The prior; default: `model` when `model_id` is given, else `profile`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub prior: Option<PriorChoice>,
    /// Seed of the simulated sensor noise (default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
    /// Noise realisations flown and identified, 1–100 (default 20): the
    /// predicted std is their spread, uncertain by ≈ 1/√(2(n − 1)).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(minimum = 1, maximum = 100)]
    pub realisations: Option<usize>,
}

impl PrecisionSettings {
    pub(super) fn prior(&self, req: &JobRequest) -> PriorChoice {
        prior_or_default(self.prior, req)
    }
}

/// A planning job's prior: the one asked for, else `model` when the job
/// names a `model_id`, else the vessel profile's rough numbers.
pub(super) fn prior_or_default(prior: Option<PriorChoice>, req: &JobRequest) -> PriorChoice {
    prior.unwrap_or(if req.model_id.is_some() {
        PriorChoice::Model
    } else {
        PriorChoice::Profile
    })
}

/// The job's result: the prediction and the plan version it is for.
#[derive(Debug, Clone, Serialize, Deserialize, utoipa::ToSchema)]
pub struct PrecisionResult {
    /// The plan predicted.
    pub plan_id: String,
    /// Its version.
    pub plan_version: i64,
    /// The table.
    pub prediction: PrecisionPrediction,
    /// For an ROV whose profile declares no autopilot: the one inferred
    /// from the campaign's flown runs, which the prediction flew (copy it
    /// into the vessel profile's `autopilot` to keep it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inferred_autopilot: Option<InferredAutopilot>,
}

/// The `precision` handler.
pub struct Precision;

struct Checked {
    profile: seatrial_core::planning::VesselProfile,
    settings: PrecisionSettings,
    model: Option<(ModelDocument, PriorSource)>,
}

async fn checked(cx: &JobContext, req: &JobRequest) -> Result<Checked, ApiError> {
    let settings: PrecisionSettings =
        parse_settings(&req.settings).map_err(|(f, m)| ApiError::invalid(f, m))?;
    if let Some(n) = settings.realisations
        && !(1..=MAX_REALISATIONS).contains(&n)
    {
        return Err(ApiError::invalid(
            "settings.realisations",
            format!("must be between 1 and {MAX_REALISATIONS} (got {n})"),
        ));
    }
    let found = campaign_and_prior(cx, req, "precision", settings.prior(req)).await?;
    let Some(plan) = plans::latest(&cx.db, &found.campaign.id).await? else {
        return Err(no_plan(&found.campaign));
    };
    if !plan
        .experiments
        .iter()
        .any(|e| e.experiment.family == ExperimentFamily::Validation)
    {
        return Err(ApiError::invalid(
            "campaign_id",
            format!(
                "plan v{} of campaign '{}' has no validation run, and the identification holds one out; add the validation family (re-plan) to predict its precision",
                plan.version, found.campaign.spec.name
            ),
        ));
    }
    Ok(Checked {
        profile: found.profile,
        settings,
        model: found.model,
    })
}

/// The campaign's newest plan as stored and as the core's [`Plan`] (its
/// schedules read back).
pub(super) async fn core_plan(
    cx: &JobContext,
    cid: &str,
) -> Result<(plans::StoredPlan, Plan), JobFailure> {
    let stored = plans::latest(&cx.db, cid)
        .await?
        .ok_or_else(|| JobFailure::field("campaign_id", "the plan was deleted"))?;
    let mut experiments = Vec::with_capacity(stored.experiments.len());
    let mut conn = cx.db.acquire().await?;
    for e in &stored.experiments {
        experiments.push(PlannedExperiment {
            experiment: e.experiment.clone(),
            schedule: plans::schedule(&mut conn, &e.id).await?,
        });
    }
    drop(conn);
    let plan = Plan {
        experiments,
        totals: stored.totals.clone(),
    };
    Ok((stored, plan))
}

/// The 422 of a campaign without a plan.
pub(super) fn no_plan(campaign: &campaigns::Campaign) -> ApiError {
    ApiError::invalid(
        "campaign_id",
        format!(
            "campaign '{}' has no plan yet; generate one (POST /api/campaigns/{}/plan) first",
            campaign.spec.name, campaign.id
        ),
    )
}

/// A planning job's campaign, its vessel's profile and the stored model
/// the prior comes from (when `choice` is `model`), checked.
pub(super) struct CampaignPrior {
    pub campaign: campaigns::Campaign,
    pub profile: seatrial_core::planning::VesselProfile,
    pub model: Option<(ModelDocument, PriorSource)>,
}

/// Checks a planning job's request (`kind` names it in messages): a
/// campaign, no method or runs, and a model of the campaign's vessel when
/// the prior is a stored model.
pub(super) async fn campaign_and_prior(
    cx: &JobContext,
    req: &JobRequest,
    kind: &str,
    choice: PriorChoice,
) -> Result<CampaignPrior, ApiError> {
    let Some(cid) = &req.campaign_id else {
        return Err(ApiError::invalid(
            "campaign_id",
            format!("{kind} needs the campaign whose plan to predict"),
        ));
    };
    if req.method.is_some() {
        return Err(ApiError::invalid(
            "method",
            format!(
                "{kind} flies the vessel's physical identification (lambda_kf for an ROV, parallel_ekf for a DP ship); it takes no method"
            ),
        ));
    }
    if !req.run_ids.is_empty() {
        return Err(ApiError::invalid(
            "run_ids",
            format!("{kind} flies the plan in simulation; it reads no runs"),
        ));
    }
    let campaign = campaigns::get(&cx.db, cid)
        .await?
        .ok_or_else(|| ApiError::missing("campaign_id", format!("no campaign with id '{cid}'")))?;
    let vessel = vessels::get(&cx.db, &campaign.vessel_id)
        .await?
        .ok_or_else(|| ApiError::missing("campaign_id", "the campaign's vessel is gone"))?;
    let model = match (choice, &req.model_id) {
        (PriorChoice::Model, None) => {
            return Err(ApiError::invalid(
                "model_id",
                "settings.prior = model needs the model to fly the plan with (model_id)",
            ));
        }
        (PriorChoice::Model, Some(id)) => {
            let m = models::get(&cx.db, id)
                .await?
                .ok_or_else(|| ApiError::missing("model_id", format!("no model with id '{id}'")))?;
            if m.summary.vessel_id != vessel.id {
                return Err(ApiError::invalid(
                    "model_id",
                    format!(
                        "model '{}' v{} is of another vessel; the prior must describe '{}'",
                        m.summary.name, m.summary.version, vessel.profile.name
                    ),
                ));
            }
            let doc: ModelDocument = serde_json::from_value(m.document)
                .map_err(|e| ApiError::invalid("model_id", format!("model unreadable: {e}")))?;
            Some((
                doc,
                PriorSource::Model {
                    model_id: m.summary.id.clone(),
                    version: m.summary.version,
                },
            ))
        }
        (_, Some(_)) => {
            return Err(ApiError::invalid(
                "model_id",
                "a model_id is only used with settings.prior = model",
            ));
        }
        (_, None) => None,
    };
    if let Some((doc, _)) = &model {
        Prior::from_model(doc, &vessel.profile).map_err(design_invalid)?;
    }
    Ok(CampaignPrior {
        campaign,
        profile: vessel.profile,
        model,
    })
}

/// The prior `choice` names, built in the worker.
pub(super) fn build_prior(
    choice: PriorChoice,
    model: Option<(ModelDocument, PriorSource)>,
    profile: &seatrial_core::planning::VesselProfile,
) -> Result<(Prior, PriorSource), JobFailure> {
    let (prior, source) = match (choice, model) {
        (PriorChoice::Model, Some((doc, source))) => (Prior::from_model(&doc, profile), source),
        (PriorChoice::Reference, _) => (Prior::reference(profile), PriorSource::Reference),
        _ => (Prior::from_profile(profile), PriorSource::Profile),
    };
    Ok((prior.map_err(failure)?, source))
}

pub(super) fn design_invalid(e: DesignError) -> ApiError {
    ApiError::invalid(e.field().to_string(), e.to_string())
}

impl JobHandler for Precision {
    fn check<'a>(
        &'a self,
        cx: &'a JobContext,
        req: &'a JobRequest,
    ) -> BoxFuture<'a, Result<(), ApiError>> {
        Box::pin(async move { checked(cx, req).await.map(|_| ()) })
    }

    fn load<'a>(
        &'a self,
        cx: &'a JobContext,
        job: &'a Job,
    ) -> BoxFuture<'a, Result<Compute, JobFailure>> {
        Box::pin(async move {
            let req = &job.request;
            let c = checked(cx, req)
                .await
                .map_err(|e| JobFailure::new(e.to_string()))?;
            let cid = req.campaign_id.clone().unwrap_or_default();
            let (stored, plan) = core_plan(cx, &cid).await?;
            let choice = c.settings.prior(req);
            let seed = c.settings.seed.unwrap_or(1);
            let realisations = c.settings.realisations;
            let flown = flown_autopilot::flown_planned(cx, &cid, &c.profile, &stored).await?;
            let (plan_id, plan_version) = (stored.id.clone(), stored.version);
            Ok(compute(move |progress: &mut dyn Progress| {
                let mut profile = c.profile;
                let (mut inferred, mut why_not) = (None, None);
                if !flown.is_empty() {
                    match flown_autopilot::infer(&profile, &plan, &flown, progress)? {
                        Ok(fit) => {
                            profile.autopilot = Some(fit.autopilot.clone());
                            inferred = Some(fit);
                        }
                        Err(why) => why_not = Some(why),
                    }
                }
                let (prior, source) = build_prior(choice, c.model, &profile)?;
                let defaults = PredictSettings::default();
                let settings = PredictSettings {
                    seed,
                    realisations: realisations.unwrap_or(defaults.realisations),
                    ..defaults
                };
                let mut prediction =
                    predict_precision(&profile, &plan, &prior, source, &settings, progress)
                        .map_err(failure)?;
                if let Some(fit) = &inferred {
                    prediction.notes.insert(
                        1,
                        format!(
                            "the profile declares no autopilot: it was inferred from {} flown runs of the plan (`inferred_autopilot`), and the plan flown through it",
                            fit.loops.iter().map(|l| l.runs).max().unwrap_or(0)
                        ),
                    );
                }
                prediction.notes.extend(why_not);
                serde_json::to_value(PrecisionResult {
                    plan_id,
                    plan_version,
                    prediction,
                    inferred_autopilot: inferred,
                })
                .map_err(|e| JobFailure::new(e.to_string()))
            }))
        })
    }
}

pub(super) fn failure(e: DesignError) -> JobFailure {
    match e {
        DesignError::Cancelled => JobFailure::Cancelled,
        e => JobFailure::field(e.field().to_string(), e.to_string()),
    }
}
