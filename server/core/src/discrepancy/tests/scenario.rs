//! Sea-trial scenarios for the proof: a truth with concealed effects,
//! estimation and validation runs, and a baseline identified without them.

use nalgebra::DMatrix;

use super::truth::{Truth, commands};
use crate::discrepancy::candidates::Effect;
use crate::discrepancy::data::{Baseline, Record, Restoring};
use crate::discrepancy::fit::Prepared;
use crate::discrepancy::model::{AugmentedModel, ModelTerm};
use crate::planning::examples::surveyor_rov;
use crate::planning::{Dof, VesselProfile};

/// Sample time of the proof runs: the thesis's 10 Hz logger.
pub const H: f64 = 0.1;

/// Truth, runs and baseline of one case.
pub struct Scenario {
    pub profile: VesselProfile,
    pub truth: Truth,
    pub est: Vec<Record>,
    pub val: Vec<Record>,
    pub baseline: Baseline,
}

/// Runs `n_est` estimation and `n_val` validation runs of `duration_s`
/// on `truth` and identifies a diagonal baseline from the estimation runs.
pub fn scenario(truth: Truth, seed: u64, n_est: usize, n_val: usize, duration_s: f64) -> Scenario {
    let profile = surveyor_rov();
    let n = (duration_s / H).round() as usize;
    let mut est = Vec::new();
    let mut val = Vec::new();
    for r in 0..n_est + n_val {
        let tau = commands(&profile, n, H, r, seed);
        let psi0 = 0.7 * r as f64;
        let name = if r < n_est {
            format!("est{r}")
        } else {
            format!("val{}", r - n_est)
        };
        let rec = truth.run(
            &name,
            &tau,
            H,
            psi0,
            Some(crate::rng::mix(seed ^ (1000 + r as u64))),
        );
        if r < n_est {
            est.push(rec)
        } else {
            val.push(rec)
        }
    }
    let restoring = Restoring {
        tether_pitch_moment: 0.0,
        ..truth.restoring
    };
    let baseline = fit_diagonal_baseline(&Dof::ALL, restoring, &est);
    Scenario {
        profile,
        truth,
        est,
        val,
        baseline,
    }
}

/// Least-squares λ-filter baseline, diagonal M and D̄ per DOF row.
pub fn fit_diagonal_baseline(dofs: &[Dof], restoring: Restoring, runs: &[Record]) -> Baseline {
    let n = dofs.len();
    let start = Baseline {
        dofs: dofs.to_vec(),
        m: DMatrix::identity(n, n),
        d_bar: DMatrix::identity(n, n),
        restoring,
    };
    let prep = Prepared::new(&start, runs, 0.5, 25, 30).expect("runs long enough");
    let all: Vec<usize> = (0..runs.len()).collect();
    let f = prep
        .fit(&[], &(0..n).collect::<Vec<_>>(), &all, false)
        .expect("fit");
    let mut b = start.clone();
    for (ri, &r) in f.rows.iter().enumerate() {
        b.m[(r, r)] = f.base[ri].0[0];
        b.d_bar[(r, r)] = f.base[ri].1[0];
    }
    b
}

/// The truth written in the model's own form (same recorded-η
/// convention): the upper bound a discovered model can reach.
pub fn true_model(t: &Truth) -> AugmentedModel {
    let m = DMatrix::from_diagonal(&nalgebra::DVector::from_row_slice(&t.m));
    let d = DMatrix::from_diagonal(&nalgebra::DVector::from_row_slice(&t.d));
    let term = |effect, coefficients: Vec<f64>, shape: Option<f64>| ModelTerm {
        effect,
        coefficients,
        covariance: vec![],
        shape,
        shape_std: None,
    };
    let mut terms = Vec::new();
    for dof in Dof::ALL {
        let i = dof.index();
        if t.quad[i] != 0.0 {
            terms.push(term(
                Effect::QuadraticDamping { dof },
                vec![t.quad[i]],
                None,
            ));
        }
        if t.constant[i] != 0.0 {
            terms.push(term(
                Effect::ConstantLoad { dof },
                vec![t.constant[i]],
                None,
            ));
        }
        if let Some(l) = t.lag[i] {
            terms.push(term(Effect::ActuatorLag { dof }, vec![], Some(l)));
        }
        if t.delay[i] > 0 {
            terms.push(term(
                Effect::InputDelay { dof },
                vec![],
                Some(t.delay[i] as f64),
            ));
        }
        if let Some(l) = t.saturation[i] {
            terms.push(term(Effect::Saturation { dof }, vec![], Some(l)));
        }
    }
    if t.coriolis {
        terms.push(term(Effect::CoriolisFromM, vec![1.0], None));
    }
    if let Some([vn, ve]) = t.current {
        terms.push(term(Effect::Current, vec![vn, ve], None));
    }
    AugmentedModel::new(
        Dof::ALL.to_vec(),
        m.clone(),
        d.clone(),
        t.restoring,
        m,
        d,
        terms,
    )
}
