//! The proof: concealed effects in a 6-DOF truth, a baseline identified
//! without them, discovery run on the result.

mod proof;

use crate::discrepancy::proof::scenario::{clean_truth, restoring_of, scenario};

use crate::discrepancy::candidates::Effect;
use crate::discrepancy::fit::{Prepared, Spec};
use crate::planning::Dof;
use crate::planning::examples::surveyor_rov;

#[test]
fn clean_truth_gives_the_true_baseline() {
    let t = clean_truth();
    let s = scenario(t.clone(), 1, 2, 0, 90.0);
    let d = t.damping.at(0.0);
    for i in 0..6 {
        let (bm, bd) = (s.baseline.m[(i, i)], s.baseline.d_bar[(i, i)]);
        assert!(
            (bm / t.m[(i, i)] - 1.0).abs() < 0.05,
            "dof {i}: M {bm} vs {}",
            t.m[(i, i)]
        );
        assert!(
            (bd / d[(i, i)] - 1.0).abs() < 0.05,
            "dof {i}: D {bd} vs {}",
            d[(i, i)]
        );
    }
}

#[test]
fn quadratic_damping_coefficient_is_recovered_with_honest_uncertainty() {
    let mut t = clean_truth();
    t.quadratic_damping[0] = 3000.0;
    let s = scenario(t, 2, 3, 0, 90.0);
    let prep = Prepared::new(&s.baseline, &s.est, 0.5, 25, 30).unwrap();
    let all: Vec<usize> = (0..s.est.len()).collect();
    let spec = Spec {
        effect: Effect::QuadraticDamping { dof: Dof::Surge },
        shape: None,
    };
    let f = prep.fit(&[spec], &[], &all, true).unwrap();
    let c = f.theta[0][0];
    let sd = f.theta_cov(0).unwrap()[(0, 0)].sqrt();
    eprintln!("quad {c} ± {sd}, base {:?}", f.base);
    assert!((c - 3000.0).abs() < 0.05 * 3000.0 + 3.0 * sd, "{c} ± {sd}");
    assert!(sd < 300.0);
}

/// A damping term must dissipate. With 3000 N·s²/m² of surge |u|u in the
/// truth it is significant; with the logged τ_X shifted so that the data
/// ask for −3000 (a hull that gains energy with speed) the fit says −3000
/// and the screen refuses it.
#[test]
fn a_damping_term_that_would_inject_energy_is_not_significant() {
    use crate::discrepancy::select::{Criteria, score};
    let mut t = clean_truth();
    t.quadratic_damping[0] = 3000.0;
    let s = scenario(t, 2, 3, 0, 90.0);
    let c = Criteria {
        min_z: 4.0,
        max_delta_bic: -10.0,
        min_cv_gain: 0.01,
        min_force_share: 0.02,
        cv_candidates: 5,
        max_lag_s: 3.0,
        max_delay_samples: 10.0,
        k_step: 10,
    };
    let effect = Effect::QuadraticDamping { dof: Dof::Surge };
    let all: Vec<usize> = (0..s.est.len()).collect();
    let prep = Prepared::new(&s.baseline, &s.est, 0.5, 25, 30).unwrap();
    let ok = score(&prep, &[], effect, &all, &c).unwrap();
    assert!(
        ok.fit.theta[0][0] > 2500.0 && ok.z >= 4.0,
        "{:?} z {}",
        ok.fit.theta,
        ok.z
    );
    let mut flipped = s.est.clone();
    for r in &mut flipped {
        for k in 0..r.len() {
            let u = r.nu[(k, 0)];
            r.tau[(k, 0)] -= 6000.0 * u.abs() * u;
        }
    }
    let prep = Prepared::new(&s.baseline, &flipped, 0.5, 25, 30).unwrap();
    let bad = score(&prep, &[], effect, &all, &c).unwrap();
    assert!(bad.fit.theta[0][0] < -2500.0, "{:?}", bad.fit.theta);
    assert_eq!(bad.z, 0.0);
    assert!(!bad.significant(&c));
}

#[test]
fn bad_input_is_a_typed_error_naming_the_field() {
    use crate::discrepancy::discover::{DiscoverySettings, discover};
    use crate::discrepancy::{Baseline, Record};
    use crate::estimation::NoProgress;
    let s = scenario(clean_truth(), 3, 2, 1, 60.0);
    let set = DiscoverySettings::default();
    let field = |b: &Baseline, e: &[Record], v: &[Record], st: &DiscoverySettings| {
        discover(b, e, v, st, &mut NoProgress)
            .err()
            .map(|e| e.field().to_string())
    };
    let mut b = s.baseline.clone();
    b.m = nalgebra::DMatrix::zeros(5, 5);
    assert_eq!(
        field(&b, &s.est, &s.val, &set).as_deref(),
        Some("baseline.m")
    );
    let short = vec![s.est[0].slice(0, 50, "short".into())];
    assert_eq!(
        field(&s.baseline, &short, &[], &set).as_deref(),
        Some("estimation_runs")
    );
    assert_eq!(
        field(&s.baseline, &[], &s.val, &set).as_deref(),
        Some("estimation_runs")
    );
    let bad = DiscoverySettings {
        k_step: 0,
        ..DiscoverySettings::default()
    };
    assert_eq!(
        field(&s.baseline, &s.est, &s.val, &bad).as_deref(),
        Some("settings.k_step")
    );
}

