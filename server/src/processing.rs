//! Processing of an uploaded run, off the async runtime: parse and validate
//! the file(s), align two-file runs, resample, score data quality. The
//! numerics are all in seatrial-core; this module opens the stored files and
//! wires the steps together. The campaign's coverage by good runs is in
//! [`crate::coverage`].

use std::fs::File;
use std::io::BufReader;
use std::path::PathBuf;

use std::collections::BTreeMap;

use seatrial_core::alignment::{
    AlignmentReport, OffsetOptions, OffsetPriors, align_logs_with, check_user_offset,
};
use seatrial_core::identification::{InferredDescription, RunRole, RunSignal, infer_description};
use seatrial_core::logs::Gap;
use seatrial_core::logs::measurements::derive_body_velocities;
use seatrial_core::logs::{
    LogRole, ParseOptions, ParsedLog, input_columns, output_columns, parse_log, to_uniform,
};
use seatrial_core::planning::vessel::{HeadingUnit, InputChannels, VesselKind};
use seatrial_core::planning::{Dof, Schedule, VesselProfile};
use seatrial_core::quality::{Adherence, DofVerdict};
use seatrial_core::quality::{DofChannels, PlannedReference, QualitySpec, quality_report};
use seatrial_core::timeseries::UniformRecord;
use serde::{Deserialize, Serialize};
use serde_json::Value;

use crate::storage::plans::StoredExperiment;

/// Metadata of an upload (the `meta` part).
#[derive(Debug, Clone, Default, Deserialize, Serialize, utoipa::ToSchema)]
#[serde(deny_unknown_fields)]
pub struct RunMeta {
    /// The planned experiment this run flew.
    pub experiment_id: Option<String>,
    /// Name (default: the experiment's code, else the file name).
    pub name: Option<String>,
    /// The channel both computers recorded, for two-file runs (default `z`).
    pub shared_channel: Option<String>,
    /// Resampling rate (Hz); default the log's own rate (the lower of the two for two-file runs).
    pub rate_hz: Option<f64>,
    /// Clock offset of a two-file run set by hand (s, added to navigation
    /// time stamps to put them on the control clock; within ±86 400 s).
    /// It overrides the offset estimated from the shared channel; change or
    /// clear it later with `PUT /api/runs/{id}/clock-offset`.
    pub clock_offset_s: Option<f64>,
    /// What the run is for (default: the planned experiment's family, else inferred).
    pub role: Option<RunRole>,
    /// The grid speed it was flown at, m/s (or give `grid_speed_kn`; default: planned, else inferred).
    pub grid_speed_mps: Option<f64>,
    /// The grid speed it was flown at, kn (stored in m/s).
    pub grid_speed_kn: Option<f64>,
    /// The DOFs it excites, modelled by the vessel (default: planned, else inferred).
    pub excited_dofs: Option<Vec<Dof>>,
    /// Its excitation signal (default: planned, else inferred).
    pub signal: Option<RunSignal>,
    /// Free notes (at most 2000 characters).
    pub notes: Option<String>,
    /// Unit of the logged heading `psi` (default: the vessel profile's, else radians).
    pub heading_unit: Option<HeadingUnit>,
}

impl RunMeta {
    /// The options a stored run was read with, from its processing summary:
    /// the rate it was resampled to and the channel its two files were
    /// aligned on — so a later job reads the same record the report scored.
    pub fn of_stored(summary: Option<&Value>) -> RunMeta {
        let summary = summary.cloned().unwrap_or_default();
        RunMeta {
            shared_channel: summary
                .pointer("/alignment/shared_channel")
                .and_then(|v| v.as_str())
                .map(str::to_string),
            rate_hz: summary.get("sample_rate_hz").and_then(|v| v.as_f64()),
            heading_unit: summary
                .get("heading_unit")
                .and_then(|v| serde_json::from_value(v.clone()).ok()),
            ..RunMeta::default()
        }
    }
}

