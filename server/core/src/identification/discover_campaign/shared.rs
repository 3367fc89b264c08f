//! Forces the campaign shares, estimated once for it. A current or a pull
//! fixed in NED acts at every forward speed alike, so the grid speeds'
//! estimates of it are pooled by inverse covariance (the least-squares
//! estimate of one value from independent estimates of it), and every grid
//! speed's model is refitted with it held at that value: the LPV model then
//! carries one current, not one per speed. Where the speeds' estimates
//! scatter more than their standard deviations allow, the pooled standard
//! deviation is widened by √(χ²/dof) (the Birge ratio) and the text says so.

use nalgebra::{Matrix2, Vector2};
use serde::{Deserialize, Serialize};

use super::super::dataset::RunInput;
use super::super::document::ModelDocument;
use super::super::error::IdentifyError;
use super::super::ned_current::{self, surge_component};
use super::super::roles::nearest_grid_index;
use super::speeds_text;
use super::{EffectAcrossGrid, PointDiscovery};
use crate::discrepancy::locate::capital;
use crate::discrepancy::report::{Estimate, Finding, ModelReport};
use crate::discrepancy::{
    AugmentedModel, DiscoveryError, DiscoverySettings, Effect, ModelTerm, Record, refit_holding,
};
use crate::logs::schema::pose_column;
use crate::numbers::sig3;
use crate::planning::campaign::ExperimentFamily;
use crate::planning::dof::Dof;

/// One force the campaign shares, estimated once for it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct CampaignEstimate {
    /// Its coefficients ± std, pooled over the grid speeds.
    pub coefficients: Vec<Estimate>,
    /// Grid speeds (m/s) whose estimates were pooled.
    pub grid_speeds_mps: Vec<f64>,
    /// χ² of the speeds' estimates about the pooled one.
    pub chi2: f64,
    /// Its degrees of freedom (2 per speed beyond the first).
    pub dof: usize,
    /// Size and direction in words, and how the speeds agree.
    pub text: String,
}

/// The 95 % point of χ² with `dof` degrees of freedom (Wilson–Hilferty;
/// 5.93 for 2 against the exact 5.99): above it the speeds' estimates
/// disagree, and the std is widened.
pub(super) fn chi2_95(dof: usize) -> f64 {
    let k = dof as f64;
    let a = 2.0 / (9.0 * k);
    k * (1.0 - a + 1.645 * a.sqrt()).powi(3)
}

/// The pooled term of every NED-fixed effect that at least two grid
/// speeds' models carry (chosen there, or carried from the model examined).
pub(super) fn pool_all(points: &[PointDiscovery]) -> Vec<(ModelTerm, CampaignEstimate)> {
    let terms: Vec<(f64, &ModelTerm)> = points
        .iter()
        .flat_map(|p| p.report.model.terms.iter().map(|t| (p.grid_speed_mps, t)))
        .collect();
    [Effect::Current, Effect::TetherPull]
        .into_iter()
        .filter_map(|e| pool(&terms, e))
        .collect()
}

/// Of the pooled forces fixed in NED, the one the campaign holds: a force
/// the model carries (a current the identification found), else the first
/// in the campaign's ranking `effects`. Returns it (or nothing) and the
/// effects the grid speeds named that are its look-alikes, which the
/// refitted models leave out.
pub(super) fn one_ned_force(
    pooled: Vec<(ModelTerm, CampaignEstimate)>,
    effects: &[EffectAcrossGrid],
    carried: &[Effect],
) -> (Vec<(ModelTerm, CampaignEstimate)>, Vec<Effect>) {
    let rank = |e: Effect| {
        if carried.contains(&e) {
            0
        } else {
            1 + effects
                .iter()
                .position(|x| x.effect == e)
                .unwrap_or(effects.len())
        }
    };
    let Some(best) = pooled
        .iter()
        .map(|(t, _)| t.effect)
        .min_by_key(|e| rank(*e))
    else {
        return (pooled, vec![]);
    };
    let look_alikes = effects
        .iter()
        .map(|e| e.effect)
        .filter(|e| e.fixed_in_ned() && *e != best)
        .collect();
    (
        pooled
            .into_iter()
            .filter(|(t, _)| t.effect == best)
            .collect(),
        look_alikes,
    )
}

