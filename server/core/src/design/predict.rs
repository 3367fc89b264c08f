//! Predicted precision of a plan: fly it with the prior, log it with the
//! sensor noise, identify it as the campaign will be, read the stds.

use std::collections::HashMap;

use super::table::Scaled;
use super::{DesignError, PrecisionPrediction, Prior, PriorSource};
use crate::estimation::{Progress, SubProgress};
use crate::identification::document::ParameterRow;
use crate::identification::{
    EkfCampaignSettings, IdentifyError, LambdaCampaignSettings, RunInput, identify_ekf_campaign,
    identify_lambda_campaign,
};
use crate::logs::{LogRole, ParseOptions, input_columns, parse_log, to_uniform};
use crate::planning::dof::Dof;
use crate::planning::{Plan, PlannedExperiment, VesselProfile};
use crate::simulation::dp_ship::{DpFlightSettings, fly_dp_campaign};
use crate::simulation::trials::{MeasurementNoise, TrialSettings, fly_campaign};

/// How to fly the plan for a prediction.
#[derive(Debug, Clone, PartialEq)]
pub struct PredictSettings {
    /// Seed of the simulated sensor noise.
    pub seed: u64,
    /// ROV navigation noise (DVL, gyros, USBL, depth, attitude).
    pub rov_noise: MeasurementNoise,
    /// DP position/heading noise and bias (the supply vessel's trials by
    /// default); its seed is replaced by `seed`.
    pub dp_flight: DpFlightSettings,
}

impl Default for PredictSettings {
    fn default() -> Self {
        PredictSettings {
            seed: 1,
            rov_noise: MeasurementNoise::default(),
            dp_flight: DpFlightSettings::supply_vessel(1),
        }
    }
}

/// Predicts how precisely `plan` determines each parameter of the
/// identification the vessel gets (λ-filter for ROVs, the parallel EKF
/// with refinement for DP ships), with `prior` as the vessel.
pub fn predict_precision(
    profile: &VesselProfile,
    plan: &Plan,
    prior: &Prior,
    source: PriorSource,
    settings: &PredictSettings,
    progress: &mut dyn Progress,
) -> Result<PrecisionPrediction, DesignError> {
    progress
        .update(0.0, "flying the plan with the prior")
        .map_err(|_| cancelled())?;
    let flown: Vec<(&PlannedExperiment, String)> = match prior {
        Prior::Rov(truth) => {
            let s = TrialSettings {
                noise: settings.rov_noise,
                seed: settings.seed,
                ..TrialSettings::default()
            };
            let runs = fly_campaign(profile, truth, plan, &s, |_| true).map_err(trial_error)?;
            pair(plan, runs.into_iter().map(|r| (r.seq, r.csv)))?
        }
        Prior::Dp(ship) => {
            let s = DpFlightSettings {
                seed: settings.seed,
                ..settings.dp_flight.clone()
            };
            let runs = fly_dp_campaign(profile, ship, plan, &s, |_| true).map_err(trial_error)?;
            pair(plan, runs.into_iter().map(|r| (r.seq, r.csv)))?
        }
    };
    progress
        .update(0.15, "reading the simulated logs")
        .map_err(|_| cancelled())?;
    let runs = flown
        .iter()
        .map(|(p, csv)| run_input(profile, p, csv))
        .collect::<Result<Vec<_>, _>>()?;
    let inputs = input_columns(profile);
    let ship_hours = plan.totals.total_time_s / 3600.0;
    let mut sub = SubProgress::new(progress, 0.2, 0.98);
    let (method, identified) = match prior {
        Prior::Rov(_) => {
            let grid = grid_speeds(plan);
            let id = identify_lambda_campaign(
                profile,
                &grid,
                &inputs,
                &runs,
                &LambdaCampaignSettings::default(),
                &mut sub,
            )
            .map_err(identify_error)?;
            ("lambda_kf", id)
        }
        Prior::Dp(_) => {
            let id = identify_ekf_campaign(
                profile,
                &inputs,
                &runs,
                &EkfCampaignSettings::default(),
                &mut sub,
            )
            .map_err(identify_error)?;
            ("parallel_ekf", id)
        }
    };
    let doc = &identified.document;
    let mut rows: Vec<&ParameterRow> = doc.parameters.iter().collect();
    if let Some(r) = &doc.restoring {
        for p in &r.parameters {
            if !rows
                .iter()
                .any(|q| q.symbol == p.symbol && q.group == p.group)
            {
                rows.push(p);
            }
        }
    }
    let scaled = scale_rows(profile, &rows);
    let mut notes = vec![
        match prior {
            Prior::Rov(_) => format!(
                "the plan's {} experiments flown by the project's ROV simulator with the prior, logged with DVL ±{} m/s, gyro ±{} rad/s, attitude ±{} rad noise (seed {}), and identified by the λ-filter method with its default settings; a std is the posterior of the λ regression (inverse Fisher information), carried to M and D̄ by the delta method",
                runs.len(),
                settings.rov_noise.nu[0],
                settings.rov_noise.nu[3],
                settings.rov_noise.eta[3],
                settings.seed
            ),
            Prior::Dp(_) => format!(
                "the plan's {} experiments flown by the project's DP ship simulator with the prior, logged with ±{} m position and ±{:.2}° heading noise and a slowly varying bias (seed {}), and identified by the staged parallel EKF with refinement; a std is the Cramér–Rao bound √diag J⁻¹ of the refinement's Fisher information",
                runs.len(),
                settings.dp_flight.trial.position_noise_std * profile
                    .dp_prior
                    .as_ref()
                    .map_or(1.0, |p| p.length_m),
                settings.dp_flight.trial.heading_noise_std.to_degrees(),
                settings.seed
            ),
        },
        "a std assumes the prior is the vessel and the noise is as stated; real runs with waves, current or a mis-logged τ do worse".into(),
    ];
    notes.extend(
        doc.structure_findings
            .iter()
            .map(|f| format!("on the simulated campaign: {f}")),
    );
    Ok(PrecisionPrediction::tabulate(
        method,
        source,
        ship_hours,
        runs.len(),
        &scaled,
        notes,
    ))
}

