//! A current tested as the identification estimates it. At one forward
//! speed a current's force D̄·ν_c(ψ) turns with the heading as a pull fixed
//! in NED does, and a model identified without a current has absorbed part
//! of it into its damping; so discovery's per-speed hypotheses, which hold
//! D̄ at the absorbed values, cannot tell the two apart. The identification
//! with the NED current (`ned_current`) estimates V_c together with M and
//! D̄ at every grid speed, on relative velocities ν − ν_c. When a force
//! fixed in NED was named on a surface model identified without a current,
//! the campaign is identified again that way and the two explanations are
//! judged on the held-out runs: the re-identified model must beat the
//! baseline (the same gate as any augmentation) and the augmented model in
//! the sum of its held-out fits.

use nalgebra::{Matrix2, Vector2};

use super::super::discover_gate::{HeldOutVerdict, advantage, compare_against, inertia_verdict};
use super::super::document::{ModelDocument, NedCurrentDoc};
use super::super::error::IdentifyError;
use super::super::lambda_campaign::identify_lambda_campaign;
use super::super::ned_current;
use super::super::outcome::{Identified, RunValidation};
use super::assemble::Assembly;
use super::shared::{CampaignEstimate, polar};
use super::{CampaignDiscovery, DiscoverCampaignSettings, EffectAcrossGrid, PointDiscovery};
use crate::discrepancy::Effect;
use crate::discrepancy::locate::capital;
use crate::discrepancy::report::Estimate;
use crate::estimation::{Progress, SubProgress};
use crate::numbers::sig3;
use crate::planning::VesselProfile;

/// Whether to identify again with the current: asked for, a model with
/// surge, sway and yaw without a current (in its document or as a carried term) that was not
/// identified with one already (`ned_current` in the identification
/// settings given), and something named that a current could stand behind
/// (a force fixed in NED, or terms that absorb its force at one speed).
pub(super) fn applies(
    doc: &ModelDocument,
    settings: &DiscoverCampaignSettings,
    effects: &[EffectAcrossGrid],
    carried: &[Effect],
) -> bool {
    settings.reidentify_current
        && !settings
            .identification
            .as_ref()
            .is_some_and(|s| s.ned_current_for(&doc.dofs))
        && ned_current::possible(&doc.dofs)
        && doc.lpv.as_ref().is_some_and(|l| l.current.is_none())
        && !carried.contains(&Effect::Current)
        && !effects.is_empty()
}

/// The model identified again with the NED current, validated on the
/// held-out runs as discovery validates.
pub(super) struct Again {
    pub model: Identified,
    pub current: NedCurrentDoc,
    /// Against the baseline: the gate every augmentation passes.
    pub vs_baseline: HeldOutVerdict,
}

/// Identifies the campaign's runs again with the NED current estimated
/// (progress 0–1). `Ok(Err(why))` when it gave no current model (no
/// heading logged, an identification error): discovery then goes on
/// without it.
pub(super) fn identify_again(
    asm: &Assembly<'_>,
    profile: &VesselProfile,
    grid: &[f64],
    before: &[RunValidation],
    progress: &mut dyn Progress,
) -> Result<Result<Again, String>, IdentifyError> {
    progress.update(
        0.0,
        "identifying the campaign again with the NED current estimated",
    )?;
    let mut s = asm.settings.identification.clone().unwrap_or_default();
    s.ned_current = Some(true);
    s.validation_run_ids = Some(asm.val_ids.to_vec());
    let runs: Vec<_> = asm
        .runs
        .iter()
        .filter(|r| asm.est_ids.contains(&r.run_id) || asm.val_ids.contains(&r.run_id))
        .cloned()
        .collect();
    let model = match identify_lambda_campaign(profile, grid, asm.forces, &runs, &s, progress) {
        Ok(m) => m,
        Err(IdentifyError::Cancelled) => return Err(IdentifyError::Cancelled),
        Err(e) => return Ok(Err(e.to_string())),
    };
    let Some(current) = model.document.lpv.as_ref().and_then(|l| l.current.clone()) else {
        return Ok(Err(
            "no current stands out of the noise (or the heading ψ is not logged on every run)"
                .to_owned(),
        ));
    };
    let validation = asm.validate(&model.document)?;
    let vs_baseline = inertia_verdict(&model.document)
        .unwrap_or_else(|| compare_against(before, &validation, "the baseline"));
    Ok(Ok(Again {
        model: Identified {
            validation,
            ..model
        },
        current,
        vs_baseline,
    }))
}