/// The inverse-covariance pool of `effect`'s [N, E] coefficients over the
/// grid speeds' terms (speed, term) with a usable covariance.
fn pool(terms: &[(f64, &ModelTerm)], effect: Effect) -> Option<(ModelTerm, CampaignEstimate)> {
    let mut speeds = Vec::new();
    let mut ests: Vec<(Vector2<f64>, Matrix2<f64>)> = Vec::new();
    for &(speed, t) in terms.iter().filter(|(_, t)| t.effect == effect) {
        let (Some(x), Some(c)) = (two(&t.coefficients), covariance(&t.covariance)) else {
            continue;
        };
        let Some(w) = c.try_inverse().filter(|w| w.iter().all(|v| v.is_finite())) else {
            continue;
        };
        speeds.push(speed);
        ests.push((x, w));
    }
    if ests.len() < 2 {
        return None;
    }
    let w_sum: Matrix2<f64> = ests.iter().map(|(_, w)| w).sum();
    let cov = w_sum.try_inverse()?;
    let wx: Vector2<f64> = ests.iter().map(|(x, w)| w * x).sum();
    let mean = cov * wx;
    let chi2: f64 = ests
        .iter()
        .map(|(x, w)| {
            let d = x - mean;
            (d.transpose() * w * d)[(0, 0)]
        })
        .sum();
    let dof = 2 * (ests.len() - 1);
    let ratio = chi2 / dof as f64;
    let disagree = chi2 > chi2_95(dof);
    // One value carried at every speed is one estimate, not n.
    let identical = ests
        .iter()
        .all(|(x, _)| (x - ests[0].0).amax() <= 1e-12 * ests[0].0.amax().max(1e-300));
    let cov = if identical {
        ests[0].1.try_inverse()?
    } else if disagree {
        cov * ratio
    } else {
        cov
    };
    if !(mean.iter().chain(cov.iter()).all(|v| v.is_finite())) {
        return None;
    }
    let term = ModelTerm {
        effect,
        coefficients: vec![mean[0], mean[1]],
        covariance: (0..2)
            .map(|i| (0..2).map(|j| cov[(i, j)]).collect())
            .collect(),
        shape: None,
        shape_std: None,
    };
    let names = effect.coefficient_names();
    let coefficients = (0..2)
        .map(|j| Estimate {
            name: names.get(j).cloned().unwrap_or_default(),
            value: mean[j],
            std: Some(cov[(j, j)].sqrt()),
        })
        .collect();
    let agreement = if identical {
        "every one of them carries the same value, the start model's (no speed re-estimated it)"
            .to_owned()
    } else if disagree {
        format!(
            "the speeds' estimates scatter more than their standard deviations allow (χ² {} on {dof} degrees of freedom), so the standard deviation is widened {}×: the force changed during the campaign, or a speed's other terms traded against it",
            sig3(chi2),
            sig3(ratio.sqrt())
        )
    } else {
        format!(
            "the speeds' estimates agree within their standard deviations (χ² {} on {dof} degrees of freedom)",
            sig3(chi2)
        )
    };
    let text = format!(
        "{} for the campaign: {}, pooled from the estimates at {} grid speeds ({} m/s); {agreement}. Every examined grid speed's model is refitted with it held there.",
        capital(&effect.label()),
        polar(effect, &mean, &cov),
        ests.len(),
        speeds_text(&speeds)
    );
    Some((
        term,
        CampaignEstimate {
            coefficients,
            grid_speeds_mps: speeds,
            chi2,
            dof,
            text,
        },
    ))
}