/// Flown logs matched to their planned experiments by run order.
fn pair(
    plan: &Plan,
    flown: impl Iterator<Item = (u32, String)>,
) -> Result<Vec<(&PlannedExperiment, String)>, DesignError> {
    flown
        .map(|(seq, csv)| {
            plan.experiments
                .iter()
                .find(|p| p.experiment.seq == seq)
                .map(|p| (p, csv))
                .ok_or_else(|| DesignError::new("plan", format!("no experiment {seq}")))
        })
        .collect()
}

fn run_input(
    profile: &VesselProfile,
    planned: &PlannedExperiment,
    csv: &str,
) -> Result<RunInput, DesignError> {
    let e = &planned.experiment;
    let field = || format!("plan.experiments[{}]", e.code);
    let parsed = parse_log(
        csv.as_bytes(),
        &ParseOptions::for_vessel(profile, LogRole::Single, None),
    )
    .map_err(|err| DesignError::new(field(), format!("simulated log unreadable: {err}")))?;
    let (record, _) = to_uniform(&parsed.table, None)
        .map_err(|err| DesignError::new(field(), format!("simulated log unreadable: {err}")))?;
    Ok(RunInput {
        run_id: e.code.clone(),
        name: e.code.clone(),
        family: Some(e.family),
        grid_speed_mps: e.grid_speed_mps,
        excited_dofs: e.dofs.clone(),
        record,
    })
}

/// The plan's grid speeds, ascending.
fn grid_speeds(plan: &Plan) -> Vec<f64> {
    let mut g: Vec<f64> = plan
        .experiments
        .iter()
        .filter_map(|p| p.experiment.grid_speed_mps)
        .collect();
    g.sort_by(f64::total_cmp);
    g.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    g
}

/// Each row with the magnitude its std is measured against (module docs
/// of [`super`]).
fn scale_rows<'a>(profile: &VesselProfile, rows: &[&'a ParameterRow]) -> Vec<Scaled<'a>> {
    let entry = |symbol: &str| -> Option<(usize, usize)> {
        let inner = symbol.split_once('[')?.1.strip_suffix(']')?;
        let (a, b) = inner.split_once(',')?;
        let idx = |n: &str| Dof::ALL.iter().position(|d| d.name() == n.trim());
        Some((idx(a)?, idx(b)?))
    };
    let mut diagonal: HashMap<(String, u64, usize), f64> = HashMap::new();
    for r in rows {
        if let Some((i, j)) = entry(&r.symbol)
            && i == j
        {
            let speed = r.grid_speed_mps.unwrap_or(f64::NAN).to_bits();
            diagonal.insert((r.group.clone(), speed, i), r.value.abs());
        }
    }
    let theta = |k: usize| {
        rows.iter()
            .find(|r| r.group == "θ″" && r.symbol.starts_with(&format!("θ″{k} ")))
            .map(|r| r.value.abs())
    };
    let own = |v: f64| (v != 0.0).then(|| (v.abs(), "its value".to_string()));
    rows.iter()
        .map(|r| {
            let reference = match (r.group.as_str(), entry(&r.symbol)) {
                ("M" | "D̄", Some((i, j))) if i != j => {
                    let speed = r.grid_speed_mps.unwrap_or(f64::NAN).to_bits();
                    let d = |k| diagonal.get(&(r.group.clone(), speed, k)).copied();
                    d(i).zip(d(j)).map(|(a, b)| {
                        let g = if r.group == "M" { "M" } else { "D̄" };
                        (
                            (a * b).sqrt(),
                            format!(
                                "√|{g}[{0},{0}]·{g}[{1},{1}]|",
                                Dof::ALL[i].name(),
                                Dof::ALL[j].name()
                            ),
                        )
                    })
                }
                ("b", _) => {
                    let dof = Dof::ALL
                        .iter()
                        .find(|d| r.symbol == format!("b[{}]", d.name()));
                    dof.and_then(|d| profile.limits.get(d))
                        .map(|l| (l.max_force, "the DOF's force limit".to_string()))
                }
                ("θ″", _) if r.symbol.contains("A_h23") || r.symbol.contains("A_h32") => {
                    theta(2)
                        .zip(theta(5))
                        .map(|(a, b)| ((a * b).sqrt(), "√|A″_h22·A″_h33|".to_string()))
                }
                _ => own(r.value),
            };
            Scaled { row: r, reference }
        })
        .collect()
}

fn trial_error(e: crate::simulation::trials::TrialError) -> DesignError {
    DesignError::new(
        e.field(),
        format!("the plan could not be flown with the prior: {e}"),
    )
}

fn identify_error(e: IdentifyError) -> DesignError {
    if matches!(e, IdentifyError::Cancelled) {
        return cancelled();
    }
    DesignError::new(
        e.field().to_string(),
        format!("the simulated campaign could not be identified: {e}"),
    )
}

fn cancelled() -> DesignError {
    DesignError::Cancelled
}
