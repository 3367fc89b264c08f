//! The refinement step of a DP campaign: after the staged parallel EKF,
//! every θ″ of the layout is refined jointly on every estimation block by prediction
//! error ([`refine_dp_ship`]), and the refined θ″ replace the EKF's only
//! if the refinement converged and the held-out runs are predicted no worse
//! (the negative log-likelihood V of the Kalman predictor's innovations on
//! them rises by at most [`HELD_OUT_TOLERANCE`]). Otherwise the EKF's θ″
//! are kept and a structure finding says why; the job never fails for it.

use super::document::DpRefinementDoc;
use super::error::IdentifyError;
use crate::estimation::Progress;
use crate::estimation::ekf::{
    DpIdentConfig, DpIdentification, EkfError, RefineSettings, RunData, dp_predictor_nll,
    refine_dp_ship,
};
use crate::numbers::sig3;
use crate::simulation::dp_ship::{DpShip, N_THETA};

/// Largest rise of the held-out V accepted (log-likelihood units): a
/// likelihood ratio of e², beyond what parameters moving within their
/// std change on a held-out run.
pub(crate) const HELD_OUT_TOLERANCE: f64 = 2.0;

/// Notes and findings the refinement adds to the model document.
#[derive(Debug, Default)]
pub(crate) struct RefineOutcome {
    /// What was done and what the std means.
    pub notes: Vec<String>,
    /// Why the EKF's θ″ were kept, if they were.
    pub findings: Vec<String>,
    /// The structured record for the document (None: not attempted).
    pub record: Option<DpRefinementDoc>,
}

/// The record of a refinement that did not run or was not taken, for `why`.
pub(crate) fn not_run(id: &DpIdentification, why: &str) -> DpRefinementDoc {
    DpRefinementDoc {
        applied: false,
        reason: Some(why.to_owned()),
        ekf_theta: id.theta.to_vec(),
        ekf_theta_std: id.theta_std.to_vec(),
        iterations: 0,
        variance_ratio: None,
        std_inflation: Vec::new(),
        held_out_nll_change: None,
    }
}

/// Refines `id` in place on `estimation` (all stages' blocks), checked on
/// `held_out`; `names` are the layout's θ″ names.
pub(crate) fn refine_campaign(
    id: &mut DpIdentification,
    cfg: &DpIdentConfig,
    names: &[String; N_THETA],
    estimation: &[RunData<'_>],
    held_out: &[RunData<'_>],
    progress: &mut dyn Progress,
) -> Result<RefineOutcome, IdentifyError> {
    let all: Vec<usize> = (0..N_THETA)
        .filter(|&p| p < 5 || cfg.thrust.uses(p - 5))
        .collect();
    let mut out = RefineOutcome::default();
    let kept = |why: String| format!("{why}; the staged EKF's θ″ and std are kept");
    let r = match refine_dp_ship(
        cfg,
        estimation,
        &all,
        &id.theta,
        &RefineSettings::default(),
        progress,
    ) {
        Ok(r) => r,
        Err(EkfError::Cancelled) => return Err(IdentifyError::Cancelled),
        Err(e) => {
            let why = format!("The prediction-error refinement failed ({e})");
            out.record = Some(not_run(id, &why));
            out.findings.push(kept(why));
            return Ok(out);
        }
    };
    let fit = &r.refinement;
    // The record of a refinement that ran, whether taken or not.
    let ran = |why: Option<String>, held_change: Option<f64>| DpRefinementDoc {
        applied: why.is_none(),
        reason: why,
        iterations: u32::try_from(fit.iterations).unwrap_or(u32::MAX),
        variance_ratio: Some(fit.variance_ratio).filter(|v| v.is_finite()),
        // Only when every factor is a number (a failed pass may leave NaN).
        std_inflation: if fit.inflation.iter().all(|f| f.is_finite()) {
            let mut per_theta = vec![1.0; N_THETA];
            for (c, &p) in all.iter().enumerate() {
                per_theta[p] = fit.inflation[c];
            }
            per_theta
        } else {
            Vec::new()
        },
        held_out_nll_change: held_change.filter(|v| v.is_finite()),
        ..not_run(id, "")
    };
    if !fit.converged || r.theta.iter().chain(&r.theta_std).any(|v| !v.is_finite()) {
        let why = format!(
            "The prediction-error refinement did not converge in {} step(s) (predicted decrease {} left)",
            fit.iterations,
            sig3(fit.decrement)
        );
        out.record = Some(ran(Some(why.clone()), None));
        out.findings.push(kept(why));
        return Ok(out);
    }
    let held = match (
        dp_predictor_nll(cfg, held_out, &id.theta),
        dp_predictor_nll(cfg, held_out, &r.theta),
    ) {
        (Ok(before), Ok(after)) => Some((before, after)),
        _ => None,
    };
    if let Some((before, after)) = held
        && (after.is_nan() || after > before + HELD_OUT_TOLERANCE)
    {
        let why = format!(
            "The prediction-error refinement predicts the held-out runs worse (their negative log-likelihood rises by {})",
            sig3(after - before)
        );
        out.record = Some(ran(Some(why.clone()), Some(after - before)));
        out.findings.push(kept(why));
        return Ok(out);
    }
    out.record = Some(ran(None, held.map(|(b, a)| a - b)));
    let ekf = id.theta;
    let inflated: Vec<String> = all
        .iter()
        .enumerate()
        .filter(|&(c, _)| fit.inflation[c] > 1.05)
        .map(|(c, &p)| format!("θ″{} ({}) ×{}", p + 1, names[p], sig3(fit.inflation[c])))
        .collect();
    out.notes.push(format!(
        "Refined after the staging: all {} θ″ jointly on the {} estimation block(s) by prediction error (Levenberg–Marquardt on the negative log-likelihood of the Kalman predictor's innovations, forward sensitivities), {} step(s), from the EKF's θ″ = [{}].{}",
        all.len(),
        estimation.len(),
        fit.iterations,
        all.iter().map(|&p| sig3(ekf[p])).collect::<Vec<_>>().join(", "),
        match held {
            Some((b, a)) => format!(
                " Held-out negative log-likelihood changed by {}.",
                sig3(a - b)
            ),
            None => String::new(),
        }
    ));
    out.notes.push(format!(
        "θ″ std: the Cramér–Rao bound (inverse Gauss–Newton Hessian) under the stated noise model, inflated where the innovations' variance ratio ({}) or their Newey–West sandwich say the noise is larger or coloured{}.",
        sig3(fit.variance_ratio),
        if inflated.is_empty() {
            " (not needed here)".to_string()
        } else {
            format!(": {}", inflated.join(", "))
        }
    ));
    let ship = DpShip::from_theta(cfg.m, cfg.thrust.clone(), &r.theta);
    id.theta = r.theta;
    id.theta_std = r.theta_std;
    id.a = ship.state_space_a();
    id.b = ship.state_space_b();
    id.ship = ship;
    Ok(out)
}
