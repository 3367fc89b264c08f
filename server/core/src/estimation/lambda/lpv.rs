//! LPV identification (thesis eq. 2.16–2.18): one λ-filter model per grid
//! point of forward speed, each from its own multi-experiment set.

use super::error::LambdaError;
use super::estimate::LambdaEstimate;
use super::experiment::Experiment;
use super::identify::identify_with_progress;
use super::settings::LambdaSettings;
use crate::estimation::{Cancelled, Progress};

/// Maps a grid point's progress into the whole and names the grid point.
struct GridProgress<'a> {
    parent: &'a mut dyn Progress,
    index: usize,
    count: usize,
    speed: f64,
}

impl Progress for GridProgress<'_> {
    fn update(&mut self, fraction: f64, stage: &str) -> Result<(), Cancelled> {
        let f = (self.index as f64 + fraction.clamp(0.0, 1.0)) / self.count as f64;
        let stage = format!(
            "grid point {}/{} ({:.2} m/s): {stage}",
            self.index + 1,
            self.count,
            self.speed
        );
        self.parent.update(f, &stage)
    }
}

/// Re-roots an error of one grid point's identification at `points[g]`.
fn at_point(e: LambdaError, g: usize) -> LambdaError {
    let prefix = |field: String| {
        if field.starts_with("runs") {
            format!("points[{g}].{field}")
        } else {
            field
        }
    };
    match e {
        LambdaError::Shape { field, message } => LambdaError::Shape {
            field: prefix(field),
            message,
        },
        LambdaError::NonFinite {
            field,
            index,
            message,
        } => LambdaError::NonFinite {
            field: prefix(field),
            index,
            message,
        },
        LambdaError::TooFewSamples { field, message } => LambdaError::TooFewSamples {
            field: prefix(field),
            message,
        },
        LambdaError::InvalidParameter { field, message } => LambdaError::InvalidParameter {
            field: prefix(field),
            message: format!("grid point {g}: {message}"),
        },
        LambdaError::Singular { field, message } => LambdaError::Singular {
            field: if field.starts_with("runs") {
                prefix(field)
            } else {
                format!("points[{g}].{field}")
            },
            message,
        },
        LambdaError::Cancelled => LambdaError::Cancelled,
    }
}

/// Identifies one model per grid point `(speed m/s, runs)`, in the given
/// order, with progress per grid point and DOF; cancellable between DOFs.
///
/// # Errors
/// `points` empty or a speed not finite (`points[g].speed`); otherwise the
/// first grid point's error from [`identify_with_progress`] with runs
/// fields re-rooted at `points[g].runs…`.
pub fn identify_lpv(
    points: &[(f64, Vec<Experiment>)],
    settings: &LambdaSettings,
    progress: &mut dyn Progress,
) -> Result<Vec<(f64, LambdaEstimate)>, LambdaError> {
    if points.is_empty() {
        return Err(LambdaError::too_few("points", "no grid point given"));
    }
    if let Some(g) = points.iter().position(|(u, _)| !u.is_finite()) {
        return Err(LambdaError::non_finite(
            format!("points[{g}].speed"),
            None,
            "grid speed must be finite",
        ));
    }
    let count = points.len();
    let mut out = Vec::with_capacity(count);
    for (g, (speed, runs)) in points.iter().enumerate() {
        let mut sub = GridProgress {
            parent: &mut *progress,
            index: g,
            count,
            speed: *speed,
        };
        let est = identify_with_progress(runs, settings, &mut sub).map_err(|e| at_point(e, g))?;
        out.push((*speed, est));
    }
    Ok(out)
}
