//! Nyquist.

use super::*;

/// A command alternating every log sample (a 20 Hz controller seen at
/// 10 Hz) warns; a slow PRBS does not.
#[test]
fn nyquist_warning_fires_for_alternating_input_only() {
    let n = 4000;
    let mut rng = Rng::new(2);
    let alt: Vec<f64> = (0..n)
        .map(|k| if k % 2 == 0 { 1.0 } else { -1.0 } + 0.3 * rng.normal())
        .collect();
    let slow = rng.binary(n, 20, 1.0);
    let v = add_noise(&first_order(&slow, 0.9, 0.1), &mut rng, 0.01);
    let rec = record(10.0, vec![("tau_K", alt), ("tau_Y", slow), ("v", v)]);
    let mut spec = QualitySpec::new(names(&["tau_K", "tau_Y"]), names(&["v"]))
        .with_dof(Dof::Sway, "tau_Y", "v")
        .with_dof(Dof::Roll, "tau_K", "v");
    let r = quality_report(&rec, &spec).unwrap();
    let k = &r.inputs[0];
    assert!(
        k.nyquist.power_fraction > 0.5,
        "{}",
        k.nyquist.power_fraction
    );
    assert_eq!(k.nyquist.band_hz, [4.0, 5.0]);
    let w = k.nyquist.warning.as_deref().unwrap();
    assert!(
        w.starts_with("tau_K has power near the 5 Hz Nyquist frequency of the log"),
        "{w}"
    );
    assert!(w.contains("e.g. a 20 Hz controller logged at 10 Hz"), "{w}");
    assert!(w.contains("inputs between samples are unknown"), "{w}");
    let y = &r.inputs[1];
    assert!(
        y.nyquist.power_fraction < 0.01,
        "{}",
        y.nyquist.power_fraction
    );
    assert!(y.nyquist.warning.is_none());
    assert!(r.warnings.iter().any(|s| s.starts_with("tau_K has power")));
    let roll = &r.dofs[1];
    assert!(roll.evidence.nyquist_warning);
    assert_ne!(roll.verdict, Verdict::Good);
    assert!(
        roll.reason
            .contains("log the inputs at the controller rate"),
        "{}",
        roll.reason
    );

    // A known controller rate is quoted.
    spec.controller_rate_hz = Some(20.0);
    let r = quality_report(&rec, &spec).unwrap();
    let w = r.inputs[0].nyquist.warning.as_deref().unwrap();
    assert!(w.contains("the controller ran at 20 Hz"), "{w}");
}

/// White noise at the log rate has 20 % of its power in the top 20 % of the
/// band: it warns too (nothing says it did not change between samples),
/// so such a DOF is at best Weak.
#[test]
fn white_input_at_the_log_rate_warns() {
    let mut rng = Rng::new(17);
    let x = rng.white(36_000, 1.0);
    let y = add_noise(&first_order(&x, 0.9, 0.1), &mut rng, 1e-3);
    let rec = record(10.0, vec![("tau_Y", x), ("v", y)]);
    let r = quality_report(&rec, &sway_spec()).unwrap();
    let f = r.inputs[0].nyquist.power_fraction;
    assert!((f - 0.2).abs() < 0.02, "{f}");
    assert_eq!(r.dofs[0].verdict, Verdict::Weak, "{}", r.dofs[0].reason);
}
