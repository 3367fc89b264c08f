//! The vessel's autopilot inferred from flown runs: each planned run's
//! references (its schedule) against the logged commanded τ and the
//! measured ν, η the autopilot read, one least-squares fit per DOF.
//!
//! Per DOF the law of [`crate::planning::Autopilot`] is fitted in first
//! differences between consecutive logged samples k−1, k:
//!
//! - velocity loops (u, v, w, r): Δτ = K_p Δe + K_i ∫e dt + (W − B)·Δĝ₁(η),
//!   e = ν_ref − ν;
//! - attitude loops (φ, θ): Δτ = K_p Δe_η + K_d Δe_ω + K_i ∫e_η dt +
//!   (z_G W − z_B B)·Δĝ₂(η), e_η = η_ref − η, e_ω = ω_ref − ω, where a rate
//!   schedule gives ω_ref and η_ref = ∫ω_ref dt from the run's start;
//!
//! with ĝ₁, ĝ₂ the shapes of the lumped g(η) (thesis eq. 4.6) and ∫e over
//! the interval by the trapezoid. Differencing removes what the runs do not
//! share — the integrators' trim at the start of each run — and leaves τ,
//! which the log records exactly as commanded, on the left. Samples where a
//! command sits at the profile's force limit (saturated, the law not in
//! force) and runs that drive the DOF open loop are left out.
//!
//! The log must be the one the autopilot read (the single log of the
//! controller's computer): with independent sensor noise on the logged ν
//! the gains come out biased low.

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

use super::dataset::RunInput;
use crate::logs::schema::pose_column;
use crate::planning::VesselProfile;
use crate::planning::statics::attitude_column;
use crate::planning::vessel::VesselKind;
use crate::planning::{Autopilot, AutopilotLoop, Dof, PlannedExperiment, RestoringFeedForward};

/// Fewest sample pairs a DOF's fit needs.
pub const MIN_PAIRS: usize = 200;

/// Least share of Δτ's variance the law must explain in every DOF: below
/// it the commands do not follow a PI/PD law on the logged state (another
/// structure, or a log that is not what the autopilot read).
pub const MIN_R_SQUARED: f64 = 0.9;

/// Largest relative standard error of a DOF's K_p.
const MAX_KP_RELATIVE_STD: f64 = 0.1;

/// A command within this share of the force limit counts as saturated.
const SATURATED: f64 = 0.98;

/// One DOF's fitted loop.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct FittedLoop {
    /// The DOF.
    pub dof: Dof,
    /// The gains (negative estimates clipped to 0).
    pub gains: AutopilotLoop,
    /// Standard errors of K_p, K_i and K_d (least squares on white
    /// residuals).
    pub std: [Option<f64>; 3],
    /// The restoring coefficient this DOF's fit gives (W − B for u, v, w;
    /// z_G W − z_B B for φ, θ) with its standard error, when it enters.
    pub restoring: Option<[f64; 2]>,
    /// Sample pairs used.
    pub pairs: usize,
    /// Runs that contributed.
    pub runs: usize,
    /// Share of Δτ's variance the law explains.
    pub r_squared: f64,
}

/// The inferred autopilot and how it was found.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct InferredAutopilot {
    /// The autopilot, ready for the vessel profile.
    pub autopilot: Autopilot,
    /// Per DOF, the fit behind it.
    pub loops: Vec<FittedLoop>,
    /// What was assumed and what was left out, in words.
    pub notes: Vec<String>,
}

/// Why no autopilot could be inferred.
#[derive(Debug, Clone, PartialEq)]
pub struct AutopilotFitError {
    /// The DOF or field at fault.
    pub field: String,
    /// What is wrong.
    pub reason: String,
}

impl std::fmt::Display for AutopilotFitError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.field, self.reason)
    }
}

impl std::error::Error for AutopilotFitError {}

