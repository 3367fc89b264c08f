//! Errors and serialization.

use super::*;

#[test]
fn invalid_requests_are_errors_naming_the_field() {
    let rec = sway_log(2000, 1e-3, 1);
    let field = |rec: &UniformRecord, spec: &QualitySpec| {
        quality_report(rec, spec).unwrap_err().field().to_owned()
    };
    let mut s = sway_spec();
    s.inputs.push("tau_X".into());
    let e = quality_report(&rec, &s).unwrap_err();
    assert_eq!(e.field(), "inputs[1]");
    assert_eq!(e.message(), "column `tau_X` is not in the log");
    let s = QualitySpec::new(vec![], names(&["v"]));
    assert_eq!(field(&rec, &s), "inputs");
    let s = QualitySpec::new(names(&["tau_Y", "tau_Y"]), names(&["v"]));
    assert_eq!(field(&rec, &s), "inputs[1]");
    let s = sway_spec().with_dof(Dof::Yaw, "tau_N", "v");
    assert_eq!(field(&rec, &s), "dofs[1].input");
    let s = sway_spec().with_dof(Dof::Yaw, "tau_Y", "r");
    assert_eq!(field(&rec, &s), "dofs[1].output");
    let mut s = sway_spec();
    s.nperseg = Some(2001);
    assert_eq!(field(&rec, &s), "nperseg");
    s.nperseg = Some(0);
    assert_eq!(field(&rec, &s), "nperseg");
    let mut big = rec.clone();
    big.data[0] = vec![0.0; 2000];
    let mut s = QualitySpec::new(names(&["tau_Y"]), names(&["v"]));
    s.nperseg = Some(2000);
    assert!(quality_report(&big, &s).is_ok());
    s.planned = Some(PlannedReference {
        sample_rate_hz: 1e-3,
        columns: vec![("v".into(), "slow".into(), vec![1.0; 100])],
    });
    assert_eq!(field(&big, &s), "planned.columns[0]");
    let mut s = sway_spec();
    s.regressor_lags = 0;
    assert_eq!(field(&rec, &s), "regressor_lags");
    s.regressor_lags = 200;
    assert_eq!(field(&rec, &s), "regressor_lags");
    let mut s = sway_spec();
    s.controller_rate_hz = Some(-1.0);
    assert_eq!(field(&rec, &s), "controller_rate_hz");
    let mut s = sway_spec();
    s.planned = Some(PlannedReference {
        sample_rate_hz: 0.0,
        columns: vec![],
    });
    assert_eq!(field(&rec, &s), "planned.sample_rate_hz");
    s.planned = Some(PlannedReference {
        sample_rate_hz: 1.0,
        columns: vec![("w".into(), "p".into(), vec![1.0, 2.0])],
    });
    assert_eq!(field(&rec, &s), "planned.columns[0]");
    s.planned = Some(PlannedReference {
        sample_rate_hz: 1.0,
        columns: vec![("v".into(), "p".into(), vec![1.0])],
    });
    assert_eq!(field(&rec, &s), "planned.columns[0]");

    let mut bad = rec.clone();
    bad.data[1][1234] = f64::NAN;
    match quality_report(&bad, &sway_spec()).unwrap_err() {
        QualityError::NonFinite { field, index, .. } => {
            assert_eq!((field.as_str(), index), ("v", 1234))
        }
        e => panic!("{e:?}"),
    }
    // Outside the valid blocks a NaN is fine.
    bad.valid = vec![0..1234, 1235..2000];
    assert!(quality_report(&bad, &sway_spec()).is_ok());

    let mut r2 = rec.clone();
    r2.sample_rate_hz = f64::NAN;
    assert_eq!(field(&r2, &sway_spec()), "sample_rate_hz");
    let mut r2 = rec.clone();
    r2.valid = vec![];
    assert_eq!(field(&r2, &sway_spec()), "valid");
    r2.valid = vec![0..10, 5..20];
    assert_eq!(field(&r2, &sway_spec()), "valid[1]");
    r2.valid = vec![0..2001];
    assert_eq!(field(&r2, &sway_spec()), "valid[0]");
    let mut r2 = rec.clone();
    r2.data[1].pop();
    assert_eq!(field(&r2, &sway_spec()), "data[1]");
    let e = quality_report(&r2, &sway_spec()).unwrap_err();
    assert!(e.to_string().starts_with("data[1]: "), "{e}");
}

#[test]
fn report_serializes_in_snake_case() {
    let rec = sway_log(3000, 1e-4, 2);
    let r = quality_report(&rec, &sway_spec()).unwrap();
    let v = serde_json::to_value(&r).unwrap();
    for key in [
        "sample_rate_hz",
        "freqs_hz",
        "inputs",
        "outputs",
        "pairs",
        "regressor",
        "adherence",
        "dofs",
        "warnings",
        "welch",
    ] {
        assert!(v.get(key).is_some(), "{key}");
    }
    assert_eq!(v["dofs"][0]["dof"], "sway");
    assert_eq!(v["dofs"][0]["verdict"], "good");
    assert!(v["pairs"][0]["h1_phase_unwrapped_rad"].is_array());
    assert!(v["inputs"][0]["nyquist"]["power_fraction"].is_number());
    assert!(v["regressor"]["singular_values"].is_array());
    let spec: QualitySpec = serde_json::from_str(
        r#"{"inputs":["tau_Y"],"outputs":["v"],"dofs":[{"dof":"sway","input":"tau_Y","output":"v"}]}"#,
    )
    .unwrap();
    assert_eq!(spec, sway_spec());
}

/// Unit doubts replace every verdict by `check_units` naming them, keep the
/// evidence; no doubts leave the verdicts as computed.
#[test]
fn unit_doubts_replace_every_verdict_and_none_leave_them() {
    let report = quality_report(&sway_log(6000, 0.01, 3), &sway_spec()).unwrap();
    let mut v = report.dofs.clone();
    units_first(&mut v, &[]);
    assert_eq!(v, report.dofs);
    assert_eq!(v[0].verdict, Verdict::Good, "{}", v[0].reason);
    units_first(
        &mut v,
        &["t looks like milliseconds", "phi looks like degrees"],
    );
    for (after, before) in v.iter().zip(&report.dofs) {
        assert_eq!(after.verdict, Verdict::CheckUnits);
        assert!(
            after
                .reason
                .starts_with("sway: check the log's units first"),
            "{}",
            after.reason
        );
        assert!(
            after
                .reason
                .contains("milliseconds; phi looks like degrees")
        );
        assert_eq!(after.evidence, before.evidence);
    }
}