/// A warning about a run, with the file (or step) it concerns.
#[derive(Debug, Clone, Serialize, utoipa::ToSchema)]
pub struct RunWarning {
    /// `file`, `control`, `nav`, `alignment`, `quality`, `description` or
    /// `thrusters` (what thruster logs were read as).
    pub file: String,
    /// The column it concerns.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub column: Option<String>,
    /// What to know, in plain words.
    pub message: String,
    /// The doubt is about the log's units (milliseconds, degrees): its
    /// verdicts say "check units" until the log is fixed.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub units: bool,
}

/// What processing found: sizes, rates, gaps, warnings, alignment, verdicts.
#[derive(Debug, Clone, Default, Serialize, utoipa::ToSchema)]
pub struct RunSummary {
    /// Rate of the resampled record (Hz).
    pub sample_rate_hz: f64,
    /// Length of the record (s).
    pub duration_s: f64,
    /// Length of its valid (gap-free) part (s).
    pub valid_duration_s: f64,
    /// Data rows per file.
    pub rows: BTreeMap<String, usize>,
    /// Gaps per file (up to 5 missing samples bridged; longer ones split the run).
    pub gaps: BTreeMap<String, Vec<Gap>>,
    /// Columns kept but ignored, per file.
    pub ignored_columns: BTreeMap<String, Vec<String>>,
    /// Warnings in plain words.
    pub warnings: Vec<RunWarning>,
    /// Clock alignment of a two-file run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub alignment: Option<AlignmentReport>,
    /// Verdict per DOF, with reason and evidence.
    pub verdicts: Vec<DofVerdict>,
    /// How the run followed its planned schedule.
    pub adherence: Vec<Adherence>,
    /// Unit `psi` was read in.
    #[serde(default)]
    pub heading_unit: HeadingUnit,
    /// Channels of the record identification reads, derived ones included.
    #[serde(default)]
    pub channels: Vec<String>,
    /// Channels derived from others (a DP log's u, v, r from its pose).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub derived_channels: Vec<String>,
    /// Columns whose units look wrong (`t` in milliseconds, angles in
    /// degrees, rates in deg/s): the run is stored and accepted, but every
    /// verdict is `check_units` until a fixed log is uploaded.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub check_units: Vec<String>,
}

/// Why a run was rejected: which file, where, what.
#[derive(Debug, Clone, Serialize, utoipa::ToSchema)]

pub struct ProcessError {
    /// `file`, `control`, `nav` or `shared_channel`.
    pub file: String,
    /// Line in that file (header = 1).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub line: Option<u64>,
    /// Column name.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub column: Option<String>,
    /// What is wrong, in plain words.
    pub message: String,
}

impl ProcessError {
    fn new(file: &str, message: impl Into<String>) -> Self {
        ProcessError {
            file: file.into(),
            line: None,
            column: None,
            message: message.into(),
        }
    }
}

impl From<seatrial_core::logs::LogError> for ProcessError {
    fn from(e: seatrial_core::logs::LogError) -> Self {
        ProcessError {
            file: e.file.clone(),
            line: e.line,
            column: e.column.clone(),
            message: e.message.clone(),
        }
    }
}

/// The outcome of processing an accepted run.
pub struct Processed {
    /// Summary shown with the run.
    pub summary: Value,
    /// The quality report, serialized once.
    pub quality_json: String,
    /// What the data say the run is (none when too short to tell).
    pub inferred: Option<InferredDescription>,
}

impl Processed {
    /// What to record for an accepted run.
    pub fn outcome(&self) -> crate::storage::runs::Outcome<'_> {
        crate::storage::runs::Outcome {
            error: None,
            summary: Some(&self.summary),
            quality_json: Some(&self.quality_json),
            inferred: self.inferred.as_ref(),
        }
    }
}

/// Largest number of rows accepted per file.
pub const MAX_ROWS: usize = 50_000_000;