/// What drives a DOF in one run, read off its schedule.
enum Reference<'a> {
    Velocity(&'a [f64]),
    Attitude(&'a [f64]),
}

/// The regression of one DOF: rows of [Δe, ∫e, (Δe_ω), Δĝ] and Δτ.
#[derive(Default)]
struct Rows {
    x: Vec<[f64; 4]>,
    y: Vec<f64>,
    runs: usize,
}

/// ĝ's shape for DOF `d` at (φ, θ): the factor of W − B (u, v, w) or of
/// z_G W − z_B B (φ, θ) in the lumped g(η); yaw has none.
fn restoring_shape(d: Dof, phi: f64, theta: f64) -> Option<f64> {
    let unit = RestoringFeedForward {
        w_minus_b: 1.0,
        zg_w_minus_zb_b: 1.0,
    };
    (d != Dof::Yaw).then(|| unit.force(phi, theta)[d.index()])
}

/// Infers the autopilot of an ROV `profile` from flown `runs`, each paired
/// with the planned experiment it flew (references at the controller rate;
/// the log's first sample is the schedule's t = 0).
pub fn infer_autopilot(
    profile: &VesselProfile,
    runs: &[(&PlannedExperiment, &RunInput)],
) -> Result<InferredAutopilot, AutopilotFitError> {
    if profile.kind != VesselKind::Rov6 {
        return Err(AutopilotFitError {
            field: "vessel.kind".into(),
            reason: "only an ROV's autopilot is inferred (a DP vessel's plan is flown by thruster commands)".into(),
        });
    }
    let mut notes = Vec::new();
    let mut loops = Vec::new();
    let mut restoring: [Vec<[f64; 2]>; 2] = [Vec::new(), Vec::new()];
    for &d in &profile.dofs {
        let attitude = matches!(d, Dof::Roll | Dof::Pitch);
        let limit = profile.limit(d).max_force;
        let mut rows = Rows::default();
        for (planned, run) in runs {
            if let Some(reason) = add_run(d, limit, planned, run, &mut rows) {
                notes.push(format!("{} ({}): {reason}", run.name, d.name()));
            }
        }
        if rows.y.len() < MIN_PAIRS {
            return Err(AutopilotFitError {
                field: format!("autopilot.loops.{}", d.name()),
                reason: format!(
                    "{} sample pairs where the autopilot flew {} by a reference (at least {MIN_PAIRS} needed)",
                    rows.y.len(),
                    d.name()
                ),
            });
        }
        let shape = restoring_shape(d, 0.0, 0.0).is_some();
        let cols: Vec<usize> = (0..4)
            .filter(|&c| (c != 2 || attitude) && (c != 3 || shape))
            .collect();
        let (beta, std, r2) = least_squares(&rows, &cols).ok_or_else(|| AutopilotFitError {
            field: format!("autopilot.loops.{}", d.name()),
            reason: "the runs do not separate the loop's gains (singular regression)".into(),
        })?;
        let at = |c: usize| cols.iter().position(|&x| x == c);
        let get = |c: usize| at(c).map(|j| (beta[j], std[j]));
        let (kp, kp_sd) = get(0).unwrap_or((0.0, 0.0));
        let (ki, ki_sd) = get(1).unwrap_or((0.0, 0.0));
        let kd = get(2);
        let g = get(3);
        let field = format!("autopilot.loops.{}", d.name());
        if r2 < MIN_R_SQUARED {
            return Err(AutopilotFitError {
                field,
                reason: format!(
                    "the logged commands do not follow a {} law on the logged state (it explains {:.0} % of their changes, at least {:.0} % needed): another loop structure, or a log that is not what the autopilot read",
                    if attitude {
                        "PD attitude"
                    } else {
                        "PI velocity"
                    },
                    100.0 * r2.max(0.0),
                    100.0 * MIN_R_SQUARED
                ),
            });
        }
        if !(kp > 0.0 && kp_sd <= MAX_KP_RELATIVE_STD * kp) {
            return Err(AutopilotFitError {
                field,
                reason: format!(
                    "K_p is not determined ({kp:.4e} ± {kp_sd:.2e}): the runs hardly move this DOF's error"
                ),
            });
        }
        if let Some((v, s)) = g {
            restoring[usize::from(attitude)].push([v, s]);
        }
        loops.push(FittedLoop {
            dof: d,
            gains: AutopilotLoop {
                kp: kp.max(0.0),
                ki: ki.max(0.0),
                kd: kd.map(|(v, _)| v.max(0.0)),
            },
            std: [Some(kp_sd), Some(ki_sd), kd.map(|(_, s)| s)],
            restoring: g.map(|(v, s)| [v, s]),
            pairs: rows.y.len(),
            runs: rows.runs,
            r_squared: r2,
        });
    }
    // One W − B and one z_G W − z_B B: the DOFs' estimates weighted by
    // their inverse variances.
    let pooled = |v: &[[f64; 2]]| {
        let (mut s, mut w) = (0.0, 0.0);
        for [x, sd] in v {
            let wi = 1.0 / sd.max(1e-12).powi(2);
            s += wi * x;
            w += wi;
        }
        (w > 0.0).then(|| s / w)
    };
    let w_minus_b = pooled(&restoring[0]);
    let bg = pooled(&restoring[1]);
    let restoring_feed_forward = match (w_minus_b, bg) {
        (None, None) => None,
        (w, b) => Some(RestoringFeedForward {
            w_minus_b: w.unwrap_or(0.0),
            zg_w_minus_zb_b: b.unwrap_or(0.0),
        }),
    };
    notes.insert(
        0,
        format!(
            "fitted on the first differences of the logged commands of {} runs against their planned references, the log's first sample taken as the schedule's start; velocity loops as PI, roll and pitch as attitude PD with an integral, ĝ(η) as the lumped W − B and z_G W − z_B B (thesis eq. 4.6) pooled over the DOFs",
            runs.len()
        ),
    );
    Ok(InferredAutopilot {
        autopilot: Autopilot {
            loops: loops.iter().map(|l| (l.dof, l.gains)).collect(),
            restoring_feed_forward,
        },
        loops,
        notes,
    })
}

/// Adds one run's sample pairs for DOF `d`; `Some(reason)` when the run
/// cannot be used for it.
fn add_run(
    d: Dof,
    limit: f64,
    planned: &PlannedExperiment,
    run: &RunInput,
    rows: &mut Rows,
) -> Option<String> {
    let s = &planned.schedule;
    let col = |name: &str| s.columns.iter().position(|c| c == name);
    let vel_name = format!("{}_ref", d.velocity_symbol());
    let reference = if let Some(c) = col(&vel_name) {
        Reference::Velocity(&s.values[c])
    } else if let Some(c) = matches!(d, Dof::Roll | Dof::Pitch)
        .then(|| col(attitude_column(d)))
        .flatten()
    {
        Reference::Attitude(&s.values[c])
    } else {
        // Open loop (a force schedule) or not driven: the law is not in force.
        return None;
    };
    let rec = &run.record;
    let (Some(tau), Some(nu), Some(phi), Some(theta)) = (
        rec.column(d.force_column()),
        rec.column(d.velocity_symbol()),
        rec.column(pose_column(Dof::Roll)),
        rec.column(pose_column(Dof::Pitch)),
    ) else {
        return Some("the log lacks τ, ν or the attitude".into());
    };
    let eta = rec.column(pose_column(d));
    let fc = s.sample_rate_hz;
    let h_c = 1.0 / fc;
    let n_sched = s.len();
    if n_sched == 0 {
        return Some("the schedule is empty".into());
    }
    let h = 1.0 / rec.sample_rate_hz;
    // The reference at logged sample k: its controller tick.
    let tick = |k: usize| ((k as f64 * h * fc).round() as usize).min(n_sched - 1);
    let attitude = matches!(d, Dof::Roll | Dof::Pitch);
    // η_ref = ∫ω_ref dt from the run's start, per controller tick.
    let integrated: Option<Vec<f64>> = match (&reference, attitude) {
        (Reference::Velocity(w), true) => Some(
            w.iter()
                .scan(0.0, |acc, x| {
                    *acc += x * h_c;
                    Some(*acc)
                })
                .collect(),
        ),
        _ => None,
    };
    // (e, e_ω) at logged sample k.
    let errors = |k: usize| -> Option<(f64, f64)> {
        let j = tick(k);
        match (&reference, attitude) {
            (Reference::Velocity(v), false) => Some((v[j] - nu[k], 0.0)),
            (Reference::Velocity(w), true) => {
                let e = integrated.as_ref()?[j] - eta?[k];
                Some((e, w[j] - nu[k]))
            }
            (Reference::Attitude(a), _) => Some((a[j] - eta?[k], -nu[k])),
        }
    };
    let before = rows.y.len();
    for block in &rec.valid {
        for k in block.start + 1..block.end {
            if tau[k].abs() >= SATURATED * limit || tau[k - 1].abs() >= SATURATED * limit {
                continue;
            }
            let (Some((e1, w1)), Some((e0, w0))) = (errors(k), errors(k - 1)) else {
                continue;
            };
            let g = |i: usize| restoring_shape(d, phi[i], theta[i]).unwrap_or(0.0);
            let row = [e1 - e0, 0.5 * h * (e0 + e1), w1 - w0, g(k) - g(k - 1)];
            let y = tau[k] - tau[k - 1];
            if row.iter().all(|v| v.is_finite()) && y.is_finite() {
                rows.x.push(row);
                rows.y.push(y);
            }
        }
    }
    if rows.y.len() > before {
        rows.runs += 1;
    }
    None
}

/// Least squares of `rows.y` on the columns `cols` of `rows.x`, scaled to
/// unit column norms: (β, std(β), R²).
fn least_squares(rows: &Rows, cols: &[usize]) -> Option<(Vec<f64>, Vec<f64>, f64)> {
    let n = rows.y.len();
    let p = cols.len();
    let a = DMatrix::from_fn(n, p, |i, j| rows.x[i][cols[j]]);
    let scale: Vec<f64> = (0..p)
        .map(|j| {
            let s = a.column(j).norm();
            if s > 0.0 { s } else { 1.0 }
        })
        .collect();
    let a_s = DMatrix::from_fn(n, p, |i, j| a[(i, j)] / scale[j]);
    let y = DVector::from_vec(rows.y.clone());
    let ata = a_s.transpose() * &a_s;
    let chol = ata.clone().cholesky()?;
    let beta_s = chol.solve(&(a_s.transpose() * &y));
    let resid = &y - &a_s * &beta_s;
    let dof = n.saturating_sub(p).max(1) as f64;
    let sigma2 = resid.norm_squared() / dof;
    let cov = chol.inverse();
    let beta: Vec<f64> = (0..p).map(|j| beta_s[j] / scale[j]).collect();
    let std: Vec<f64> = (0..p)
        .map(|j| (sigma2 * cov[(j, j)]).max(0.0).sqrt() / scale[j])
        .collect();
    let mean = y.mean();
    let tss: f64 = y.iter().map(|v| (v - mean).powi(2)).sum();
    let r2 = if tss > 0.0 {
        1.0 - resid.norm_squared() / tss
    } else {
        0.0
    };
    beta.iter()
        .chain(&std)
        .all(|v| v.is_finite())
        .then_some((beta, std, r2))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::logs::{LogRole, ParseOptions, parse_log, to_uniform};
    use crate::planning::examples::{supply_vessel, surveyor_campaign, surveyor_rov};
    use crate::planning::{ExperimentFamily, generate_plan};
    use crate::simulation::rov::RovTruth;
    use crate::simulation::trials::{Feedback, TrialSettings, fly_experiment};

    fn input(profile: &VesselProfile, p: &PlannedExperiment, csv: &str) -> RunInput {
        let opts = ParseOptions::for_vessel(profile, LogRole::Single, None);
        let parsed = parse_log(csv.as_bytes(), &opts).unwrap();
        let (record, _) = to_uniform(&parsed.table, None).unwrap();
        RunInput {
            run_id: p.experiment.code.clone(),
            name: p.experiment.code.clone(),
            family: Some(p.experiment.family),
            grid_speed_mps: p.experiment.grid_speed_mps,
            excited_dofs: p.experiment.dofs.clone(),
            record,
        }
    }

    #[test]
    fn the_gains_that_flew_the_runs_come_back_and_too_little_data_is_an_error() {
        // The project's simulator flies dynamic runs at one grid speed
        // through a declared autopilot reading noisy sensors (20 Hz,
        // logged at 10 Hz); the fit recovers it.
        let truth = RovTruth::surveyor_like();
        let mut profile = surveyor_rov();
        let loops = profile
            .dofs
            .iter()
            .map(|&d| {
                let m = truth.m[(d.index(), d.index())];
                let l = if matches!(d, Dof::Roll | Dof::Pitch) {
                    let kp = 2.0 * m + 800.0;
                    AutopilotLoop {
                        kp,
                        ki: 0.0,
                        kd: Some(1.5 * (kp * m).sqrt()),
                    }
                } else {
                    AutopilotLoop {
                        kp: m,
                        ki: 0.3 * m,
                        kd: None,
                    }
                };
                (d, l)
            })
            .collect();
        let declared = Autopilot {
            loops,
            restoring_feed_forward: Some(RestoringFeedForward {
                w_minus_b: 60.0,
                zg_w_minus_zb_b: 2000.0,
            }),
        };
        profile.autopilot = Some(declared.clone());
        let plan = generate_plan(&profile, &surveyor_campaign(3)).unwrap();
        let settings = TrialSettings {
            seed: 4,
            feedback: Feedback::Measured,
            max_duration_s: Some(200.0),
            ..TrialSettings::default()
        };
        let flown: Vec<(&PlannedExperiment, RunInput)> = plan
            .experiments
            .iter()
            .filter(|p| {
                p.experiment.family == ExperimentFamily::Dynamic
                    && p.experiment.grid_index == Some(1)
            })
            .map(|p| {
                let run = fly_experiment(&profile, &truth, p, &settings).unwrap();
                (p, input(&profile, p, &run.csv))
            })
            .collect();
        assert!(flown.len() >= 6, "{} runs", flown.len());
        let pairs: Vec<_> = flown.iter().map(|(p, i)| (*p, i)).collect();
        let mut blind = profile.clone();
        blind.autopilot = None;
        let fit = infer_autopilot(&blind, &pairs).unwrap();
        for l in &fit.loops {
            let want = declared.loops[&l.dof];
            let name = l.dof.name();
            assert!(
                (l.gains.kp - want.kp).abs() < 0.02 * want.kp,
                "{name} kp {} vs {}",
                l.gains.kp,
                want.kp
            );
            if want.ki > 0.0 {
                assert!(
                    (l.gains.ki - want.ki).abs() < 0.05 * want.ki,
                    "{name} ki {} vs {}",
                    l.gains.ki,
                    want.ki
                );
            }
            assert_eq!(l.gains.kd.is_some(), want.kd.is_some(), "{name}");
            if let (Some(a), Some(b)) = (l.gains.kd, want.kd) {
                assert!((a - b).abs() < 0.02 * b, "{name} kd {a} vs {b}");
            }
            assert!(l.std.iter().flatten().all(|s| s.is_finite() && *s >= 0.0));
        }
        let g = fit.autopilot.restoring_feed_forward.unwrap();
        assert!((g.zg_w_minus_zb_b - 2000.0).abs() < 40.0, "{g:?}");
        assert!(fit.autopilot.validate(&profile.dofs).is_ok());

        // Runs flown by the generic loops (roll and pitch as rate PI under
        // an attitude P loop) and logged with noise the controller did not
        // read: not the law, and said so.
        let generic: Vec<(&PlannedExperiment, RunInput)> = flown
            .iter()
            .map(|(p, _)| {
                let s = TrialSettings {
                    feedback: Feedback::True,
                    ..settings
                };
                let run = fly_experiment(&blind, &truth, p, &s).unwrap();
                (*p, input(&blind, p, &run.csv))
            })
            .collect();
        let pairs: Vec<_> = generic.iter().map(|(p, i)| (*p, i)).collect();
        let e = infer_autopilot(&blind, &pairs).unwrap_err();
        assert!(e.field.starts_with("autopilot.loops."), "{e}");
        eprintln!("{e}");

        // One short run is not enough.
        let short: Vec<(&PlannedExperiment, RunInput)> = flown[..1]
            .iter()
            .map(|(p, i)| {
                let mut i = i.clone();
                for c in &mut i.record.data {
                    c.truncate(50);
                }
                i.record.valid = std::iter::once(0..50).collect();
                (*p, i)
            })
            .collect();
        let pairs: Vec<_> = short.iter().map(|(p, i)| (*p, i)).collect();
        let e = infer_autopilot(&blind, &pairs).unwrap_err();
        assert_eq!(e.field, "autopilot.loops.surge", "{e}");
        assert!(e.reason.contains("sample pairs"), "{e}");
        // A DP vessel's plan is flown by thruster commands.
        let e = infer_autopilot(&supply_vessel(), &[]).unwrap_err();
        assert_eq!(e.field, "vessel.kind");
    }
}
