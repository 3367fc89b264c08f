//! The λ model on its held-out runs, and whether it carries C(δ)δ.

use super::attitude_loop::AttitudeLoop;
use super::dataset::{RunInput, segments};
use super::discover_gate::advantage;
use super::error::IdentifyError;
use super::heading_loop::HeadingLoop;
use super::lambda_data::experiment;
use super::lambda_extension::speed_coverage_notes;
use super::outcome::RunValidation;
use super::through_water::speed_through_water;
use crate::estimation::restoring::RestoringParams;
use crate::models::LpvModel;
use crate::numbers::sig3;
use crate::planning::dof::Dof;
use crate::validation::{ValidationRecord, ValidationSettings, validate};
use nalgebra::DMatrix;

/// How much better (summed free-run fit) the linear model must be on the
/// held-out runs for C(δ)δ to be left out: round-off and the noise of a
/// fit, not a preference for the thesis's linear model.
const SECOND_ORDER_MARGIN: f64 = 0.01;

/// The held-out runs and how a model is validated on them.
pub(crate) struct HeldOut<'a> {
    pub runs: &'a [&'a RunInput],
    /// Regression columns: forces in DOF order, then the pose when g(η)
    /// is estimated.
    pub cols: &'a [String],
    pub outputs: &'a [String],
    /// Modelled DOFs.
    pub n: usize,
    /// The regression column of the heading ψ (read with a current).
    pub psi_col: usize,
    /// g(η), when estimated: validated with the attitude in the loop.
    pub restoring: Option<&'a RestoringParams>,
    /// A current fixed in NED, V = [V_N, V_E] (m/s): validated with the
    /// heading in the loop.
    pub current: Option<nalgebra::Vector2<f64>>,
    pub settings: &'a ValidationSettings,
}

impl HeldOut<'_> {
    /// Notes on where each held-out run's forward speed (output column
    /// `surge`, its longest valid block) leaves `lpv`'s grid speeds and
    /// extension: in a current, its speed through the water
    /// u_r = u − u_c(ψ), which the model is scheduled on.
    pub fn speed_coverage(&self, surge: usize, lpv: &LpvModel) -> Vec<String> {
        let grid = lpv.grid_speeds();
        let mut notes = Vec::new();
        for r in self.runs {
            if let Ok(segs) = segments(r, self.cols, self.outputs, 50)
                && let Some(longest) = segs.iter().max_by_key(|s| s.y.nrows())
            {
                let v = self.current;
                let u = speed_through_water(longest, surge, self.psi_col, v);
                notes.extend(speed_coverage_notes(&r.name, &u, grid, lpv.extension()));
            }
        }
        notes
    }

    /// Each held-out run's longest valid block validated with `lpv`: with
    /// g(η) of the simulated attitude in the loop when g(η) is estimated,
    /// on γ = τ − g(η) otherwise.
    pub fn validate(&self, lpv: &LpvModel) -> Result<Vec<RunValidation>, IdentifyError> {
        let (n, g) = (self.n, self.restoring);
        let attitude_loop = g.and_then(|g| match self.current {
            Some(v) => AttitudeLoop::with_current(lpv.clone(), *g, v),
            None => AttitudeLoop::new(lpv.clone(), *g),
        });
        let loop_settings = ValidationSettings {
            input_names: AttitudeLoop::input_names(&self.cols[..n]),
            ..self.settings.clone()
        };
        let heading_loop = self.current.and_then(|v| HeadingLoop::new(lpv.clone(), v));
        let heading_settings = ValidationSettings {
            input_names: HeadingLoop::input_names(&self.cols[..n]),
            ..self.settings.clone()
        };
        let mut validation = Vec::new();
        for r in self.runs {
            let segs = segments(r, self.cols, self.outputs, 50).map_err(|e| {
                IdentifyError::invalid(format!("runs[{}]", e.run_id), e.to_string())
            })?;
            let longest = segs
                .iter()
                .max_by_key(|s| s.y.nrows())
                .expect("segments is non-empty");
            let report = match (&attitude_loop, &heading_loop) {
                // The current's force of the simulated heading: [τ | ψ].
                (None, Some(model)) => validate(
                    model,
                    &ValidationRecord {
                        h: longest.h,
                        u: &DMatrix::from_fn(longest.u.nrows(), n + 1, |k, j| {
                            longest.u[(k, if j < n { j } else { self.psi_col })]
                        }),
                        y: &longest.y,
                    },
                    &heading_settings,
                ),
                // g(η) of the simulated attitude in the loop (and the
                // current's force of the simulated heading): record [τ | η].
                (Some(model), _) => validate(
                    model,
                    &ValidationRecord {
                        h: longest.h,
                        u: &longest.u.columns(0, 12).into_owned(),
                        y: &longest.y,
                    },
                    &loop_settings,
                ),
                (None, None) => {
                    let e = experiment(longest, n, g, None)?;
                    let rec = ValidationRecord {
                        h: longest.h,
                        u: &e.gamma,
                        y: &e.nu,
                    };
                    validate(lpv, &rec, self.settings)
                }
            }
            .map_err(|e| IdentifyError::invalid(format!("runs[{}]", r.run_id), e.to_string()))?;
            validation.push(RunValidation {
                run_id: r.run_id.clone(),
                run_name: r.name.clone(),
                report,
            });
        }
        Ok(validation)
    }
}

