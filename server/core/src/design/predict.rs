//! Predicted precision of a plan: fly it with the prior, log it with the
//! sensor noise, identify it as the campaign will be, read the stds.

use std::collections::HashMap;

use super::table::Scaled;
use super::{DesignError, PrecisionPrediction, Prior, PriorSource};
use crate::estimation::{NoProgress, Progress};
use crate::identification::document::{ModelDocument, ParameterRow};
use crate::identification::{
    EkfCampaignSettings, IdentifyError, LambdaCampaignSettings, RunInput, identify_ekf_campaign,
    identify_lambda_campaign,
};
use crate::logs::{LogRole, ParseOptions, input_columns, parse_log, to_uniform};
use crate::planning::dof::Dof;
use crate::planning::{ExperimentFamily, Plan, PlannedExperiment, VesselProfile};
use crate::rng::mix;
use crate::simulation::dp_ship::{DpFlightSettings, fly_dp_campaign};
use crate::simulation::trials::{Feedback, MeasurementNoise, TrialSettings, fly_campaign};

/// How to fly the plan for a prediction.
#[derive(Debug, Clone, PartialEq)]
pub struct PredictSettings {
    /// Seed of the simulated sensor noise (realisation r uses mix(seed ⊕ r)).
    pub seed: u64,
    /// Noise realisations flown and identified: the predicted std is their
    /// spread (its own relative error ≈ 1/√(2(n − 1)): 16 % at 20). One
    /// realisation gives the identification's reported std instead.
    pub realisations: usize,
    /// ROV navigation noise (DVL, gyros, USBL, depth, attitude).
    pub rov_noise: MeasurementNoise,
    /// What the ROV's controller feeds back (the sensors, as at sea).
    pub rov_feedback: Feedback,
    /// DP position/heading noise and bias (the supply vessel's trials by
    /// default); its seed is replaced per realisation.
    pub dp_flight: DpFlightSettings,
    /// How an ROV's flights are identified (the campaign's default λ-filter
    /// identification unless told otherwise).
    pub lambda: LambdaCampaignSettings,
}

/// Most noise realisations of one prediction.
pub const MAX_REALISATIONS: usize = 100;

impl Default for PredictSettings {
    fn default() -> Self {
        PredictSettings {
            seed: 1,
            realisations: 20,
            rov_noise: MeasurementNoise::default(),
            rov_feedback: Feedback::Measured,
            dp_flight: DpFlightSettings::supply_vessel(1),
            lambda: LambdaCampaignSettings::default(),
        }
    }
}

/// One realisation: the plan flown with one noise seed and identified.
struct Realisation {
    runs: usize,
    doc: ModelDocument,
}

/// Flies `plan` with `prior` under noise seed `seed` and identifies it.
fn realise(
    profile: &VesselProfile,
    plan: &Plan,
    prior: &Prior,
    settings: &PredictSettings,
    seed: u64,
    progress: &mut dyn Progress,
) -> Result<Realisation, DesignError> {
    let flown: Vec<(&PlannedExperiment, String)> = match prior {
        Prior::Rov(truth) => {
            let s = TrialSettings {
                noise: settings.rov_noise,
                seed,
                feedback: settings.rov_feedback,
                ..TrialSettings::default()
            };
            let runs = fly_campaign(profile, truth, plan, &s, |_| true).map_err(trial_error)?;
            pair(plan, runs.into_iter().map(|r| (r.seq, r.csv)))?
        }
        Prior::Dp(ship) => {
            let s = DpFlightSettings {
                seed,
                ..settings.dp_flight.clone()
            };
            let runs = fly_dp_campaign(profile, ship, plan, &s, |_| true).map_err(trial_error)?;
            pair(plan, runs.into_iter().map(|r| (r.seq, r.csv)))?
        }
    };
    let runs = flown
        .iter()
        .map(|(p, csv)| run_input(profile, p, csv))
        .collect::<Result<Vec<_>, _>>()?;
    let inputs = input_columns(profile);
    let identified = match prior {
        Prior::Rov(_) => identify_lambda_campaign(
            profile,
            &plan.grid_speeds(),
            &inputs,
            &runs,
            &settings.lambda,
            progress,
        ),
        Prior::Dp(_) => identify_ekf_campaign(
            profile,
            &crate::logs::commanded_columns(profile),
            &runs,
            &EkfCampaignSettings::default(),
            progress,
        ),
    }
    .map_err(identify_error)?;
    Ok(Realisation {
        runs: runs.len(),
        doc: identified.document,
    })
}

