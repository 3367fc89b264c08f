//! The report's parts made from the selection's outcome: hypotheses as
//! reported, the before/after plot series, the structure left unexplained
//! and the summary in words.

use super::candidates::Effect;
use super::data::Record;
use super::fit::Spec;
use super::lines::spectral_lines;
use super::locate::{
    BAND_EXCESS_DB, Predictions, capital, force_residual, phi_diag, residual, signature_words,
};
use super::model::AugmentedModel;
use super::report::*;
use super::residual::{BandPower, residual_spectrum};
use super::select::{Criteria, Scored};
use crate::numbers::sig3;

pub(super) fn hypothesis(
    s: &Scored,
    step: usize,
    verdict: Verdict,
    _c: &Criteria,
) -> HypothesisReport {
    let e = s.spec.effect;
    let own = s.own();
    let cov = s.fit.theta_cov(own);
    let coefficients = s.fit.theta[own]
        .iter()
        .zip(e.coefficient_names())
        .enumerate()
        .map(|(i, (v, name))| Estimate {
            name,
            value: *v,
            std: cov
                .as_ref()
                .map(|c| c[(i, i)].max(0.0).sqrt())
                .filter(|s| s.is_finite()),
        })
        .collect();
    let shape = s.spec.shape.map(|v| Estimate {
        name: e
            .shape()
            .unwrap_or(super::candidates::ShapeKind::DeadZoneWidth)
            .name()
            .into(),
        value: v,
        std: s.shape_std.filter(|s| s.is_finite()),
    });
    HypothesisReport {
        effect: e,
        family: e.family(),
        label: e.label(),
        step,
        coefficients,
        shape,
        delta_bic: s.delta_bic,
        z: s.z,
        cv_gain: s.cv_gain,
        force_share: s.force_share.filter(|x| x.is_finite()),
        verdict,
    }
}

pub(super) fn plot_series(
    rec: &Record,
    before: &Predictions,
    after: &Predictions,
    dofs: &[crate::planning::Dof],
    points: usize,
) -> Vec<PlotSeries> {
    let step = rec.len().div_ceil(points).max(1);
    let idx: Vec<usize> = (0..rec.len()).step_by(step).collect();
    dofs.iter()
        .enumerate()
        .map(|(i, &dof)| PlotSeries {
            run: rec.name.clone(),
            dof,
            t: idx.iter().map(|&k| k as f64 * rec.h).collect(),
            measured: idx.iter().map(|&k| rec.nu[(k, i)]).collect(),
            before: idx.iter().map(|&k| before.free[(k, i)]).collect(),
            after: idx.iter().map(|&k| after.free[(k, i)]).collect(),
        })
        .collect()
}

