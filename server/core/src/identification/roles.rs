//! Which run does what: static runs give the restoring forces, validation
//! runs are held out, the rest estimate the dynamics at their grid point.

use super::dataset::RunInput;
use super::error::IdentifyError;
use crate::planning::campaign::ExperimentFamily;

/// The runs of an identification, by role.
#[derive(Debug, Default)]
pub struct Roles<'a> {
    /// Static runs (restoring forces and tether moment).
    pub statics: Vec<&'a RunInput>,
    /// Runs the dynamics are estimated from.
    pub estimation: Vec<&'a RunInput>,
    /// Runs held out for validation.
    pub validation: Vec<&'a RunInput>,
}

/// Splits `runs`: the ids in `validation_run_ids` (or, when none are given,
/// the runs whose family is validation) are held out; static runs go to
/// restoring; everything else is estimation data. A run's family is its role
/// as the supervisor described it, else its planned experiment's family,
/// else the role inferred from its data ([`RunInput::family`]): a static or
/// validation role from metadata counts exactly like the plan's. A
/// validation run is required — a model is only stored with a test on data
/// it was not fitted to.
pub fn assign_roles<'a>(
    runs: &'a [RunInput],
    validation_run_ids: Option<&[String]>,
) -> Result<Roles<'a>, IdentifyError> {
    if let Some(ids) = validation_run_ids {
        for id in ids {
            if !runs.iter().any(|r| &r.run_id == id) {
                return Err(IdentifyError::invalid(
                    "settings.validation_run_ids",
                    format!("run '{id}' is not among the job's runs"),
                ));
            }
        }
    }
    let mut roles = Roles::default();
    for r in runs {
        if held_out(&r.run_id, r.family, validation_run_ids) {
            roles.validation.push(r);
        } else if r.family == Some(ExperimentFamily::Static) {
            roles.statics.push(r);
        } else {
            roles.estimation.push(r);
        }
    }
    if roles.validation.is_empty() {
        return Err(no_validation_run());
    }
    if roles.estimation.is_empty() {
        return Err(IdentifyError::invalid(
            "run_ids",
            "no estimation run left once validation and static runs are set aside",
        ));
    }
    Ok(roles)
}

/// The error of a job without a held-out run.
pub fn no_validation_run() -> IdentifyError {
    IdentifyError::invalid(
        "settings.validation_run_ids",
        "no validation run: fly the plan's validation experiment, set a run's role to validation (PATCH /api/runs/{id}), or name held-out runs in settings.validation_run_ids",
    )
}

/// Whether a run is held out: named in `validation_run_ids` when given,
/// else its family is validation.
pub fn held_out(
    run_id: &str,
    family: Option<ExperimentFamily>,
    validation_run_ids: Option<&[String]>,
) -> bool {
    match validation_run_ids {
        Some(ids) => ids.iter().any(|i| i == run_id),
        None => family == Some(ExperimentFamily::Validation),
    }
}

/// Index of the grid speed nearest `speed`.
pub fn nearest_grid_index(grid: &[f64], speed: f64) -> usize {
    grid.iter()
        .enumerate()
        .min_by(|a, b| (a.1 - speed).abs().total_cmp(&(b.1 - speed).abs()))
        .map_or(0, |(i, _)| i)
}

/// Shares of the forward speeds `u` (m/s, non-finite samples ignored)
/// below and above the grid by more than a tenth of the end spacing (a
/// tenth of the speed for a one-point grid): there an LPV model holds its
/// end sub-model (thesis eq. 2.18), and the speed-dependent part of its
/// damping and Coriolis linearization is frozen.
pub fn beyond_grid(u: &[f64], grid: &[f64]) -> (f64, f64) {
    let (Some(&lo), Some(&hi)) = (grid.first(), grid.last()) else {
        return (0.0, 0.0);
    };
    let margin = |a: f64, b: f64| {
        0.1 * if grid.len() > 1 {
            (a - b).abs()
        } else {
            a.abs()
        }
    };
    let (below_by, above_by) = match grid.len() {
        1 => (margin(lo, lo), margin(hi, hi)),
        n => (margin(grid[1], lo), margin(hi, grid[n - 2])),
    };
    shares_outside(u, lo - below_by, hi + above_by)
}