/// `start` refitted on `est` with the pooled terms held at the campaign's
/// values and `terms` fitted beside them, less any force fixed in NED (the
/// held one's look-alikes).
fn refit_with_pooled(
    start: &AugmentedModel,
    terms: &[ModelTerm],
    est: &[Record],
    settings: &DiscoverySettings,
    pooled: &[(ModelTerm, CampaignEstimate)],
) -> Result<AugmentedModel, DiscoveryError> {
    let own: Vec<ModelTerm> = terms
        .iter()
        .filter(|t| !t.effect.fixed_in_ned())
        .cloned()
        .collect();
    let held: Vec<ModelTerm> = pooled.iter().map(|(t, _)| t.clone()).collect();
    refit_holding(start, est, settings, &own, &held)
}

/// Point `p` with the pooled terms held: its model refitted on its
/// estimation runs with them at the campaign's values and without their
/// look-alikes (any other force fixed in NED), its findings of them showing
/// those values, and a finding added where the speed's own discovery had
/// not named a shared force its start does not carry (the current acts at
/// this speed too).
pub(super) fn held_at(
    p: &PointDiscovery,
    start: &AugmentedModel,
    est: &[Record],
    settings: &DiscoverySettings,
    pooled: &[(ModelTerm, CampaignEstimate)],
) -> Result<PointDiscovery, IdentifyError> {
    // Every force fixed in NED but the held one is its look-alike.
    let model =
        refit_with_pooled(start, &p.report.model.terms, est, settings, pooled).map_err(|e| {
            IdentifyError::invalid(
                e.field().to_string(),
                format!("at grid speed {} m/s: {e}", p.grid_speed_mps),
            )
        })?;
    let mut out = p.clone();
    out.report
        .findings
        .retain(|f| !f.effect.fixed_in_ned() || pooled.iter().any(|(t, _)| t.effect == f.effect));
    for (t, c) in pooled {
        match out
            .report
            .findings
            .iter_mut()
            .find(|f| f.effect == t.effect)
        {
            Some(f) => {
                f.coefficients = c.coefficients.clone();
                f.evidence.push(c.text.clone());
            }
            None if !start.terms.iter().any(|s| s.effect == t.effect) => {
                out.report.findings.push(Finding {
                    effect: t.effect,
                    label: t.effect.label(),
                    dofs: t
                        .effect
                        .rows(&model.dofs, &model.d_ref)
                        .into_iter()
                        .map(|r| model.dofs[r])
                        .collect(),
                    coefficients: c.coefficients.clone(),
                    shape: None,
                    effect_text: c.text.clone(),
                    evidence: vec![format!(
                        "Not named by this speed's own discovery; a force fixed in NED acts at every speed, so it is held here at the campaign's estimate ({}).",
                        c.text
                    )],
                });
            }
            None => {}
        }
    }
    out.report.model = ModelReport::of(&model);
    Ok(out)
}