/// C(δ)δ rests on M: an M the data determine poorly can make it cost more
/// than it explains. With `second_order`, `lpv` (validated as
/// `validation`) keeps it only if the held-out free runs, summed over runs
/// and channels, are no worse with it than without; the note says which
/// and by how much. Where M holds a mass at its prior (`prior_masses`:
/// DOFs no run forced, such as an underactuated USV's sway), C(δ)δ acts
/// through a number the data never saw, and it must earn its place:
/// better by more than [`SECOND_ORDER_MARGIN`] (independent truth, the
/// Otter in a 0.29 m/s current flown at two turn amplitudes: kept at
/// −0.010, the free run fell 0.23 short of the true model's; left out and
/// refitted, 0.048). Returns the model, its validation and whether it
/// carries the term.
pub(crate) fn choose_second_order(
    lpv: LpvModel,
    validation: Vec<RunValidation>,
    second_order: bool,
    prior_masses: &[Dof],
    validate_with: &dyn Fn(&LpvModel) -> Result<Vec<RunValidation>, IdentifyError>,
    notes: &mut Vec<String>,
) -> Result<(LpvModel, Vec<RunValidation>, bool), IdentifyError> {
    if !second_order || validation.is_empty() {
        return Ok((lpv, validation, second_order));
    }
    let linear = lpv.clone().without_second_order_coriolis();
    let without = validate_with(&linear)?;
    let (with_fit, without_fit) = (free_run_total(&validation), free_run_total(&without));
    if without_fit > with_fit + SECOND_ORDER_MARGIN {
        notes.push(format!(
            "the second-order Coriolis–centripetal force C(δ)δ of the estimated M was left out: on the held-out runs it made the free runs worse (fit summed over runs and channels {with_fit:.3} with it, {without_fit:.3} without)"
        ));
        return Ok((linear, without, false));
    }
    if !prior_masses.is_empty() && with_fit <= without_fit + SECOND_ORDER_MARGIN {
        let masses: Vec<&str> = prior_masses.iter().map(|d| d.name()).collect();
        notes.push(format!(
            "the second-order Coriolis–centripetal force C(δ)δ was left out: it acts through M's {} mass, which no run forced and which is the profile's prior, so it is kept only where it improves the held-out free runs by more than {SECOND_ORDER_MARGIN}, and it did not (fit summed over runs and channels {with_fit:.3} with it, {without_fit:.3} without)",
            masses.join(" and ")
        ));
        return Ok((linear, without, false));
    }
    notes.push(format!(
        "the model carries the second-order Coriolis–centripetal force C(δ)δ of one vehicle M, its grid points' M pooled by inverse variance (δ = ν about straight-ahead motion at the scheduled speed: the centripetal forces of turning, heaving and rolling that the linear sub-models cannot hold; no parameter added); held-out free-run fit summed over runs and channels {with_fit:.3} with it, {without_fit:.3} without"
    ));
    Ok((lpv, validation, true))
}

/// A current the data hold beyond their noise is kept only if it makes the
/// held-out fits better (`with` against `without` it: 1-step, k-step,
/// 10 s restarted and whole-run free run, each clamped to [−1, 1], summed
/// over runs and channels) by more than round-off: a heading-correlated
/// remainder of physics the model lacks can pass the χ² test and still
/// predict nothing. Not the whole-run free run alone: its heading is
/// integrated from the model's own yaw rate, so over a long run a small
/// yaw error turns the current's force the wrong way however right the
/// current is. The note says which and by how much.
pub(crate) fn keep_current(
    with: &[RunValidation],
    without: &[RunValidation],
    notes: &mut Vec<String>,
) -> bool {
    let (gain, fits) = advantage(with, without);
    let (with_fit, without_fit) = (free_run_total(with), free_run_total(without));
    let keep = gain > SECOND_ORDER_MARGIN;
    let sums = format!(
        "its held-out fits (1-step, k-step, 10 s restarted and whole-run free run, each clamped to [−1, 1]) sum {} {} over {fits} fits; the whole-run free runs alone sum {with_fit:.3} with it, {without_fit:.3} without",
        sig3(gain.abs()),
        if gain >= 0.0 { "higher" } else { "lower" }
    );
    notes.push(if keep {
        format!("the current improves the held-out runs: {sums}")
    } else {
        format!("the current was left out: it did not improve the held-out runs ({sums}), so the model names none")
    });
    keep
}

/// Free-run NRMSE fit summed over runs and channels; a channel without a
/// fit (diverged, constant output) counts −1, and none counts below −1.
pub(crate) fn free_run_total(validation: &[RunValidation]) -> f64 {
    validation
        .iter()
        .flat_map(|r| &r.report.channels)
        .map(|c| {
            c.fit_simulation
                .filter(|f| f.is_finite())
                .unwrap_or(-1.0)
                .max(-1.0)
        })
        .sum()
}
