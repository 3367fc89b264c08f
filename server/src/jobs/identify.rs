//! The `identify` job: a campaign's accepted runs → a validated, versioned
//! model. Methods: `lambda_kf` (LPV by the λ-filter Kalman method, thesis
//! sec. 2.5), `n4sid` (black-box comparison), `parallel_ekf` (DP ships,
//! Fossen et al. 1995). The numerics are the core's
//! [`seatrial_core::identification`]; this file loads, calls and stores.

use seatrial_core::estimation::Progress;
use seatrial_core::identification::dataset::RunInput;
use seatrial_core::identification::ekf_checks::{RunFacts, check_ekf_job};
use seatrial_core::identification::{
    EkfCampaignSettings, Identified, IdentifyError, LambdaCampaignSettings, N4sidCampaignSettings,
    identify_ekf_campaign, identify_lambda_campaign, identify_n4sid_campaign,
};
use seatrial_core::planning::VesselProfile;
use seatrial_core::planning::vessel::{InputChannels, VesselKind};
use serde::de::DeserializeOwned;
use sqlx::SqliteConnection;

use super::handler::{BoxFuture, Compute, JobContext, JobFailure, JobHandler, Persist, compute};
use super::run_inputs;
use crate::error::ApiError;
use crate::processing::generalized_force_columns;
use crate::storage::jobs::{Job, JobRequest};
use crate::storage::models::{self, Lineage, NewModel};
use crate::storage::{campaigns, runs, vessels};

/// Methods of `identify`: `lambda_kf` (LPV on forward speed: ROVs, and
/// surface vessels logging forces τ, with a current), `n4sid` (black box,
/// any vessel), `parallel_ekf` (DP vessels).
pub const METHODS: [&str; 3] = ["lambda_kf", "n4sid", "parallel_ekf"];

/// The method used when the request names none: the vessel's physical one.
pub fn default_method(vessel: &VesselProfile) -> &'static str {
    match vessel.kind {
        VesselKind::Rov6 => "lambda_kf",
        VesselKind::Dp3 => "parallel_ekf",
    }
}

/// The `identify` handler.
pub struct Identify;

/// Parses `settings` for a method, naming the field on error.
pub(super) fn parse_settings<T: DeserializeOwned>(
    v: &serde_json::Value,
) -> Result<T, (String, String)> {
    serde_path_to_error::deserialize(v).map_err(|e| {
        let path = e.path().to_string();
        let field = if path == "." {
            "settings".to_string()
        } else {
            format!("settings.{path}")
        };
        (field, e.inner().to_string())
    })
}

fn check_method(vessel: &VesselProfile, method: &str) -> Result<(), String> {
    match (method, vessel.kind) {
        ("lambda_kf", VesselKind::Rov6) | ("n4sid", _) | ("parallel_ekf", VesselKind::Dp3) => {
            Ok(())
        }
        ("lambda_kf", VesselKind::Dp3) => match vessel.inputs {
            InputChannels::GeneralizedForces => Ok(()),
            _ => Err(format!(
                "lambda_kf fits M, D̄ and a current in SI units from forces in N and N·m; '{}' logs thruster commands whose T″ is in Bis units with unknown thrust coefficients: identify it by parallel_ekf (Fossen et al. 1995), or describe its inputs as generalized_forces (tau_X, tau_Y, tau_N) if the logs carry them",
                vessel.name
            )),
        },
        ("parallel_ekf", _) => Err(format!(
            "parallel_ekf identifies DP vessels (kind dp3) from the SI1–SI3 manoeuvres; '{}' is a {:?} vessel: use lambda_kf or n4sid",
            vessel.name, vessel.kind
        )),
        (m, _) => Err(format!(
            "unknown method '{m}'; use one of {}",
            METHODS.join(", ")
        )),
    }
}

/// Parses `settings` for a known method, naming the field on error.
fn check_settings(method: &str, settings: &serde_json::Value) -> Result<(), (String, String)> {
    match method {
        "lambda_kf" => parse_settings::<LambdaCampaignSettings>(settings).map(|_| ()),
        "parallel_ekf" => parse_settings::<EkfCampaignSettings>(settings).map(|_| ()),
        _ => parse_settings::<N4sidCampaignSettings>(settings).map(|_| ()),
    }
}