fn parse(
    vessel: &VesselProfile,
    path: &PathBuf,
    role: LogRole,
    file: &str,
    shared: Option<&str>,
    heading_unit: HeadingUnit,
) -> Result<ParsedLog, ProcessError> {
    let f = File::open(path)
        .map_err(|e| ProcessError::new(file, format!("stored file unreadable: {e}")))?;
    let opts = ParseOptions {
        file: file.to_string(),
        max_rows: MAX_ROWS,
        heading_unit,
        ..ParseOptions::for_vessel(vessel, role, shared)
    };
    Ok(parse_log(BufReader::with_capacity(1 << 20, f), &opts)?)
}

/// For thruster-actuated vessels the DOF's input is the normalized
/// generalized force τ_T = T·u (K = I): its direction is known from the
/// thruster configuration matrix even though the thrust coefficients are not.
fn add_thruster_forces(vessel: &VesselProfile, rec: &mut UniformRecord) {
    // Commanded inputs: thr_j, or a turning azimuth's two components.
    let inputs = seatrial_core::logs::commanded_inputs(vessel);
    for ((r, &d), name) in vessel
        .dofs
        .iter()
        .enumerate()
        .zip(thruster_force_columns(vessel))
    {
        debug_assert_eq!(name, format!("{}_T", d.force_column()));
        let mut acc = vec![0.0; rec.len()];
        for input in &inputs {
            if let Some(u) = rec.column(&input.column) {
                for (a, x) in acc.iter_mut().zip(u) {
                    *a += input.t[r] * x;
                }
            }
        }
        rec.names.push(name);
        rec.data.push(acc);
    }
}

/// Names of the derived τ_T = T·u columns (empty unless thruster-actuated).
pub fn thruster_force_columns(vessel: &VesselProfile) -> Vec<String> {
    match vessel.inputs {
        InputChannels::Thrusters { .. } => vessel
            .dofs
            .iter()
            .map(|d| format!("{}_T", d.force_column()))
            .collect(),
        _ => Vec::new(),
    }
}

/// The generalized force of each modelled DOF, in DOF order: the logged τ
/// column, or the derived τ_T = T·u of a thruster-actuated vessel. What the
/// quality report scores and the identification methods regress on.
pub fn generalized_force_columns(vessel: &VesselProfile) -> Vec<String> {
    let derived = thruster_force_columns(vessel);
    if derived.is_empty() {
        vessel
            .dofs
            .iter()
            .map(|d| d.force_column().to_string())
            .collect()
    } else {
        derived
    }
}

/// The log column a planned schedule column should be compared with.
fn logged_column(schedule_column: &str) -> String {
    match schedule_column.strip_suffix("_ref") {
        Some(sym) => sym.to_string(),
        None => schedule_column.to_string(),
    }
}

/// The request field an alignment error about a prior offset concerns.
fn prior_field(core_field: &str) -> &'static str {
    match core_field {
        "priors.user_run_s" => "meta.clock_offset_s",
        "priors.user_campaign_s" => "campaign.clock_offset_s",
        "priors.pooled" => "campaign.pooled_clock_offset",
        _ => "shared_channel",
    }
}

