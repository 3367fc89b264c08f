//! The `discover` job: a stored model and its runs → where simulation and
//! recordings part, what physics was left out, the augmented model as the
//! model's next version, and the report. The numerics are the core's
//! [`seatrial_core::identification::discover_campaign`]; this file loads,
//! calls and stores.

use seatrial_core::estimation::{Progress, SubProgress};
use seatrial_core::identification::document::{Method, ModelDocument, ModelKind};
use seatrial_core::identification::{
    DiscoverCampaignSettings, IdentifyError, LambdaCampaignSettings, discover_campaign,
};
use sqlx::SqliteConnection;

use super::handler::{BoxFuture, Compute, JobContext, JobFailure, JobHandler, Persist, compute};
use super::identify::parse_settings;
use super::run_inputs;
use crate::error::ApiError;
use crate::processing::generalized_force_columns;
use crate::storage::discrepancies::{self, NewDiscrepancy};
use crate::storage::jobs::{Job, JobRequest};
use crate::storage::models::{self, Lineage, NewModel, StoredModel};
use crate::storage::{campaigns, runs, vessels};

/// The `discover` handler.
pub struct Discover;

async fn the_model(cx: &JobContext, req: &JobRequest) -> Result<StoredModel, ApiError> {
    let Some(id) = &req.model_id else {
        return Err(ApiError::invalid(
            "model_id",
            "discover needs the model to examine (model_id)",
        ));
    };
    let m = models::get(&cx.db, id)
        .await?
        .ok_or_else(|| ApiError::missing("model_id", format!("no model with id '{id}'")))?;
    if let Some(at) = &m.summary.deleted_at {
        return Err(ApiError::invalid(
            "model_id",
            format!(
                "model '{}' v{} ({id}) was deleted at {at}; restore it (POST /api/models/{id}/restore) first",
                m.summary.name, m.summary.version
            ),
        ));
    }
    Ok(m)
}