impl JobHandler for Identify {
    fn check<'a>(
        &'a self,
        cx: &'a JobContext,
        req: &'a JobRequest,
    ) -> BoxFuture<'a, Result<(), ApiError>> {
        Box::pin(async move {
            let Some(cid) = &req.campaign_id else {
                return Err(ApiError::invalid(
                    "campaign_id",
                    "identify needs the campaign whose runs to use",
                ));
            };
            let campaign = campaigns::get(&cx.db, cid).await?.ok_or_else(|| {
                ApiError::missing("campaign_id", format!("no campaign with id '{cid}'"))
            })?;
            let vessel = vessels::get(&cx.db, &campaign.vessel_id)
                .await?
                .ok_or_else(|| ApiError::missing("campaign_id", "the campaign's vessel is gone"))?;
            let method = req
                .method
                .as_deref()
                .unwrap_or(default_method(&vessel.profile));
            check_method(&vessel.profile, method).map_err(|m| ApiError::invalid("method", m))?;
            check_settings(method, &req.settings)
                .map_err(|(field, msg)| ApiError::invalid(field, msg))?;
            let all = runs::list(&cx.db, cid).await?;
            if method == "parallel_ekf" {
                check_parallel_ekf(&vessel.profile, req, &all)?;
            }
            if req.run_ids.is_empty() {
                let usable = all.iter().filter(|r| usable_by_default(r)).count();
                if usable < 2 {
                    let excluded = all.iter().filter(|r| r.excluded).count();
                    return Err(ApiError::invalid(
                        "run_ids",
                        format!(
                            "the campaign has {usable} accepted run(s) not excluded{}; identification needs estimation runs and a held-out validation run",
                            if excluded > 0 {
                                format!(
                                    " ({excluded} excluded: include them again or name them in run_ids)"
                                )
                            } else {
                                String::new()
                            }
                        ),
                    ));
                }
            }
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
            let cid = req
                .campaign_id
                .clone()
                .ok_or_else(|| JobFailure::field("campaign_id", "missing"))?;
            let campaign = campaigns::get(&cx.db, &cid)
                .await?
                .ok_or_else(|| JobFailure::field("campaign_id", "the campaign was deleted"))?;
            let vessel = vessels::get(&cx.db, &campaign.vessel_id)
                .await?
                .ok_or_else(|| JobFailure::field("campaign_id", "the vessel was deleted"))?;
            let all = runs::list(&cx.db, &cid).await?;
            let chosen: Vec<_> = if req.run_ids.is_empty() {
                all.into_iter().filter(usable_by_default).collect()
            } else {
                let mut v = Vec::new();
                for id in &req.run_ids {
                    v.push(all.iter().find(|r| &r.id == id).cloned().ok_or_else(|| {
                        JobFailure::field(
                            "run_ids",
                            format!("run '{id}' was deleted after the job was queued"),
                        )
                    })?);
                }
                v
            };
            let names: Vec<(String, String)> = chosen
                .iter()
                .map(|r| (r.id.clone(), r.name.clone()))
                .collect();
            let derived = derived_note(&chosen);
            let stored = run_inputs::describe(cx, &cid, chosen).await?;
            let method = req
                .method
                .clone()
                .unwrap_or_else(|| default_method(&vessel.profile).into());
            let settings = req.settings.clone();
            let profile = vessel.profile.clone();
            let grid = campaign.grid_speeds_mps.clone();
            let (campaign_id, vessel_id) = (campaign.id.clone(), campaign.vessel_id.clone());
            let name = format!("{} — {}", profile.name, method);
            let lineage = models::latest_of_method(&cx.db, &cid, &method)
                .await?
                .map(|m| Lineage::After(m.id))
                .unwrap_or(Lineage::New);
            Ok(compute(move |progress: &mut dyn Progress| {
                progress.update(0.0, "reading runs")?;
                let (inputs, clocks) = run_inputs::read(&profile, &stored)?;
                if method == "lambda_kf" {
                    one_sample_rate(&inputs)?;
                }
                let mut sub = seatrial_core::estimation::SubProgress::new(progress, 0.05, 0.95);
                let forces = generalized_force_columns(&profile);
                let out: Result<Identified, IdentifyError> = match method.as_str() {
                    "lambda_kf" => {
                        let s: LambdaCampaignSettings =
                            parse_settings(&settings).map_err(|(f, m)| JobFailure::field(f, m))?;
                        identify_lambda_campaign(&profile, &grid, &forces, &inputs, &s, &mut sub)
                    }
                    "parallel_ekf" => {
                        let s: EkfCampaignSettings =
                            parse_settings(&settings).map_err(|(f, m)| JobFailure::field(f, m))?;
                        let thrusters = seatrial_core::logs::commanded_columns(&profile);
                        identify_ekf_campaign(&profile, &thrusters, &inputs, &s, &mut sub)
                    }
                    _ => {
                        let s: N4sidCampaignSettings =
                            parse_settings(&settings).map_err(|(f, m)| JobFailure::field(f, m))?;
                        identify_n4sid_campaign(&profile, &forces, &inputs, &s, &mut sub)
                    }
                };
                let mut out = out.map_err(|e| match e {
                    IdentifyError::Cancelled => JobFailure::Cancelled,
                    e => {
                        let field = e.field().to_string();
                        let message = run_inputs::naming_run(&field, e.to_string(), &names);
                        JobFailure::field(field, message)
                    }
                })?;
                out.document
                    .notes
                    .extend(clocks.iter().map(run_inputs::RunClock::note));
                if method != "parallel_ekf" {
                    out.document.notes.extend(derived);
                }
                let model = NewModel {
                    lineage,
                    campaign_id,
                    vessel_id,
                    kind: serde_json::to_value(out.document.kind)
                        .ok()
                        .and_then(|v| v.as_str().map(str::to_string))
                        .unwrap_or_default(),
                    method: out.document.method.name().to_string(),
                    name,
                    settings: out.settings_used,
                    run_ids: out.estimation_run_ids,
                    validation_run_ids: out.validation_run_ids,
                    job_id: None,
                    document: serde_json::to_value(&out.document)
                        .map_err(|e| JobFailure::new(e.to_string()))?,
                    validation: serde_json::to_value(&out.validation)
                        .map_err(|e| JobFailure::new(e.to_string()))?,
                };
                Ok(NewModelOutput(model, clocks))
            }))
        })
    }
}