/// The grid speeds discovery did not examine (no held-out run there, or
/// not asked for: (speed, its start model, its estimation records)) with
/// the pooled terms held: each model refitted on its estimation runs with
/// them at the campaign's values, its own terms (carried from the model
/// examined) refitted beside them. Returns the refitted speeds and what the
/// summary says of them; a speed without estimation runs, or whose refit
/// fails, stays as it was, and the summary says so.
pub(super) fn hold_unexamined(
    unexamined: &[(f64, AugmentedModel, &[Record])],
    settings: &DiscoverySettings,
    pooled: &[(ModelTerm, CampaignEstimate)],
) -> (Vec<(f64, ModelReport)>, Vec<String>) {
    let Some((term, _)) = pooled.first() else {
        return (vec![], vec![]);
    };
    let (mut out, mut left) = (Vec::new(), Vec::new());
    for (speed, start, est) in unexamined {
        let fit = if est.is_empty() {
            Err("no estimation run to refit on".to_owned())
        } else {
            refit_with_pooled(start, &start.terms, est, settings, pooled)
                .map(|m| ModelReport::of(&m))
                .map_err(|e| e.to_string())
        };
        match fit {
            Ok(model) => out.push((*speed, model)),
            Err(why) => left.push(format!("{speed:.2} m/s ({why})")),
        }
    }
    let label = term.effect.label();
    let mut notes = Vec::new();
    if !out.is_empty() {
        let speeds: Vec<f64> = out.iter().map(|(s, _)| *s).collect();
        notes.push(format!(
            "{} is also held at the grid speeds not examined ({} m/s): their models are refitted on their estimation runs with it at the campaign's estimate.",
            capital(&label),
            speeds_text(&speeds)
        ));
    }
    if !left.is_empty() {
        notes.push(format!(
            "At {} the model stays as it was, without the {label}.",
            left.join(", ")
        ));
    }
    (out, notes)
}

/// When the examined model was identified without the current discovery
/// pooled ([V_N, V_E] m/s), the way to a model that has it throughout: the
/// identification's own current estimate, which also places each run at
/// the grid point of its speed through the water u − u_c(ψ). Names the
/// estimation runs (`est_ids`, no stated grid speed) that the current moves
/// to another grid point. `None` when the model has a current or is not a
/// model with surge, sway and yaw.
pub(super) fn reidentify_note(
    doc: &ModelDocument,
    runs: &[RunInput],
    est_ids: &[String],
    grid: &[f64],
    v: [f64; 2],
) -> Option<String> {
    let lpv = doc.lpv.as_ref()?;
    if lpv.current.is_some() || !ned_current::possible(&doc.dofs) {
        return None;
    }
    let mut moved = Vec::new();
    for r in runs
        .iter()
        .filter(|r| est_ids.contains(&r.run_id) && r.grid_speed_mps.is_none())
        .filter(|r| r.family != Some(ExperimentFamily::Static))
    {
        let (Some(u), Some(psi)) = (
            r.record.column(Dof::Surge.velocity_symbol()),
            r.record.column(pose_column(Dof::Yaw)),
        ) else {
            continue;
        };
        let (mut ground, mut water, mut n) = (0.0, 0.0, 0usize);
        for (u, psi) in u.iter().zip(psi) {
            if u.is_finite() && psi.is_finite() {
                ground += u;
                water += u - surge_component(v, *psi);
                n += 1;
            }
        }
        if n == 0 {
            continue;
        }
        let (ground, water) = (ground / n as f64, water / n as f64);
        let (a, b) = (
            nearest_grid_index(grid, ground),
            nearest_grid_index(grid, water),
        );
        if a != b {
            moved.push(format!(
                "{} ({} m/s over ground, {} through the water: the {} m/s sub-model's, not the {} m/s one's)",
                r.name,
                sig3(ground),
                sig3(water),
                sig3(grid[b]),
                sig3(grid[a])
            ));
        }
    }
    let why = if moved.is_empty() {
        "it estimates the current together with M and D̄, once for the campaign, instead of fitting around damping that absorbed it".to_owned()
    } else {
        format!(
            "it also places each run at the grid point of its speed through the water, which the hull's forces follow; this model holds runs at the grid point of their speed over ground: {}",
            moved.join(", ")
        )
    };
    Some(format!(
        "The model was identified without a current. Identify the campaign again with the NED current estimated (`ned_current: true`, the default for surface vessels): {why}."
    ))
}

