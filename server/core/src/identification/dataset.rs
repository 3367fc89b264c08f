//! From stored runs to estimation data: each run's valid blocks become
//! segments (N × channels matrices, one row per sample), each with its own
//! initial state — runs and gap-separated blocks are never concatenated.

use std::borrow::Cow;

use nalgebra::DMatrix;

use crate::logs::schema::pose_column;
use crate::planning::Dof;
use crate::planning::campaign::ExperimentFamily;
use crate::timeseries::UniformRecord;

/// A run as identification sees it: its record and what it is — from the
/// supervisor's description, else its planned experiment, else inferred
/// from its data (see [`super::description::describe_run`]).
#[derive(Debug, Clone)]
pub struct RunInput {
    /// Run id (for provenance and messages).
    pub run_id: String,
    /// Run name (the experiment code when planned).
    pub name: String,
    /// The family the run counts as: its role (static, dynamic, recursive,
    /// validation) as an experiment family, or the planned / inferred DP
    /// manoeuvre. `None`: unknown, used as estimation data.
    pub family: Option<ExperimentFamily>,
    /// The LPV grid speed it was flown at (m/s).
    pub grid_speed_mps: Option<f64>,
    /// The DOFs it excites (empty: not known).
    pub excited_dofs: Vec<Dof>,
    /// The resampled record (inputs, ν, η; τ_T for thruster-actuated vessels).
    pub record: UniformRecord,
}

/// One contiguous block of valid samples of a run.
#[derive(Debug, Clone)]
pub struct Segment {
    /// Run id.
    pub run_id: String,
    /// Sample time h (s).
    pub h: f64,
    /// Time of the first sample (s, record clock).
    pub t0: f64,
    /// Inputs, N × m.
    pub u: DMatrix<f64>,
    /// Outputs, N × p.
    pub y: DMatrix<f64>,
}

/// Why a run cannot be used.
#[derive(Debug, Clone, PartialEq)]
pub struct DatasetError {
    /// The run.
    pub run_id: String,
    /// The column, when one is at fault.
    pub column: Option<String>,
    /// What is wrong.
    pub message: String,
}

impl std::fmt::Display for DatasetError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "run {}", self.run_id)?;
        if let Some(c) = &self.column {
            write!(f, ", column '{c}'")?;
        }
        write!(f, ": {}", self.message)
    }
}

impl std::error::Error for DatasetError {}

fn gather(
    run: &RunInput,
    names: &[String],
    range: &std::ops::Range<usize>,
) -> Result<DMatrix<f64>, DatasetError> {
    let n = range.len();
    let mut m = DMatrix::zeros(n, names.len());
    for (j, name) in names.iter().enumerate() {
        let col = run.record.column(name).ok_or_else(|| DatasetError {
            run_id: run.run_id.clone(),
            column: Some(name.clone()),
            message: "the record has no such column".into(),
        })?;
        for (i, k) in range.clone().enumerate() {
            let v = col[k];
            if !v.is_finite() {
                return Err(DatasetError {
                    run_id: run.run_id.clone(),
                    column: Some(name.clone()),
                    message: format!("non-finite value at sample {k}"),
                });
            }
            m[(i, j)] = v;
        }
    }
    Ok(m)
}

/// A horizontal (surge, sway, yaw) model's η is (x, y, 0, 0, 0, ψ): a
/// surface vessel's log need not carry z, φ, θ. The run with those columns
/// added as zeros where it lacks them; borrowed unchanged when nothing is
/// missing or the model has other DOFs (whose η must be logged).
pub fn level_attitude<'a>(run: &'a RunInput, dofs: &[Dof]) -> Cow<'a, RunInput> {
    if !dofs.iter().all(|d| Dof::HORIZONTAL.contains(d)) {
        return Cow::Borrowed(run);
    }
    let missing: Vec<&str> = [Dof::Heave, Dof::Roll, Dof::Pitch]
        .iter()
        .map(|d| pose_column(*d))
        .filter(|c| run.record.column(c).is_none())
        .collect();
    if missing.is_empty() {
        return Cow::Borrowed(run);
    }
    let mut run = run.clone();
    let n = run.record.len();
    for c in missing {
        run.record.names.push(c.to_string());
        run.record.data.push(vec![0.0; n]);
    }
    Cow::Owned(run)
}

/// The valid blocks of `run` at least `min_samples` long, with the given
/// input and output columns. Shorter blocks are skipped (too short to carry
/// information about the dynamics); none left is an error naming the run.
pub fn segments(
    run: &RunInput,
    inputs: &[String],
    outputs: &[String],
    min_samples: usize,
) -> Result<Vec<Segment>, DatasetError> {
    let fs = run.record.sample_rate_hz;
    if !(fs.is_finite() && fs > 0.0) {
        return Err(DatasetError {
            run_id: run.run_id.clone(),
            column: None,
            message: format!("sample rate must be positive, got {fs} Hz"),
        });
    }
    let h = 1.0 / fs;
    let mut out = Vec::new();
    for block in &run.record.valid {
        if block.len() < min_samples {
            continue;
        }
        out.push(Segment {
            run_id: run.run_id.clone(),
            h,
            t0: run.record.t0 + block.start as f64 * h,
            u: gather(run, inputs, block)?,
            y: gather(run, outputs, block)?,
        });
    }
    if out.is_empty() {
        return Err(DatasetError {
            run_id: run.run_id.clone(),
            column: None,
            message: format!(
                "no valid block of at least {min_samples} samples ({:.0} s); the longest is {} samples",
                min_samples as f64 * h,
                run.record.valid.iter().map(|b| b.len()).max().unwrap_or(0)
            ),
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(valid: Vec<std::ops::Range<usize>>) -> RunInput {
        let n = 100;
        RunInput {
            run_id: "r1".into(),
            name: "test".into(),
            family: None,
            grid_speed_mps: None,
            excited_dofs: vec![],
            record: UniformRecord {
                sample_rate_hz: 10.0,
                t0: 5.0,
                names: vec!["tau_X".into(), "u".into()],
                data: vec![
                    (0..n).map(|k| k as f64).collect(),
                    (0..n).map(|k| -(k as f64)).collect(),
                ],
                valid,
            },
        }
    }

    #[test]
    fn blocks_become_separate_segments_and_short_ones_are_skipped() {
        let r = run(vec![0..40, 45..50, 60..100]);
        let segs = segments(&r, &["tau_X".into()], &["u".into()], 10).unwrap();
        assert_eq!(segs.len(), 2);
        assert_eq!(segs[0].u.nrows(), 40);
        assert_eq!(segs[1].u[(0, 0)], 60.0);
        assert_eq!(segs[1].y[(39, 0)], -99.0);
        assert!((segs[1].t0 - 11.0).abs() < 1e-12);
        assert!((segs[0].h - 0.1).abs() < 1e-15);
    }

    #[test]
    fn missing_columns_nan_and_short_runs_name_the_problem() {
        let r = run(std::iter::once(0..100).collect());
        let e = segments(&r, &["tau_Y".into()], &["u".into()], 10).unwrap_err();
        assert_eq!(e.column.as_deref(), Some("tau_Y"));
        let mut bad = run(std::iter::once(0..100).collect());
        bad.record.data[1][7] = f64::NAN;
        let e = segments(&bad, &["tau_X".into()], &["u".into()], 10).unwrap_err();
        assert!(e.to_string().contains("sample 7"), "{e}");
        let e = segments(
            &run(std::iter::once(0..5).collect()),
            &["tau_X".into()],
            &["u".into()],
            10,
        )
        .unwrap_err();
        assert!(e.to_string().contains("longest is 5"), "{e}");
    }
}