/// Shares of the forward speeds `u` (non-finite samples ignored) below
/// `lo` and above `hi`; (0, 0) without a finite sample.
pub fn shares_outside(u: &[f64], lo: f64, hi: f64) -> (f64, f64) {
    let finite = u.iter().filter(|v| v.is_finite()).count();
    if finite == 0 {
        return (0.0, 0.0);
    }
    let share = |f: &dyn Fn(f64) -> bool| {
        u.iter().filter(|v| v.is_finite() && f(**v)).count() as f64 / finite as f64
    };
    (share(&|v| v < lo), share(&|v| v > hi))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::timeseries::UniformRecord;

    fn run(id: &str, family: Option<ExperimentFamily>) -> RunInput {
        RunInput {
            run_id: id.into(),
            name: id.into(),
            family,
            grid_speed_mps: None,
            excited_dofs: vec![],
            record: UniformRecord {
                sample_rate_hz: 10.0,
                t0: 0.0,
                names: vec![],
                data: vec![],
                valid: vec![],
            },
        }
    }

    #[test]
    fn roles_follow_the_plan_or_the_settings() {
        use ExperimentFamily::*;
        let runs = vec![
            run("s", Some(Static)),
            run("d", Some(Dynamic)),
            run("v", Some(Validation)),
            run("x", None),
        ];
        let r = assign_roles(&runs, None).unwrap();
        assert_eq!(r.statics.len(), 1);
        assert_eq!(r.validation[0].run_id, "v");
        assert_eq!(
            r.estimation
                .iter()
                .map(|r| r.run_id.as_str())
                .collect::<Vec<_>>(),
            ["d", "x"]
        );
        let r = assign_roles(&runs, Some(&["x".to_string()])).unwrap();
        assert_eq!(r.validation[0].run_id, "x");
        assert_eq!(r.estimation.len(), 2);
        let e = assign_roles(&runs, Some(&["nope".to_string()])).unwrap_err();
        assert_eq!(e.field(), "settings.validation_run_ids");
        let e = assign_roles(&runs[..2], None).unwrap_err();
        assert!(e.to_string().contains("no validation run"));
    }

    #[test]
    fn a_role_from_the_supervisor_counts_like_the_plans_family() {
        use crate::identification::description::{RunRole, UserDescription, describe_run};
        let said = |role| {
            let user = UserDescription {
                role: Some(role),
                ..UserDescription::default()
            };
            describe_run(&user, None, None).family
        };
        let runs = vec![
            run("s", said(RunRole::Static)),
            run("d", said(RunRole::Dynamic)),
            run("v", said(RunRole::Validation)),
        ];
        let r = assign_roles(&runs, None).unwrap();
        assert_eq!(r.statics[0].run_id, "s");
        assert_eq!(r.estimation[0].run_id, "d");
        assert_eq!(r.validation[0].run_id, "v");
    }

    #[test]
    fn nearest_grid_point() {
        let g = [0.25, 0.5, 1.0];
        assert_eq!(nearest_grid_index(&g, 0.0), 0);
        assert_eq!(nearest_grid_index(&g, 0.8), 2);
        assert_eq!(nearest_grid_index(&g, 0.6), 1);
    }

    #[test]
    fn speeds_beyond_the_grid_are_counted_past_a_tenth_of_the_end_spacing() {
        let grid = [0.5, 1.0, 1.5, 2.0];
        let u = [0.3, 0.46, 0.5, 1.2, 2.04, 2.06, 2.25, f64::NAN];
        let (below, above) = beyond_grid(&u, &grid);
        assert!((below - 1.0 / 7.0).abs() < 1e-12, "{below}");
        assert!((above - 2.0 / 7.0).abs() < 1e-12, "{above}");
        assert_eq!(beyond_grid(&[1.0, 1.05], &[1.0]), (0.0, 0.0));
        assert_eq!(beyond_grid(&[0.8, 1.2], &[1.0]), (0.5, 0.5));
        assert_eq!(beyond_grid(&[], &grid), (0.0, 0.0));
    }
}
