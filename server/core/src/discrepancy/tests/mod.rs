//! The proof: concealed effects in a 6-DOF truth, a baseline identified
//! without them, discovery run on the result.

mod proof;
mod scenario;
mod truth;

use scenario::scenario;
use truth::Truth;

use crate::discrepancy::candidates::Effect;
use crate::discrepancy::fit::{Prepared, Spec};
use crate::planning::Dof;
use crate::planning::examples::surveyor_rov;

#[test]
fn clean_truth_gives_the_true_baseline() {
    let t = Truth::from_profile(&surveyor_rov());
    let s = scenario(t.clone(), 1, 2, 0, 90.0);
    for i in 0..6 {
        let (m, d) = (s.baseline.m[(i, i)], s.baseline.d_bar[(i, i)]);
        assert!((m / t.m[i] - 1.0).abs() < 0.03, "dof {i}: M {m} vs {}", t.m[i]);
        assert!((d / t.d[i] - 1.0).abs() < 0.03, "dof {i}: D {d} vs {}", t.d[i]);
    }
}

#[test]
fn quadratic_damping_coefficient_is_recovered_with_honest_uncertainty() {
    let mut t = Truth::from_profile(&surveyor_rov());
    t.quad[0] = 3000.0;
    let s = scenario(t, 2, 3, 0, 90.0);
    let prep = Prepared::new(&s.baseline, &s.est, 0.5, 25, 30).unwrap();
    let all: Vec<usize> = (0..s.est.len()).collect();
    let spec = Spec { effect: Effect::QuadraticDamping { dof: Dof::Surge }, shape: None };
    let f = prep.fit(&[spec], &[], &all, true).unwrap();
    let c = f.theta[0][0];
    let sd = f.theta_cov(0).unwrap()[(0, 0)].sqrt();
    eprintln!("quad {c} ± {sd}, base {:?}", f.base);
    assert!((c - 3000.0).abs() < 0.05 * 3000.0 + 3.0 * sd, "{c} ± {sd}");
    assert!(sd < 300.0);
}


#[test]
#[ignore]
fn debug_current_truth_model() {
    use crate::discrepancy::model::{AugmentedModel, ModelTerm};
    use nalgebra::{DMatrix, DVector};
    let p = surveyor_rov();
    let mut t = Truth::from_profile(&p);
    t.current = Some([0.0, -0.2]);
    let s = scenario(t.clone(), 11, 3, 1, 120.0);
    let m = DMatrix::from_diagonal(&DVector::from_row_slice(&t.m));
    let d = DMatrix::from_diagonal(&DVector::from_row_slice(&t.d));
    let term = ModelTerm { effect: Effect::Current, coefficients: vec![0.0, -0.2], covariance: vec![], shape: None, shape_std: None };
    let model = AugmentedModel::new(Dof::ALL.to_vec(), m.clone(), d.clone(), t.restoring, m, d, vec![term]);
    let val = &s.val[0];
    let sim = model.simulate(val);
    let tr = scenario::true_free_run(&s, val, 0);
    for i in 0..6 {
        let a = crate::validation::nrmse_fit(val.nu.column(i).as_slice(), sim.column(i).as_slice());
        let b = crate::validation::nrmse_fit(val.nu.column(i).as_slice(), tr.column(i).as_slice());
        eprintln!("dof {i}: model {a:?} truth {b:?}");
    }
}

#[test]
#[ignore]
fn debug_current_case() {
    let o = proof::run_case(&[proof::Concealed::Current], 11);
    let m = &o.report.model;
    for i in 0..6 {
        eprintln!("row {i}: M {:?}\n       D {:?}", m.m[i], m.d_bar[i]);
    }
    eprintln!("terms {:?}", m.terms);
    for h in o.report.hypotheses.iter().take(8) {
        eprintln!("{} dBIC {:.0} z {:.1} cv {:?}", h.label, h.delta_bic, h.z, h.cv_gain);
    }
}