/// Structure of the augmented model's 1-step residual no candidate
/// explains, per DOF: a narrow line ([`spectral_lines`]) in the residual
/// force M·e/h — an exogenous periodic force, sized in N or N·m — and the
/// octave band furthest above the noise floor.
pub(super) fn unexplained(
    model: &AugmentedModel,
    runs: &[&Record],
    chosen: &[Spec],
) -> Vec<Unexplained> {
    let h = runs.first().map_or(0.1, |r| r.h);
    let phi = phi_diag(model, h);
    let preds: Vec<_> = runs.iter().map(|r| model.predict_k_step(r, 1)).collect();
    let mut out = Vec::new();
    for (i, &dof) in model.dofs.iter().enumerate() {
        let explained_here = chosen.iter().any(|c| c.effect.dof() == Some(dof));
        let after = if explained_here {
            " after the chosen terms"
        } else {
            ""
        };
        let forces: Vec<Vec<f64>> = runs
            .iter()
            .zip(&preds)
            .map(|(r, p)| force_residual(model, r, p, i))
            .collect();
        if let Some(line) = spectral_lines(&forces, 1.0 / h).into_iter().next() {
            let unit = dof.force_unit();
            let text = format!(
                "{}: a periodic force no candidate explains{after} — a line at {} Hz (period {} s), about {} {unit} in amplitude ({}–{} {unit} run by run), {:.0} dB over the residual around it, in {} of {} runs; it comes from outside the model's physics (waves, vortex shedding, machinery), and nothing physical is named for it.",
                capital(dof.name()),
                sig3(line.frequency_hz),
                sig3(1.0 / line.frequency_hz),
                sig3(line.amplitude),
                sig3(line.run_amplitudes[0]),
                sig3(line.run_amplitudes[1]),
                line.excess_db,
                line.runs_with_line,
                line.runs
            );
            out.push(Unexplained {
                dof,
                band: BandPower {
                    f_lo_hz: line.frequency_hz - 2.0 * line.resolution_hz,
                    f_hi_hz: line.frequency_hz + 2.0 * line.resolution_hz,
                    excess_db: line.excess_db,
                    peak_hz: line.frequency_hz,
                },
                low_slope: 0.0,
                signature: format!("narrow line at {} Hz", sig3(line.frequency_hz)),
                text,
                line: Some(line),
            });
        }
        let e: Vec<Vec<f64>> = runs
            .iter()
            .zip(&preds)
            .map(|(r, p)| residual(r, p, i))
            .collect();
        let Some(spec) = residual_spectrum(&e, 1.0 / h, phi[i]) else {
            continue;
        };
        let Some(b) = spec
            .bands
            .iter()
            .filter(|b| b.excess_db > BAND_EXCESS_DB)
            .max_by(|a, b| a.excess_db.total_cmp(&b.excess_db))
        else {
            continue;
        };
        let signature = signature_words(spec.low_slope, b)
            .trim_start_matches(", ")
            .to_string();
        out.push(Unexplained {
            dof,
            band: b.clone(),
            low_slope: spec.low_slope,
            text: format!(
                "{}: structure no candidate explains{after} — 1-step residual {:.0} dB above the noise floor at {:.3}–{:.3} Hz, {signature}.",
                capital(dof.name()),
                b.excess_db,
                b.f_lo_hz,
                b.f_hi_hz
            ),
            signature,
            line: None,
        });
    }
    out
}

pub(super) fn summary(
    loc: &super::locate::LocationReport,
    carried: &[Effect],
    findings: &[Finding],
    validation: &[ChannelComparison],
    ambiguities: &[Ambiguity],
    unexplained: &[Unexplained],
) -> Vec<String> {
    let mut out = Vec::new();
    let parting: Vec<&str> = loc
        .per_dof
        .iter()
        .filter(|d| d.parts)
        .map(|d| d.dof.name())
        .collect();
    let the_model = if carried.is_empty() {
        "The baseline"
    } else {
        let labels: Vec<String> = carried.iter().map(Effect::label).collect();
        out.push(format!(
            "Started from the terms the model carries ({}): kept, refitted with any new term, not tested again.",
            labels.join("; ")
        ));
        "The model"
    };
    if parting.is_empty() && findings.is_empty() {
        out.push(format!(
            "{the_model} explains the recordings: no {}candidate term improves held-out runs.",
            if carried.is_empty() { "" } else { "further " }
        ));
    } else if !parting.is_empty() {
        out.push(format!(
            "{the_model} parts from the recordings in {}.",
            parting.join(", ")
        ));
    }
    for f in findings {
        out.push(f.effect_text.clone());
    }
    for c in validation {
        if let (Some(b), Some(a)) = (c.before.free_run, c.after.free_run)
            && (a - b).abs() >= 0.01
        {
            out.push(format!(
                "{}: validation free-run fit {:.2} → {:.2}.",
                capital(c.dof.name()),
                b,
                a
            ));
        }
    }
    out.extend(ambiguities.iter().map(|a| a.text.clone()));
    out.extend(unexplained.iter().map(|u| u.text.clone()));
    out
}