/// A pull fixed in NED named on a model (surge, sway, yaw) identified without a
/// current: at one forward speed a current's force D̄·ν_c(ψ) turns with the
/// heading as the pull does, so the text names the look-alike and how to
/// test it.
pub(super) fn pull_or_current_note(doc: &ModelDocument) -> Option<String> {
    let lpv = doc.lpv.as_ref()?;
    (lpv.current.is_none() && ned_current::possible(&doc.dofs)).then(|| {
        "A force fixed in NED was named; a current looks the same at one forward speed (its force D̄·ν_c(ψ) turns with the heading too), and the model was identified without one. Unless the vessel was moored, tethered, towed or held in a steady wind, identify the campaign again with the NED current estimated (`ned_current: true`, the default for surface vessels) and compare the held-out fits.".to_owned()
    })
}

fn two(v: &[f64]) -> Option<Vector2<f64>> {
    (v.len() == 2 && v.iter().all(|x| x.is_finite())).then(|| Vector2::new(v[0], v[1]))
}

fn covariance(c: &[Vec<f64>]) -> Option<Matrix2<f64>> {
    if c.len() != 2 || c.iter().any(|r| r.len() != 2) {
        return None;
    }
    let m = Matrix2::new(c[0][0], c[0][1], c[1][0], c[1][1]);
    (m.iter().all(|v| v.is_finite()) && m[(0, 0)] > 0.0 && m[(1, 1)] > 0.0).then_some(m)
}