/// Discovery on the current model (never identifying again), between
/// progress 0.975 and 0.99, when [`continue_from_it`] says so; `None`
/// when it is not needed or fails (the comparison then goes without it).
pub(super) fn continue_discovery(
    asm: &Assembly<'_>,
    profile: &VesselProfile,
    again: &Again,
    gated: Option<&Identified>,
    progress: &mut dyn Progress,
) -> Result<Option<CampaignDiscovery>, IdentifyError> {
    if !continue_from_it(again, gated) {
        return Ok(None);
    }
    let s = DiscoverCampaignSettings {
        estimation_run_ids: Some(asm.est_ids.to_vec()),
        validation_run_ids: Some(asm.val_ids.to_vec()),
        reidentify_current: false,
        ..asm.settings.clone()
    };
    let mut sub = SubProgress::new(progress, 0.975, 0.015);
    match super::discover_campaign(
        &again.model.document,
        profile,
        asm.forces,
        asm.runs,
        asm.est_ids,
        asm.val_ids,
        &s,
        &mut sub,
    ) {
        Ok(c) => Ok(Some(c)),
        Err(IdentifyError::Cancelled) => Err(IdentifyError::Cancelled),
        Err(_) => Ok(None),
    }
}

/// The outcome once both explanations are known.
pub(super) struct Settled {
    /// The model to store.
    pub model: Option<Identified>,
    /// The verdict on it, in a sentence (replaces the gate's).
    pub overall: Option<String>,
    /// What the re-identification showed, for the summary.
    pub note: String,
    /// The grid speeds' reports of the discovery that continued from the
    /// current model, when that model is the one stored.
    pub points: Option<Vec<PointDiscovery>>,
}

/// Whether the current model loses to the gate's model on the held-out
/// runs while beating the baseline: then discovery continues from it (the
/// physics the force's model found beside the force may be missing from
/// the current model too) before the two are compared again.
fn continue_from_it(again: &Again, gated: Option<&Identified>) -> bool {
    again.vs_baseline.keep
        && gated.is_some_and(|g| advantage(&again.model.validation, &g.validation).0 <= 0.0)
}

