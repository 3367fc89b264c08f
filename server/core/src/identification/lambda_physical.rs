//! Physical structure enforced on each λ-identified sub-model: M symmetric
//! positive definite and D̄ dissipative (Fossen 2011, property 6.1; the
//! thesis's assumption under eq. 2.10). An estimate that violates them is
//! replaced by its nearest physical pair ([`project_physical`]) and the cost
//! is stated as the rise of the 1-step residual on the estimation data, so
//! a stored model can always be simulated without gaining energy.

use nalgebra::{DMatrix, DVector};

use super::error::IdentifyError;
use super::lambda_coriolis::coriolis_jacobian;
use crate::estimation::lambda::{Experiment, LambdaEstimate};
use crate::models::{LinearVesselModel, project_physical};
use crate::planning::dof::Dof;

/// Relative tolerance of the structure check (symmetry, dissipativity).
const TOL: f64 = 1e-3;

/// The sub-model to store and what was done to it.
pub(crate) struct Enforced {
    pub model: LinearVesselModel,
    pub findings: Vec<String>,
}

/// Σ of squared 1-step residuals per DOF over the experiments.
fn one_step_rss(model: &LinearVesselModel, exps: &[Experiment]) -> Option<Vec<f64>> {
    let n = model.dofs().len();
    let mut rss = vec![0.0; n];
    for e in exps {
        let d = model.discretize(e.h).ok()?;
        for k in 0..e.nu.nrows().saturating_sub(1) {
            let x = e.nu.row(k).transpose();
            let u = e.gamma.row(k).transpose();
            let r = e.nu.row(k + 1).transpose() - d.step(&x, &u);
            for (acc, v) in rss.iter_mut().zip(r.iter()) {
                *acc += v * v;
            }
        }
    }
    rss.iter().all(|v| v.is_finite()).then_some(rss)
}

fn percent(x: f64) -> String {
    format!("{:.1} %", 100.0 * x)
}

/// The stored sub-model at `speed` from the estimate `est` with load
/// `load`, projected onto the physical set when it is not physical. With
/// `coriolis`, the damping checked and projected is D = D̄ − J_C(M, u₀) —
/// at speed D̄ carries C(ν)'s linearization, whose symmetric part is not
/// definite (the Munk moment), and only D must dissipate.
pub(crate) fn enforce(
    dofs: &[Dof],
    est: &LambdaEstimate,
    load: &DVector<f64>,
    exps: &[Experiment],
    speed: f64,
    coriolis: bool,
) -> Result<Enforced, IdentifyError> {
    let at = |m: &DMatrix<f64>, d: &DMatrix<f64>| {
        LinearVesselModel::new(dofs.to_vec(), m.clone(), d.clone())
            .and_then(|x| x.with_load(load.clone()))
    };
    let n = dofs.len();
    let jc = |m: &DMatrix<f64>| {
        coriolis
            .then(|| coriolis_jacobian(m, dofs, speed))
            .flatten()
            .unwrap_or_else(|| DMatrix::zeros(n, n))
    };
    let j0 = jc(&est.m);
    let p = project_physical(&est.m, &(&est.d_bar - &j0));
    let asym = {
        let norm = est.m.norm();
        if norm > 0.0 {
            (&est.m - est.m.transpose()).norm() / norm
        } else {
            0.0
        }
    };
    let raw = at(&est.m, &est.d_bar);
    let mut violations = Vec::new();
    if let Err(e) = &raw {
        violations.push(e.to_string());
    }
    if asym > TOL {
        violations.push(format!("M is not symmetric (‖M − Mᵀ‖/‖M‖ = {asym:.3})"));
    }
    if p.m_raised > 0 {
        violations.push(format!(
            "M has {} eigenvalue(s) that are not clearly positive",
            p.m_raised
        ));
    }
    if p.d_removed > 0 {
        let what = if coriolis {
            "the damping D = D̄ − J_C(M, u₀)"
        } else {
            "D̄"
        };
        violations.push(format!(
            "{what} would feed energy into the vehicle in {} direction(s)",
            p.d_removed
        ));
    }
    if violations.is_empty() {
        return Ok(Enforced {
            model: raw.map_err(|e| IdentifyError::invalid("model", e.to_string()))?,
            findings: Vec::new(),
        });
    }
    let d_bar = &p.d_bar + jc(&p.m);
    let model = at(&p.m, &d_bar).map_err(|e| {
        IdentifyError::invalid("model", format!("at {speed:.2} m/s, after projection: {e}"))
    })?;
    let cost = match (
        raw.ok().and_then(|r| one_step_rss(&r, exps)),
        one_step_rss(&model, exps),
    ) {
        (Some(before), Some(after)) => {
            let parts: Vec<String> = dofs
                .iter()
                .zip(before.iter().zip(&after))
                .filter(|(_, (b, a))| **b > 0.0 && (**a - **b) / **b > 1e-4)
                .map(|(d, (b, a))| format!("{} +{}", d.name(), percent((a - b) / b)))
                .collect();
            if parts.is_empty() {
                "the 1-step fit on the estimation data is unchanged".to_string()
            } else {
                format!(
                    "1-step residual sum of squares on the estimation data: {}",
                    parts.join(", ")
                )
            }
        }
        _ => "the unconstrained estimate could not be simulated, so its fit is not compared".into(),
    };
    Ok(Enforced {
        model,
        findings: vec![format!(
            "at {speed:.2} m/s the estimate was not physical ({}); stored the nearest physical M and D̄ instead (M changed by {}, D̄ by {}); cost: {cost}",
            violations.join("; "),
            percent(p.m_change),
            percent((&d_bar - &est.d_bar).norm() / est.d_bar.norm().max(f64::MIN_POSITIVE)),
        )],
    })
}