/// Size and direction (towards, degrees from north) ± std of a vector
/// [N, E] with covariance `cov`, by the first-order propagation through
/// |v| and atan2(E, N).
pub(super) fn polar(effect: Effect, v: &Vector2<f64>, cov: &Matrix2<f64>) -> String {
    let size = v.norm();
    let dir = v[1].atan2(v[0]).to_degrees().rem_euclid(360.0);
    let (unit, digits) = match effect {
        Effect::Current => ("m/s", 1000.0),
        _ => ("N", 1.0),
    };
    if size <= 0.0 {
        return format!("0 {unit}");
    }
    let js = Vector2::new(v[0] / size, v[1] / size);
    let jd = Vector2::new(-v[1] / (size * size), v[0] / (size * size));
    let s_size = (js.transpose() * cov * js)[(0, 0)].max(0.0).sqrt();
    let s_dir = (jd.transpose() * cov * jd)[(0, 0)]
        .max(0.0)
        .sqrt()
        .to_degrees();
    let round = |x: f64| (x * digits).round() / digits;
    format!(
        "{} ± {} {unit} towards {:.0}° ± {:.0}° (north {}, east {} {unit})",
        sig3(round(size)),
        sig3(s_size),
        dir,
        s_dir.max(1.0),
        sig3(round(v[0])),
        sig3(round(v[1]))
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn term(x: [f64; 2], var: f64) -> ModelTerm {
        ModelTerm {
            effect: Effect::Current,
            coefficients: x.to_vec(),
            covariance: vec![vec![var, 0.0], vec![0.0, var]],
            shape: None,
            shape_std: None,
        }
    }

    /// Two estimates of equal covariance pool to their mean with the
    /// variance halved; estimates two std apart give χ² = 2 on 2 dof.
    #[test]
    fn two_equal_estimates_pool_to_their_mean() {
        let (a, b) = (term([0.1, -0.2], 1e-4), term([0.1, -0.18], 1e-4));
        let (t, e) = pool(&[(0.3, &a), (0.6, &b)], Effect::Current).expect("pooled");
        assert!((t.coefficients[0] - 0.1).abs() < 1e-12);
        assert!((t.coefficients[1] + 0.19).abs() < 1e-12);
        // (0.01/0.01)² twice = 2 on 2 dof: agree, std 0.01/√2.
        assert!((e.chi2 - 2.0).abs() < 1e-9, "{}", e.chi2);
        assert_eq!(e.dof, 2);
        assert!((e.coefficients[1].std.unwrap() - 0.01 / 2f64.sqrt()).abs() < 1e-12);
        assert!(e.text.contains("agree"), "{}", e.text);
        // |(0.1, −0.19)| = 0.2147, towards 360° − 62.2°.
        assert!(
            e.text.contains("0.215 ± 0.00707 m/s towards 298°"),
            "{}",
            e.text
        );
    }

    /// The χ² 95 % points of 2 and 4 degrees of freedom (5.99, 9.49).
    #[test]
    fn the_chi2_points_are_close_to_the_tables() {
        assert!((chi2_95(2) - 5.991).abs() < 0.1);
        assert!((chi2_95(4) - 9.488).abs() < 0.05);
    }

    /// Estimates twenty std apart: the std is widened by √(χ²/dof).
    #[test]
    fn scattered_estimates_widen_the_std() {
        let (a, b) = (term([0.0, 0.3], 1e-4), term([0.0, 0.1], 1e-4));
        let (t, e) = pool(&[(0.3, &a), (0.6, &b)], Effect::Current).expect("pooled");
        assert!((t.coefficients[1] - 0.2).abs() < 1e-12);
        // χ² = 2·(0.1/0.01)² = 200 on 2 dof → std 0.00707·10.
        assert!((e.chi2 - 200.0).abs() < 1e-6);
        assert!((e.coefficients[1].std.unwrap() - 0.01 / 2f64.sqrt() * 10.0).abs() < 1e-9);
        assert!(e.text.contains("widened 10×"), "{}", e.text);
    }

    /// A speed not examined and without estimation runs keeps its model,
    /// and the summary says so; nothing is held there.
    #[test]
    fn a_speed_without_estimation_runs_stays_as_it_was() {
        use crate::discrepancy::{Baseline, Restoring};
        use nalgebra::DMatrix;
        let start = AugmentedModel::from_baseline(&Baseline {
            dofs: Dof::HORIZONTAL.to_vec(),
            m: DMatrix::identity(3, 3) * 100.0,
            d_bar: DMatrix::identity(3, 3) * 50.0,
            restoring: Restoring::default(),
            coriolis: None,
            quadratic: None,
        });
        let (a, b) = (term([0.1, -0.2], 1e-4), term([0.1, -0.18], 1e-4));
        let pooled = vec![pool(&[(0.3, &a), (0.6, &b)], Effect::Current).expect("pooled")];
        let (held, notes) =
            hold_unexamined(&[(0.9, start, &[])], &DiscoverySettings::default(), &pooled);
        assert!(held.is_empty());
        assert_eq!(
            notes,
            vec![format!(
                "At 0.90 m/s (no estimation run to refit on) the model stays as it was, without the {}.",
                Effect::Current.label()
            )]
        );
        // Nothing pooled: nothing to hold, nothing to say.
        assert_eq!(
            hold_unexamined(&[], &DiscoverySettings::default(), &[])
                .1
                .len(),
            0
        );
    }

    /// The same value carried at every speed (the start model's campaign
    /// term, re-estimated nowhere) keeps its own std, not one shrunk by
    /// √n, and the text says so instead of quoting a χ² of zero.
    #[test]
    fn one_value_carried_at_every_speed_is_one_estimate() {
        let a = term([0.1, -0.2], 1e-4);
        let (t, e) = pool(&[(0.3, &a), (0.6, &a), (0.9, &a)], Effect::Current).expect("pooled");
        assert_eq!(t.coefficients, vec![0.1, -0.2]);
        assert!((e.coefficients[0].std.unwrap() - 0.01).abs() < 1e-12);
        assert!(e.text.contains("carries the same value"), "{}", e.text);
        assert!(!e.text.contains("χ²"), "{}", e.text);
    }

    /// One speed's estimate, or a term without covariance, is no pool.
    #[test]
    fn one_estimate_is_not_pooled() {
        let a = term([0.1, 0.1], 1e-4);
        let mut b = term([0.1, 0.1], 1e-4);
        b.covariance = vec![];
        assert!(pool(&[(0.3, &a)], Effect::Current).is_none());
        assert!(pool(&[(0.3, &a), (0.6, &b)], Effect::Current).is_none());
    }
}