/// A parallel-EKF job that cannot run is refused at submission, naming what
/// is missing ([`check_ekf_job`]): the profile's L or thruster layout, a
/// run's pose channels or thruster columns (from the channels recorded at
/// upload), a held-out run, a manoeuvre. A run's field `runs[<id>]` is
/// named as the request's `run_ids[i]` when the request lists the runs.
fn check_parallel_ekf(
    profile: &VesselProfile,
    req: &JobRequest,
    all: &[crate::storage::runs::Run],
) -> Result<(), ApiError> {
    let chosen: Vec<&crate::storage::runs::Run> = if req.run_ids.is_empty() {
        all.iter().filter(|r| usable_by_default(r)).collect()
    } else {
        req.run_ids
            .iter()
            .filter_map(|id| all.iter().find(|r| &r.id == id))
            .collect()
    };
    let channels: Vec<Option<Vec<String>>> = chosen
        .iter()
        .map(|r| {
            r.summary
                .as_ref()
                .and_then(|s| s.get("channels"))
                .and_then(|c| serde_json::from_value(c.clone()).ok())
                .filter(|c: &Vec<String>| !c.is_empty())
        })
        .collect();
    let facts: Vec<RunFacts<'_>> = chosen
        .iter()
        .zip(&channels)
        .map(|(r, c)| RunFacts {
            run_id: &r.id,
            name: &r.name,
            family: r.description.family,
            channels: c.as_deref(),
        })
        .collect();
    let settings: EkfCampaignSettings =
        parse_settings(&req.settings).map_err(|(field, msg)| ApiError::invalid(field, msg))?;
    check_ekf_job(profile, &facts, &settings).map_err(|e| {
        let field = e.field().to_string();
        let field = req
            .run_ids
            .iter()
            .position(|id| field == format!("runs[{id}]"))
            .map_or(field, |i| format!("run_ids[{i}]"));
        ApiError::invalid(field, e.to_string())
    })
}