/// Every parameter row of a document: the model's and g(η)'s.
fn rows(doc: &ModelDocument) -> Vec<ParameterRow> {
    let mut rows = doc.parameters.clone();
    if let Some(r) = &doc.restoring {
        for p in &r.parameters {
            if !rows
                .iter()
                .any(|q| q.symbol == p.symbol && q.group == p.group)
            {
                rows.push(p.clone());
            }
        }
    }
    rows
}

/// A parameter row's identity: group, symbol, grid speed (bits).
type RowKey = (String, String, Option<u64>);

fn key(r: &ParameterRow) -> RowKey {
    (
        r.group.clone(),
        r.symbol.clone(),
        r.grid_speed_mps.map(f64::to_bits),
    )
}

/// Predicts how precisely `plan` determines each parameter of the
/// identification the vessel gets (λ-filter for ROVs, the parallel EKF
/// with refinement for DP ships), with `prior` as the vessel: the spread of
/// the estimates over `settings.realisations` noise realisations of the
/// plan, and the std the identification will report.
pub fn predict_precision(
    profile: &VesselProfile,
    plan: &Plan,
    prior: &Prior,
    source: PriorSource,
    settings: &PredictSettings,
    progress: &mut dyn Progress,
) -> Result<PrecisionPrediction, DesignError> {
    let n = settings.realisations;
    if n == 0 || n > MAX_REALISATIONS {
        return Err(DesignError::new(
            "settings.realisations",
            format!("must be between 1 and {MAX_REALISATIONS} (got {n})"),
        ));
    }
    if !plan
        .experiments
        .iter()
        .any(|p| p.experiment.family == ExperimentFamily::Validation)
    {
        return Err(DesignError::new(
            "plan",
            "the plan has no validation run, and the identification holds one out; add the validation family (re-plan) to predict it",
        ));
    }
    let seeds: Vec<u64> = (0..n as u64)
        .map(|r| {
            if r == 0 {
                settings.seed
            } else {
                mix(settings.seed ^ mix(r))
            }
        })
        .collect();
    // Realisations are independent: two at a time on scoped threads, the
    // progress reported between pairs.
    let mut done: Vec<Realisation> = Vec::with_capacity(n);
    let mut failed: Vec<DesignError> = Vec::new();
    for (b, batch) in seeds.chunks(2).enumerate() {
        progress
            .update(
                (2 * b) as f64 / n as f64,
                &format!(
                    "flying and identifying noise realisation {} of {n}",
                    2 * b + 1
                ),
            )
            .map_err(|_| cancelled())?;
        let out: Vec<Result<Realisation, DesignError>> = std::thread::scope(|s| {
            let handles: Vec<_> = batch
                .iter()
                .map(|&seed| {
                    s.spawn(move || realise(profile, plan, prior, settings, seed, &mut NoProgress))
                })
                .collect();
            handles
                .into_iter()
                .map(|h| {
                    h.join()
                        .unwrap_or_else(|_| Err(DesignError::new("plan", "a realisation panicked")))
                })
                .collect()
        });
        for r in out {
            match r {
                Ok(r) => done.push(r),
                Err(DesignError::Cancelled) => return Err(DesignError::Cancelled),
                Err(e) => failed.push(e),
            }
        }
    }
    // One unlucky realisation does not sink the prediction; most failing
    // means the plan or the prior is at fault.
    if done.is_empty() || done.len() * 2 < n {
        return Err(failed
            .into_iter()
            .next()
            .unwrap_or_else(|| DesignError::new("plan", "no realisation could be identified")));
    }
    progress
        .update(0.99, "tabulating")
        .map_err(|_| cancelled())?;
    let per: Vec<HashMap<_, ParameterRow>> = done
        .iter()
        .map(|r| rows(&r.doc).into_iter().map(|p| (key(&p), p)).collect())
        .collect();
    // M fitted symmetric has one parameter per off-diagonal pair: the
    // lower entry, equal to the upper in every realisation, is not listed.
    let mut mirrored = 0;
    let first: Vec<ParameterRow> = rows(&done[0].doc)
        .into_iter()
        .filter(|p| {
            let dup = mirrors_upper_entry(p, &per);
            mirrored += usize::from(dup);
            !dup
        })
        .collect();
    // Per parameter: mean value, spread over realisations, median reported std.
    let mut reported_median = Vec::with_capacity(first.len());
    let table: Vec<ParameterRow> = first
        .iter()
        .map(|p| {
            let k = key(p);
            let vals: Vec<f64> = per
                .iter()
                .filter_map(|m| m.get(&k).map(|q| q.value))
                .filter(|v| v.is_finite())
                .collect();
            let mut reported: Vec<f64> = per
                .iter()
                .filter_map(|m| m.get(&k).and_then(|q| q.std))
                .filter(|v| v.is_finite())
                .collect();
            reported.sort_by(f64::total_cmp);
            let median = reported.get(reported.len() / 2).copied();
            reported_median.push(median);
            let mean = vals.iter().sum::<f64>() / vals.len().max(1) as f64;
            let spread = (vals.len() > 1).then(|| {
                (vals.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (vals.len() - 1) as f64)
                    .sqrt()
            });
            ParameterRow {
                value: if vals.is_empty() { p.value } else { mean },
                std: if done.len() > 1 { spread } else { median },
                ..p.clone()
            }
        })
        .collect();
    // An entry the identification fixes in most realisations (reported std
    // 0: a coupling the structure choice leaves out) is not a parameter of
    // this plan's model.
    let fixed = reported_median.iter().filter(|r| **r == Some(0.0)).count();
    let (table, reported_median): (Vec<ParameterRow>, Vec<Option<f64>>) = table
        .into_iter()
        .zip(reported_median)
        .filter(|(_, r)| *r != Some(0.0))
        .unzip();
    let refs: Vec<&ParameterRow> = table.iter().collect();
    let mut scaled = scale_rows(profile, &refs);
    for (s, r) in scaled.iter_mut().zip(reported_median) {
        s.reported_std = r;
    }
    let doc = &done[0].doc;
    let runs = done[0].runs;
    let (method, how) = match prior {
        Prior::Rov(_) => (
            "lambda_kf",
            format!(
                "the plan's {runs} experiments flown {n} times by the project's ROV simulator with the prior, its controller reading sensors with DVL ±{} m/s, gyro ±{} rad/s, attitude ±{} rad noise (seeds from {}), and each flight identified by the λ-filter method with its default settings",
                settings.rov_noise.nu[0],
                settings.rov_noise.nu[3],
                settings.rov_noise.eta[3],
                settings.seed
            ),
        ),
        Prior::Dp(_) => (
            "parallel_ekf",
            format!(
                "the plan's {runs} experiments flown {n} times by the project's DP ship simulator with the prior, logged with ±{} m position and ±{:.2}° heading noise and a slowly varying bias (seeds from {}), and each flight identified by the staged parallel EKF with refinement",
                settings.dp_flight.trial.position_noise_std
                    * profile.dp_prior.as_ref().map_or(1.0, |p| p.length_m),
                settings.dp_flight.trial.heading_noise_std.to_degrees(),
                settings.seed
            ),
        ),
    };
    let loops = match (prior, &profile.autopilot) {
        (Prior::Rov(_), Some(_)) => Some(
            "the ROV flies the plan through its own autopilot (the loops' gains and ĝ(η) feed-forward of the vessel profile, or inferred from flown runs), as it will at sea".to_string(),
        ),
        (Prior::Rov(_), None) => Some(
            "the vessel profile declares no autopilot, so the ROV flies the plan through generic PI loops designed from its limits; how stiffly the real loops hold each DOF decides how much sensor noise becomes thrust and motion, so declare the autopilot (`autopilot` in the profile) for a sharper prediction (on the independent truth: within 1.5× of the spread for 92 % of the parameters with it, 57 % without)".to_string(),
        ),
        (Prior::Dp(_), _) => None,
    };
    let mut notes = vec![
        how,
        if n > 1 {
            format!(
                "predicted std: the spread of the {n} estimates (itself uncertain by about {:.0} %); reported std: the median of what the identification reported on them, which also carries the misfit of the model's structure — where it is much larger than the spread, more ship time will not help, a richer model would",
                100.0 / (2.0 * (n as f64 - 1.0)).sqrt()
            )
        } else {
            "one realisation: the predicted std is the std the identification reported on it".into()
        },
        "a std assumes the prior is the vessel and the noise is as stated; waves, current or a mis-logged τ do worse".into(),
    ];
    if let Some(e) = failed.first() {
        notes.push(format!(
            "{} of {n} realisations could not be identified and were left out (first: {e})",
            failed.len()
        ));
    }
    notes.extend(loops);
    if mirrored > 0 {
        notes.push(format!(
            "M is fitted symmetric: each of its {mirrored} off-diagonal pairs is one parameter, listed once as its upper entry M[i,j] = M[j,i]"
        ));
    }
    if fixed > 0 {
        notes.push(format!(
            "{fixed} matrix entries left out: the identification's structure fixes them (at zero or from M) in most realisations"
        ));
    }
    notes.extend(
        doc.structure_findings
            .iter()
            .map(|f| format!("on the simulated campaign: {f}")),
    );
    Ok(PrecisionPrediction::tabulate(
        method,
        source,
        plan.totals.total_time_s / 3600.0,
        runs,
        done.len(),
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

pub(super) fn run_input(
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
    let (mut record, _) = to_uniform(&parsed.table, None)
        .map_err(|err| DesignError::new(field(), format!("simulated log unreadable: {err}")))?;
    // As the service loads a run (turning azimuths split into components).
    crate::logs::read_thruster_commands(profile, &mut record);
    Ok(RunInput {
        run_id: e.code.clone(),
        name: e.code.clone(),
        family: Some(e.family),
        grid_speed_mps: e.grid_speed_mps,
        excited_dofs: e.dofs.clone(),
        record,
    })
}

/// (i, j) in DOF order of a matrix entry's symbol "X[dof_i,dof_j]".
fn matrix_entry(symbol: &str) -> Option<(usize, usize)> {
    let inner = symbol.split_once('[')?.1.strip_suffix(']')?;
    let (a, b) = inner.split_once(',')?;
    let idx = |n: &str| Dof::ALL.iter().position(|d| d.name() == n.trim());
    Some((idx(a)?, idx(b)?))
}

/// `row` is a lower entry M[j,i] (j > i) equal to M[i,j] at its grid speed
/// in every realisation: the same parameter as the upper entry.
fn mirrors_upper_entry(row: &ParameterRow, per: &[HashMap<RowKey, ParameterRow>]) -> bool {
    let Some((j, i)) = matrix_entry(&row.symbol) else {
        return false;
    };
    if row.group != "M" || j <= i {
        return false;
    }
    let upper = ParameterRow {
        symbol: format!("M[{},{}]", Dof::ALL[i].name(), Dof::ALL[j].name()),
        ..row.clone()
    };
    let (kl, ku) = (key(row), key(&upper));
    per.iter().all(|m| match (m.get(&kl), m.get(&ku)) {
        (Some(l), Some(u)) => {
            (l.value - u.value).abs() <= 1e-9 * l.value.abs().max(u.value.abs()).max(1e-300)
        }
        _ => false,
    })
}

/// Each row with the magnitude its std is measured against (module docs
/// of [`super`]).
fn scale_rows<'a>(profile: &VesselProfile, rows: &[&'a ParameterRow]) -> Vec<Scaled<'a>> {
    let entry = matrix_entry;
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
            Scaled {
                row: r,
                reference,
                reported_std: None,
            }
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

pub(super) fn cancelled() -> DesignError {
    DesignError::Cancelled
}