/// Keeps the better of the gate's model (`gated`, `None` when the gate
/// stored nothing) and the re-identified one (or, when that loses, the
/// model of the discovery `continued` from it), and marks the effects: the
/// current, when its model wins, goes first with its one estimate (the
/// value the stored model holds), then what the continued discovery
/// found; the forces fixed in NED are its look-alikes, and any other
/// finding on the baseline is left out with the reason.
pub(super) fn settle(
    again: Again,
    continued: Option<CampaignDiscovery>,
    gated: Option<Identified>,
    effects: &mut Vec<EffectAcrossGrid>,
    before: &[RunValidation],
) -> Settled {
    let Again {
        model,
        current,
        vs_baseline,
    } = again;
    let Estimated { polar, estimate } = campaign_estimate(&current);
    let found = format!(
        "Identified again with the NED current estimated, the campaign's current is {}",
        polar
    );
    if !vs_baseline.keep {
        return Settled {
            model: gated,
            overall: None,
            note: format!("{found}; that model is not kept: {}.", vs_baseline.reason),
            points: None,
        };
    }
    // The current model, or (when it loses to the force's model) the
    // discovery that continued from it, with what it found there.
    let mut model = model;
    let mut vs_baseline = vs_baseline;
    let mut on_top: Option<CampaignDiscovery> = None;
    if let Some(g) = &gated {
        let (edge, n) = advantage(&model.validation, &g.validation);
        if edge <= 0.0 {
            // What discovery on the current model did, in words, when it
            // does not win either.
            let mut on_it = "discovery did not run on it".to_owned();
            let plus = continued.and_then(|mut c| {
                let named: Vec<String> = c.report.effects.iter().map(|e| e.label.clone()).collect();
                let Some(m) = c.augmented.take() else {
                    on_it = if named.is_empty() {
                        "discovery on it names nothing".to_owned()
                    } else {
                        format!(
                            "discovery on it names {} and stores nothing",
                            named.join("; ")
                        )
                    };
                    return None;
                };
                let v = inertia_verdict(&m.document)
                    .unwrap_or_else(|| compare_against(before, &m.validation, "the baseline"));
                let (e2, _) = advantage(&m.validation, &g.validation);
                on_it = format!(
                    "with what discovery finds on it ({}) its fits sum {} {}",
                    named.join("; "),
                    sig3(e2.abs()),
                    if e2 > 0.0 {
                        "higher but it fails the gate against the baseline"
                    } else {
                        "lower"
                    }
                );
                (v.keep && e2 > 0.0).then_some((m, v, c))
            });
            let Some((m, v, c)) = plus else {
                return Settled {
                    model: gated,
                    overall: None,
                    note: format!(
                        "{found}; on the held-out runs that model is better than the baseline but not than the model with the force fixed in NED (its {n} fits sum {} lower; {on_it}), so the force stands.",
                        sig3(-edge)
                    ),
                    points: None,
                };
            };
            model = m;
            vs_baseline = v;
            on_top = Some(c);
        }
    }
    // The value the stored model holds (refitted when discovery went on).
    let estimate = match on_top.as_ref().and_then(|_| held_current(&model.document)) {
        Some(held) => held.estimate,
        None => estimate,
    };
    let (gain, _) = advantage(&model.validation, before);
    let versus = match &gated {
        Some(g) => {
            let (edge, n) = advantage(&model.validation, &g.validation);
            format!(
                " and better than the model with the force fixed in NED (its {n} held-out fits sum {} higher)",
                sig3(edge)
            )
        }
        None => String::new(),
    };
    let with = match &on_top {
        Some(c) => {
            let kept: Vec<String> = c
                .report
                .effects
                .iter()
                .filter(|e| e.kept == Some(true))
                .map(|e| e.label.clone())
                .collect();
            format!(
                " and with what discovery found on that model ({})",
                kept.join("; ")
            )
        }
        None => String::new(),
    };
    let reason = format!(
        "identified again with the current{with}, {}{versus}",
        vs_baseline.reason
    );
    let why = if effects.iter().any(|e| e.effect.fixed_in_ned()) {
        "A force fixed in NED was named; at one forward speed a current looks the same, and estimated with the damping it explains the held-out runs better.".to_owned()
    } else {
        let named: Vec<String> = effects.iter().map(|e| e.label.clone()).collect();
        format!(
            "The terms named ({}) stood in for it: estimated with the damping, the current explains the held-out runs better.",
            named.join("; ")
        )
    };
    // Not named by a grid speed: its evidence is the re-identified model's
    // held-out gain over the baseline.
    let mut entry = effects
        .iter()
        .position(|e| e.effect == Effect::Current)
        .map(|i| effects.remove(i))
        .unwrap_or_else(|| EffectAcrossGrid {
            held_out_gains: vec![gain],
            ..EffectAcrossGrid::unnamed(Effect::Current, Effect::Current.label())
        });
    entry.kept = Some(true);
    entry.held_out_verdict = Some(reason.clone());
    entry.campaign_estimate = Some(estimate.clone());
    let mut previous = std::mem::take(effects);
    for e in previous.iter_mut() {
        e.kept = Some(false);
        e.held_out_verdict = Some(if e.effect.fixed_in_ned() {
            "the current, estimated with M and D̄ by identifying the campaign again, is its look-alike and explains the held-out runs better".to_owned()
        } else if on_top.is_some() {
            "named on the baseline; the stored model is the campaign identified again with the current and what discovery found on that model (listed with it)".to_owned()
        } else {
            "not in the stored model, which is the campaign identified again with the current; run discovery on it to test this again".to_owned()
        });
    }
    let stored = if on_top.is_some() {
        "The model identified again with the NED current, with what discovery found on it, was stored"
    } else {
        "The model identified again with the NED current was stored"
    };
    effects.push(entry);
    let points = on_top.map(|c| {
        effects.extend(c.report.effects);
        c.report.points
    });
    effects.extend(previous);
    Settled {
        model: Some(model),
        overall: Some(format!("{stored}: {reason}.")),
        note: format!("{found}. {why}"),
        points,
    }
}

/// The current as the campaign's one estimate, and its size and direction
/// in words.
struct Estimated {
    polar: String,
    estimate: CampaignEstimate,
}

/// The current as the campaign's one estimate: [V_N, V_E] ± std by the
/// first-order propagation of speed and direction.
fn campaign_estimate(c: &NedCurrentDoc) -> Estimated {
    let (v, b) = (c.speed_mps, c.direction_deg.to_radians());
    let (sv, sb) = (c.speed_std_mps, c.direction_std_deg.to_radians());
    let (cb, sn) = (b.cos(), b.sin());
    let var_n = cb * cb * sv * sv + v * v * sn * sn * sb * sb;
    let var_e = sn * sn * sv * sv + v * v * cb * cb * sb * sb;
    let cov_ne = cb * sn * (sv * sv - v * v * sb * sb);
    estimated(
        Vector2::new(c.ned_mps[0], c.ned_mps[1]),
        Matrix2::new(var_n, cov_ne, cov_ne, var_e),
        "estimated once with M and D̄ at every grid speed by identifying the campaign again on the velocities through the water",
    )
}