/// A note naming the runs whose velocities were derived from their pose
/// (position-only DP logs): a velocity-based method fits those, not
/// measured velocities. `None` when every run logged its velocities.
fn derived_note(runs: &[crate::storage::runs::Run]) -> Option<String> {
    let names: Vec<&str> = runs
        .iter()
        .filter(|r| {
            r.summary
                .as_ref()
                .and_then(|s| s.get("derived_channels"))
                .and_then(|d| d.as_array())
                .is_some_and(|d| !d.is_empty())
        })
        .map(|r| r.name.as_str())
        .collect();
    (!names.is_empty()).then(|| {
        format!(
            "{} of the {} runs logged no body velocities: their u, v, r were derived from the measured pose (local linear fit, rotated into the body frame), so this fit is on differentiated positions: {}",
            names.len(),
            runs.len(),
            names.join(", ")
        )
    })
}

/// Runs identification uses when the request names none: accepted and not excluded.
fn usable_by_default(r: &crate::storage::runs::Run) -> bool {
    r.status == "accepted" && !r.excluded
}

/// The λ-filter fit needs one sample time over its runs: a run logged at
/// another rate fails the job naming it (name and id), not an index into
/// the estimator's list.
fn one_sample_rate(inputs: &[RunInput]) -> Result<(), JobFailure> {
    let Some(first) = inputs.first() else {
        return Ok(());
    };
    let fs = first.record.sample_rate_hz;
    for r in &inputs[1..] {
        let other = r.record.sample_rate_hz;
        if (other - fs).abs() > 1e-9 * fs {
            return Err(JobFailure::field(
                format!("runs[{}]", r.run_id),
                format!(
                    "run '{}' ({}) is logged at {other} Hz, run '{}' ({}) at {fs} Hz: the λ-filter fit needs one sample rate; exclude one of them (PATCH /api/runs/{{id}} with excluded: true) or leave it out of run_ids",
                    r.name, r.run_id, first.name, first.run_id
                ),
            ));
        }
    }
    Ok(())
}

/// A model to store when the job succeeds, and the clock offsets its
/// two-file runs were read with (reported in the job's result).
pub struct NewModelOutput(pub NewModel, pub Vec<run_inputs::RunClock>);

impl Persist for NewModelOutput {
    fn persist<'a>(
        self: Box<Self>,
        conn: &'a mut SqliteConnection,
        job: &'a Job,
    ) -> BoxFuture<'a, anyhow::Result<serde_json::Value>> {
        Box::pin(async move {
            let NewModelOutput(mut m, clocks) = *self;
            m.job_id = Some(job.id.clone());
            let saved = models::insert(conn, m).await?;
            let mut result = serde_json::json!({ "model_id": saved.id, "version": saved.version, "lineage_id": saved.lineage_id });
            if !clocks.is_empty() {
                result["clock_offsets"] = serde_json::to_value(&clocks)?;
            }
            Ok(result)
        })
    }
}

#[cfg(test)]
mod manage_tests {
    use super::*;
    use seatrial_core::timeseries::UniformRecord;

    fn input(id: &str, name: &str, fs: f64) -> RunInput {
        RunInput {
            run_id: id.into(),
            name: name.into(),
            family: None,
            grid_speed_mps: None,
            excited_dofs: vec![],
            record: UniformRecord {
                sample_rate_hz: fs,
                t0: 0.0,
                names: vec![],
                data: vec![],
                valid: vec![],
            },
        }
    }

    #[test]
    fn a_run_at_another_rate_is_named_by_name_and_id() {
        let ok = [input("r1", "DYN-1", 10.0), input("r2", "DYN-2", 10.0)];
        assert!(one_sample_rate(&ok).is_ok());
        let bad = [input("r1", "DYN-1", 10.0), input("r7", "bad dive", 20.0)];
        let Err(JobFailure::Failed(e)) = one_sample_rate(&bad) else {
            panic!("a second rate must fail the job");
        };
        assert_eq!(e.field.as_deref(), Some("runs[r7]"));
        assert!(
            e.message.contains("'bad dive' (r7)") && e.message.contains("20 Hz"),
            "{}",
            e.message
        );
    }

    #[test]
    fn errors_about_a_run_name_it() {
        let runs = [("r1".to_string(), "DYN-1".to_string())];
        assert_eq!(
            run_inputs::naming_run("runs[r1].nu", "too short".into(), &runs),
            "run 'DYN-1' (r1): too short"
        );
        assert_eq!(
            run_inputs::naming_run("settings.k", "bad".into(), &runs),
            "bad"
        );
    }
}