impl JobHandler for Discover {
    fn check<'a>(
        &'a self,
        cx: &'a JobContext,
        req: &'a JobRequest,
    ) -> BoxFuture<'a, Result<(), ApiError>> {
        Box::pin(async move {
            let model = the_model(cx, req).await?;
            if model.summary.kind != "lpv" {
                return Err(ApiError::invalid(
                    "model_id",
                    format!(
                        "discovery augments a physical LPV model (λ-filter identification); model '{}' is {} ({})",
                        model.summary.id, model.summary.kind, model.summary.method
                    ),
                ));
            }
            if let Some(cid) = &req.campaign_id
                && cid != &model.summary.campaign_id
            {
                return Err(ApiError::invalid(
                    "campaign_id",
                    format!(
                        "model '{}' belongs to campaign '{}', not to '{cid}'",
                        model.summary.id, model.summary.campaign_id
                    ),
                ));
            }
            if req.method.is_some() {
                return Err(ApiError::invalid(
                    "method",
                    "discover has no methods; its options are in settings",
                ));
            }
            parse_settings::<DiscoverCampaignSettings>(&req.settings)
                .map_err(|(field, msg)| ApiError::invalid(field, msg))?;
            Ok(())
        })
    }

    fn load<'a>(
        &'a self,
        cx: &'a JobContext,
        job: &'a Job,
    ) -> BoxFuture<'a, Result<Compute, JobFailure>> {
        Box::pin(async move {
            let req = &job.request;
            let model = the_model(cx, req)
                .await
                .map_err(|e| JobFailure::field("model_id", e.to_string()))?;
            let doc: ModelDocument = serde_json::from_value(model.document.clone())
                .map_err(|e| JobFailure::new(format!("stored model unreadable: {e}")))?;
            if doc.kind != ModelKind::Lpv {
                return Err(JobFailure::field("model_id", "not an LPV model"));
            }
            let cid = model.summary.campaign_id.clone();
            let campaign = campaigns::get(&cx.db, &cid)
                .await?
                .ok_or_else(|| JobFailure::field("model_id", "the model's campaign was deleted"))?;
            let vessel = vessels::get(&cx.db, &campaign.vessel_id)
                .await?
                .ok_or_else(|| JobFailure::field("model_id", "the vessel was deleted"))?;
            // The model's own runs, plus any the request adds (held out).
            let est_ids = model.run_ids.clone();
            let mut val_ids = model.validation_run_ids.clone();
            for id in &req.run_ids {
                if !est_ids.contains(id) && !val_ids.contains(id) {
                    val_ids.push(id.clone());
                }
            }
            let all = runs::list(&cx.db, &cid).await?;
            let mut chosen = Vec::new();
            for id in est_ids.iter().chain(&val_ids) {
                let Some(run) = all.iter().find(|r| &r.id == id).cloned() else {
                    let name = runs::get(&cx.db, id).await?.map(|r| r.name);
                    return Err(JobFailure::field(
                        "run_ids",
                        format!(
                            "run '{}' ({id}) of the model is deleted; restore it (POST /api/runs/{id}/restore) to use it",
                            name.as_deref().unwrap_or("?")
                        ),
                    ));
                };
                chosen.push(run);
            }
            let stored = run_inputs::describe(cx, &cid, chosen).await?;
            let settings = req.settings.clone();
            // The examined model's own λ-filter settings: discovery may
            // identify the campaign again with the NED current.
            let identified_with = (model.summary.method == Method::LambdaKf.name())
                .then(|| {
                    serde_json::from_value::<LambdaCampaignSettings>(model.settings.clone()).ok()
                })
                .flatten();
            let profile = vessel.profile.clone();
            let base = model.summary.clone();
            Ok(compute(move |progress: &mut dyn Progress| {
                let mut s: DiscoverCampaignSettings =
                    parse_settings(&settings).map_err(|(f, m)| JobFailure::field(f, m))?;
                if s.identification.is_none() {
                    s.identification = identified_with;
                }
                progress.update(0.0, "reading runs")?;
                let (inputs, _) = run_inputs::read(&profile, &stored)?;
                let forces = generalized_force_columns(&profile);
                let mut sub = SubProgress::new(progress, 0.05, 0.93);
                let out = discover_campaign(
                    &doc, &profile, &forces, &inputs, &est_ids, &val_ids, &s, &mut sub,
                )
                .map_err(|e| match e {
                    IdentifyError::Cancelled => JobFailure::Cancelled,
                    e => JobFailure::field(e.field().to_string(), e.to_string()),
                })?;
                let to_json = |v: serde_json::Result<serde_json::Value>| {
                    v.map_err(|e| JobFailure::new(e.to_string()))
                };
                let augmented = match out.augmented {
                    None => None,
                    Some(a) => Some(NewModel {
                        lineage: Lineage::After(base.id.clone()),
                        campaign_id: base.campaign_id.clone(),
                        vessel_id: base.vessel_id.clone(),
                        kind: base.kind.clone(),
                        method: a.document.method.name().to_string(),
                        name: augmented_name(&base.name),
                        settings: a.settings_used,
                        run_ids: a.estimation_run_ids,
                        validation_run_ids: a.validation_run_ids,
                        job_id: None,
                        document: to_json(serde_json::to_value(&a.document))?,
                        validation: to_json(serde_json::to_value(&a.validation))?,
                    }),
                };
                Ok(DiscoveryOutput {
                    augmented,
                    report: NewDiscrepancy {
                        model_id: base.id.clone(),
                        augmented_model_id: None,
                        campaign_id: base.campaign_id.clone(),
                        job_id: None,
                        settings: to_json(serde_json::to_value(&s))?,
                        run_ids: est_ids,
                        validation_run_ids: val_ids,
                        summary: out.report.summary.clone(),
                        report: to_json(serde_json::to_value(&out.report))?,
                    },
                })
            }))
        })
    }
}

/// The name of a model augmented from `base`: marked once, however often
/// discovery continues from an augmented model.
fn augmented_name(base: &str) -> String {
    const MARK: &str = " + discovered physics";
    if base.ends_with(MARK) {
        base.to_owned()
    } else {
        format!("{base}{MARK}")
    }
}

/// The report and, when terms were named, the augmented model.
struct DiscoveryOutput {
    augmented: Option<NewModel>,
    report: NewDiscrepancy,
}

impl Persist for DiscoveryOutput {
    fn persist<'a>(
        self: Box<Self>,
        conn: &'a mut SqliteConnection,
        job: &'a Job,
    ) -> BoxFuture<'a, anyhow::Result<serde_json::Value>> {
        Box::pin(async move {
            let DiscoveryOutput {
                augmented,
                mut report,
            } = *self;
            let mut version = None;
            if let Some(mut m) = augmented {
                m.job_id = Some(job.id.clone());
                let saved = models::insert(conn, m).await?;
                report.augmented_model_id = Some(saved.id.clone());
                version = Some(saved.version);
            }
            report.job_id = Some(job.id.clone());
            let model_id = report.model_id.clone();
            let augmented_model_id = report.augmented_model_id.clone();
            let id = discrepancies::insert(conn, report).await?;
            Ok(serde_json::json!({
                "discrepancy_id": id,
                "model_id": model_id,
                "augmented_model_id": augmented_model_id,
                "augmented_version": version,
            }))
        })
    }
}