/// [V_N, V_E] with covariance `cov` as the campaign's estimate; `how` it
/// was estimated ends the sentence.
fn estimated(mean: Vector2<f64>, cov: Matrix2<f64>, how: &str) -> Estimated {
    let names = Effect::Current.coefficient_names();
    let coefficients = (0..2)
        .map(|j| Estimate {
            name: names.get(j).cloned().unwrap_or_default(),
            value: mean[j],
            std: Some(cov[(j, j)].max(0.0).sqrt()).filter(|s| s.is_finite()),
        })
        .collect();
    let polar = polar(Effect::Current, &mean, &cov);
    let text = format!(
        "{} for the campaign: {polar}, {how}.",
        capital(&Effect::Current.label())
    );
    Estimated {
        polar,
        estimate: CampaignEstimate {
            coefficients,
            grid_speeds_mps: vec![],
            chi2: 0.0,
            dof: 0,
            text,
        },
    }
}

/// The current a stored model holds: its `lpv.current`, or the one value
/// every grid point's current term holds (with that term's covariance).
fn held_current(doc: &ModelDocument) -> Option<Estimated> {
    let lpv = doc.lpv.as_ref()?;
    if let Some(c) = &lpv.current {
        return Some(campaign_estimate(c));
    }
    let terms: Vec<_> = lpv
        .points
        .iter()
        .filter_map(|p| p.augmentation.as_ref())
        .filter_map(|a| a.terms.iter().find(|t| t.effect == Effect::Current))
        .collect();
    let first = terms.first()?;
    let same = terms.iter().all(|t| t.coefficients == first.coefficients);
    let (c, v) = (&first.coefficients, &first.covariance);
    if !same || c.len() != 2 || v.len() != 2 || v.iter().any(|r| r.len() != 2) {
        return None;
    }
    Some(estimated(
        Vector2::new(c[0], c[1]),
        Matrix2::new(v[0][0], v[0][1], v[1][0], v[1][1]),
        "estimated with M and D̄ by identifying the campaign again, then refitted with what discovery found on that model and held at every grid speed",
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identification::discover_gate::tests::held_out;

    /// The sum counts each fit both give, clamped to [−1, 1]: one fit up
    /// 0.1, a whole-run free run down to −5 (−1 after clamping), a k-step
    /// fit missing on one side (not counted).
    #[test]
    fn the_advantage_sums_the_fits_both_give() {
        let b = held_out();
        let both = |v: &[RunValidation]| advantage(v, v).1;
        let n0 = both(&b);
        assert!(n0 >= 4, "{n0} fits");
        let mut a = b.clone();
        let c = &mut a[0].report.channels[0];
        let (one, sim) = (
            c.fit_one_step.expect("1-step"),
            c.fit_simulation.expect("free run"),
        );
        assert!(c.fit_k_step.is_some());
        c.fit_one_step = Some(one + 0.1);
        c.fit_simulation = Some(-5.0);
        c.fit_k_step = None;
        let (sum, n) = advantage(&a, &b);
        assert_eq!(n, n0 - 1);
        let want =
            (one + 0.1).clamp(-1.0, 1.0) - one.clamp(-1.0, 1.0) + (-1.0 - sim.clamp(-1.0, 1.0));
        assert!((sum - want).abs() < 1e-12, "{sum} vs {want}");
        assert_eq!(advantage(&a, &[]), (0.0, 0));
    }

    /// [V_N, V_E] ± std from speed and direction: a current towards east
    /// with an exact direction has σ_N = 0 and σ_E = σ_V; towards north
    /// with σ_β = 0.1 rad, σ_E = V·σ_β.
    #[test]
    fn the_current_estimate_propagates_speed_and_direction() {
        let doc = |dir: f64, s_dir: f64| NedCurrentDoc {
            speed_mps: 0.2,
            speed_std_mps: 0.01,
            direction_deg: dir,
            direction_std_deg: s_dir,
            ned_mps: [0.2 * dir.to_radians().cos(), 0.2 * dir.to_radians().sin()],
            evidence: String::new(),
        };
        let east = campaign_estimate(&doc(90.0, 0.0)).estimate;
        assert!(east.coefficients[0].std.unwrap() < 1e-12);
        assert!((east.coefficients[1].std.unwrap() - 0.01).abs() < 1e-12);
        assert!((east.coefficients[1].value - 0.2).abs() < 1e-12);
        let north = campaign_estimate(&doc(0.0, 0.1f64.to_degrees()));
        assert!((north.estimate.coefficients[0].std.unwrap() - 0.01).abs() < 1e-12);
        assert!((north.estimate.coefficients[1].std.unwrap() - 0.02).abs() < 1e-12);
        assert!(
            north.polar.starts_with("0.2 ± 0.01 m/s towards 0°"),
            "{}",
            north.polar
        );
        assert!(
            north.estimate.text.starts_with("Ocean current"),
            "{}",
            north.estimate.text
        );
    }
}