/// One bad run (a NaN, another sample time, too short) is set aside with
/// its reason in the summary; the others are still examined.
#[test]
fn one_bad_run_is_set_aside_and_named_not_fatal() {
    use crate::discrepancy::discover::{DiscoverySettings, discover};
    use crate::estimation::NoProgress;
    let s = scenario(clean_truth(), 3, 3, 1, 60.0);
    let mut e = s.est.clone();
    e[1].nu[(7, 2)] = f64::NAN;
    e[1].name = "nan-run".into();
    e.push(s.est[0].slice(0, 50, "short-run".into()));
    let mut v = s.val.clone();
    let mut odd = v[0].clone();
    odd.h = 0.2;
    odd.name = "odd-rate".into();
    v.push(odd);
    let r = discover(
        &s.baseline,
        &e,
        &v,
        &DiscoverySettings::default(),
        &mut NoProgress,
    )
    .expect("the good runs are examined");
    let said = r.summary.join("\n");
    for (name, field) in [
        ("nan-run", "estimation_runs[1].nu"),
        ("short-run", "estimation_runs[3].nu"),
        ("odd-rate", "validation_runs[1].h"),
    ] {
        assert!(
            said.contains(&format!("run '{name}' set aside (`{field}`")),
            "{said}"
        );
    }
}

#[test]
fn cancelling_stops_discovery() {
    use crate::discrepancy::DiscoveryError;
    use crate::discrepancy::discover::{DiscoverySettings, discover};
    use crate::estimation::Cancelled;
    let s = scenario(clean_truth(), 3, 2, 1, 60.0);
    let mut stop = |f: f64, _: &str| if f > 0.05 { Err(Cancelled) } else { Ok(()) };
    let r = discover(
        &s.baseline,
        &s.est,
        &s.val,
        &DiscoverySettings::default(),
        &mut stop,
    );
    assert_eq!(r.err(), Some(DiscoveryError::Cancelled));
}

#[test]
fn a_current_and_a_constant_load_are_told_apart_by_turning_the_vessel() {
    // At heading ψ₀ both models push surge with the same force; the
    // proposal must fly other headings, where the current's body-frame
    // force turns and the tether's does not.
    use crate::discrepancy::experiment::propose;
    use crate::discrepancy::model::{AugmentedModel, ModelTerm};
    let p = surveyor_rov();
    let t = clean_truth();
    let m = nalgebra::DMatrix::from_fn(6, 6, |i, j| t.m[(i, j)]);
    let dl = t.damping.at(0.0);
    let d = nalgebra::DMatrix::from_fn(6, 6, |i, j| dl[(i, j)]);
    let psi0: f64 = 0.4;
    let term = |effect, coefficients| ModelTerm {
        effect,
        coefficients,
        covariance: vec![],
        shape: None,
        shape_std: None,
    };
    let model = |terms| {
        AugmentedModel::new(
            Dof::ALL.to_vec(),
            m.clone(),
            d.clone(),
            restoring_of(&t),
            m.clone(),
            d.clone(),
            terms,
        )
    };
    let current = model(vec![term(
        Effect::Current,
        vec![0.2 * psi0.cos(), 0.2 * psi0.sin()],
    )]);
    // −D̄ν_c at ψ₀ is −d_u·0.2 in surge: the same constant load there.
    let load = model(vec![term(
        Effect::ConstantLoad { dof: Dof::Surge },
        vec![-d[(0, 0)] * 0.2],
    )]);
    let noise = vec![1e-3; 6];
    let e = propose(
        &p,
        &current,
        &load,
        ["current".into(), "tether".into()],
        &[Dof::Surge, Dof::Sway],
        &noise,
        psi0,
        0.1,
    )
    .unwrap();
    assert!(e.headings_deg.len() > 1, "{e:?}");
    assert!(
        e.predicted_separation_sigma > 10.0,
        "{}",
        e.predicted_separation_sigma
    );
    assert!(
        e.channels
            .iter()
            .all(|c| c.offset.abs() + c.amplitude <= c.limit + 1e-9)
    );
    let json = serde_json::to_string(&e).unwrap();
    assert!(json.contains("\"headings_deg\""));
}

#[test]
fn the_report_serializes_and_a_clean_vessel_reads_as_explained() {
    use crate::discrepancy::discover::{DiscoverySettings, discover};
    use crate::estimation::NoProgress;
    let s = scenario(clean_truth(), 21, 3, 1, 90.0);
    let r = discover(
        &s.baseline,
        &s.est,
        &s.val,
        &DiscoverySettings::default(),
        &mut NoProgress,
    )
    .unwrap();
    assert!(r.findings.is_empty() && r.ambiguities.is_empty());
    assert!(r.unexplained.is_empty(), "{:?}", r.unexplained);
    assert!(
        r.summary[0].contains("explains"),
        "{:?}",
        r.location.sentences
    );
    assert_eq!(r.validation.len(), 6);
    assert!(
        r.plots
            .iter()
            .all(|p| p.t.len() <= 400 && p.t.len() == p.after.len())
    );
    let json = serde_json::to_string(&r).unwrap();
    assert!(json.contains("\"location\"") && json.contains("\"hypotheses\""));
}