/// Parses, aligns (two-file runs) and resamples a stored run into one
/// uniform record; what was found (rows, gaps, warnings, alignment) goes into
/// `summary`. Two-file runs are merged with the offset chosen from `priors`
/// (set by hand for the run or campaign, the campaign's pooled offset) and
/// their own estimate, see [`seatrial_core::alignment::choose_offset`];
/// `priors.user_run_s` is the run's hand-set offset (at upload,
/// `meta.clock_offset_s`). Identification jobs load accepted runs through
/// this too, so the record they fit is the one the quality report scored
/// (unless the campaign's offsets changed since: jobs use the current ones).
pub fn load_record(
    vessel: &VesselProfile,
    files: &[(String, PathBuf)],
    meta: &RunMeta,
    priors: &OffsetPriors,
    summary: &mut RunSummary,
) -> Result<UniformRecord, ProcessError> {
    if let Some(v) = priors.user_run_s {
        check_user_offset("meta.clock_offset_s", v)
            .map_err(|e| ProcessError::new("meta.clock_offset_s", e.message()))?;
    }
    if let Some(r) = meta.rate_hz {
        seatrial_core::logs::check_rate_hz(r).map_err(|m| ProcessError::new("meta.rate_hz", m))?;
    }
    let path = |role: &str| files.iter().find(|(r, _)| r == role).map(|(_, p)| p);
    let note = |file: &str, p: &ParsedLog, summary: &mut RunSummary| {
        summary
            .warnings
            .extend(p.warnings.iter().map(|w| RunWarning {
                file: file.into(),
                column: w.column.clone(),
                message: w.message.clone(),
                units: w.units,
            }));
        summary.rows.insert(file.into(), p.rows);
        summary.gaps.insert(file.into(), p.gaps.clone());
        summary
            .ignored_columns
            .insert(file.into(), p.ignored_columns.clone());
    };
    let unit = meta
        .heading_unit
        .or(vessel.heading_unit)
        .unwrap_or_default();
    summary.heading_unit = unit;
    let mut rec = if let Some(p) = path("file") {
        let parsed = parse(vessel, p, LogRole::Single, "file", None, unit)?;
        let (rec, _) = to_uniform(&parsed.table, meta.rate_hz)?;
        note("file", &parsed, summary);
        rec
    } else {
        let shared = meta.shared_channel.as_deref().unwrap_or("z");
        let (Some(cp), Some(np)) = (path("control"), path("nav")) else {
            return Err(ProcessError::new(
                "file",
                "a run needs 'file', or 'control' and 'nav'",
            ));
        };
        let control = parse(vessel, cp, LogRole::Control, "control", Some(shared), unit)?;
        let nav = parse(vessel, np, LogRole::Nav, "nav", Some(shared), unit)?;
        note("control", &control, summary);
        note("nav", &nav, summary);
        let (rec, report) = align_logs_with(
            &control.table,
            &nav.table,
            shared,
            meta.rate_hz,
            &OffsetOptions::default(),
            priors,
        )
        .map_err(|e| {
            let field = prior_field(e.field());
            if field == "shared_channel" {
                ProcessError::new(field, e.to_string())
            } else {
                ProcessError::new(field, e.message())
            }
        })?;
        summary
            .warnings
            .extend(report.warnings.iter().map(|w| RunWarning {
                file: "alignment".into(),
                column: None,
                message: w.clone(),
                units: false,
            }));
        summary.alignment = Some(report);
        rec
    };
    let thrusters = seatrial_core::logs::read_thruster_commands(vessel, &mut rec);
    summary
        .warnings
        .extend(thrusters.note.map(|message| RunWarning {
            file: "thrusters".into(),
            column: None,
            message,
            units: false,
        }));
    summary.warnings.extend(
        thrusters
            .warnings
            .into_iter()
            .map(|(column, message)| RunWarning {
                file: "thrusters".into(),
                column: Some(column),
                message,
                units: true,
            }),
    );
    add_thruster_forces(vessel, &mut rec);
    velocities_from_pose(vessel, &mut rec, summary);
    summary.channels = rec.names.clone();
    Ok(rec)
}

/// A DP log without body velocities: u, v, r derived from its pose for the
/// quality report and the run description (see
/// [`seatrial_core::logs::measurements`]), over ± a quarter of the
/// shortest time constant of the profile (at least one sample), and said so.
fn velocities_from_pose(vessel: &VesselProfile, rec: &mut UniformRecord, summary: &mut RunSummary) {
    let velocities = output_columns(vessel);
    if vessel.kind != VesselKind::Dp3 || velocities.iter().any(|c| rec.column(c).is_some()) {
        return;
    }
    let half = vessel
        .dofs
        .iter()
        .map(|&d| vessel.limit(d).time_constant_s / 4.0)
        .fold(f64::INFINITY, f64::min);
    if derive_body_velocities(rec, half).is_ok() {
        summary.warnings.push(RunWarning {
            file: "file".into(),
            column: None,
            message: format!(
                "{} are not logged: derived from x, y, psi (local linear fit over ±{} s, rotated \
                 into the body frame) for the quality report and the run description; \
                 parallel_ekf identifies from the logged pose",
                velocities.join(", "),
                seatrial_core::numbers::sig3(half.max(1.0 / rec.sample_rate_hz))
            ),
            units: false,
        });
        summary.derived_channels = velocities;
    }
}

/// Parses, aligns (with `priors`, see [`load_record`]), resamples and
/// scores a run, and infers what it is from its data (role, grid speed on
/// the campaign's `grid`, excited DOFs, signal).
pub fn process_run(
    vessel: &VesselProfile,
    files: &[(String, PathBuf)],
    meta: &RunMeta,
    priors: &OffsetPriors,
    planned: Option<&(StoredExperiment, Schedule)>,
    grid: &[f64],
) -> Result<Processed, ProcessError> {
    let mut summary = RunSummary::default();
    let rec = load_record(vessel, files, meta, priors, &mut summary)?;
    let inferred = infer_description(&rec, vessel, &generalized_force_columns(vessel), grid)
        .map_err(|e| {
            summary.warnings.push(RunWarning {
                file: "description".into(),
                column: None,
                message: format!("nothing inferred about what the run is: {e}"),
                units: false,
            })
        })
        .ok();
    let dofs: Vec<DofChannels> = vessel
        .dofs
        .iter()
        .zip(generalized_force_columns(vessel))
        .map(|(&d, input)| DofChannels {
            dof: d,
            input,
            output: d.velocity_symbol().to_string(),
        })
        .collect();
    // A thruster-actuated vessel's DOFs are scored on the derived τ_T = T·u,
    // so those columns are inputs of the report too.
    let mut inputs = input_columns(vessel);
    inputs.extend(thruster_force_columns(vessel));
    let outputs = output_columns(vessel);
    let planned_ref = planned.map(|(e, s)| PlannedReference {
        sample_rate_hz: s.sample_rate_hz,
        columns: e
            .experiment
            .channels
            .iter()
            .zip(&s.values)
            .filter(|(c, _)| c.excited)
            .map(|(c, v)| (logged_column(&c.column), c.column.clone(), v.clone()))
            .collect(),
    });
    let spec = QualitySpec {
        dofs,
        inputs,
        outputs,
        nperseg: None,
        controller_rate_hz: Some(vessel.controller_rate_hz),
        // The identified model is first order in ν (ν̇ = Aν + Bτ, thesis eq. 2.10):
        // one lag per channel. Two lags on first-order data are collinear by
        // construction (y(t−1) = a·y(t−2) + b·x(t−2)) and would flag every DOF.
        regressor_lags: 1,
        planned: planned_ref,
    };
    let report =
        quality_report(&rec, &spec).map_err(|e| ProcessError::new("file", e.to_string()))?;
    let quality_json =
        serde_json::to_string(&report).map_err(|e| ProcessError::new("file", e.to_string()))?;
    summary
        .warnings
        .extend(report.warnings.iter().map(|m| RunWarning {
            file: "quality".into(),
            column: None,
            message: m.clone(),
            units: false,
        }));
    summary.sample_rate_hz = rec.sample_rate_hz;
    summary.duration_s = rec.len() as f64 / rec.sample_rate_hz;
    summary.valid_duration_s = rec.valid_duration_s();
    summary.verdicts = report.dofs;
    let doubts: Vec<&str> = summary
        .warnings
        .iter()
        .filter(|w| w.units)
        .map(|w| w.message.as_str())
        .collect();
    seatrial_core::quality::units_first(&mut summary.verdicts, &doubts);
    summary.check_units = summary
        .warnings
        .iter()
        .filter(|w| w.units)
        .filter_map(|w| w.column.clone())
        .collect();
    summary.adherence = report.adherence;
    let summary =
        serde_json::to_value(&summary).map_err(|e| ProcessError::new("file", e.to_string()))?;
    Ok(Processed {
        summary,
        quality_json,
        inferred,
    })
}
