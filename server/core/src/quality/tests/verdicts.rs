//! Verdicts.

use super::*;

/// A PRBS-like force through a first-order lag, measured with little
/// noise: Good, and the reason says so with its numbers.
#[test]
fn well_excited_first_order_dof_is_good() {
    let rec = sway_log(36_000, 1e-4, 7);
    let r = quality_report(&rec, &sway_spec()).unwrap();
    let d = &r.dofs[0];
    assert_eq!(d.verdict, Verdict::Good, "{}", d.reason);
    assert!(
        d.reason.starts_with("sway: good — coherence ≥ 0.8 over "),
        "{}",
        d.reason
    );
    assert!(d.reason.contains("PE order ≥ 24"), "{}", d.reason);
    assert_eq!(d.evidence.pe_order, PE_CAP);
    assert!(d.evidence.median_coherence.unwrap() > 0.9);
    assert!(!d.evidence.nyquist_warning);
    // With so little noise a first-order DOF makes v(t-1), v(t-2) and
    // tau_Y(t-1) nearly dependent (na = 2 is one more than it needs): a
    // direction on the output lags, not held against the log.
    assert!(!d.evidence.input_deficient);
    assert!(
        r.regressor
            .deficient_directions
            .iter()
            .all(|dd| dd.input_share < MIN_INPUT_SHARE)
    );
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
    // Default nperseg: the rule of `default_quality_nperseg`.
    assert_eq!(r.welch.nperseg, default_quality_nperseg(36_000));
    assert_eq!(r.welch.nperseg, 4096);
}

/// A force that never moved: Insufficient, and the reason names the DOF,
/// the input, the evidence and the action.
#[test]
fn constant_input_is_insufficient_and_named() {
    let mut rng = Rng::new(9);
    let n = 6000;
    let x = vec![5000.0; n];
    let y = rng.white(n, 0.01);
    let rec = record(10.0, vec![("tau_Y", x), ("v", y)]);
    // Two lags, so each dead channel removes one direction per lag.
    let mut spec = sway_spec();
    spec.regressor_lags = 2;
    let r = quality_report(&rec, &spec).unwrap();
    let d = &r.dofs[0];
    assert_eq!(d.verdict, Verdict::Insufficient);
    assert!(
        d.reason
            .starts_with("sway: the input tau_Y barely moved (PE order 0, mean 5000, RMS 0)"),
        "{}",
        d.reason
    );
    assert!(
        d.reason.contains("holds no dynamic information"),
        "{}",
        d.reason
    );
    // No plan: nothing to repeat, and not exciting a DOF is no failure of the run.
    assert!(
        d.reason.contains("fly a run that excites it") && !d.reason.contains("planned schedule"),
        "{}",
        d.reason
    );
    assert!(r.inputs[0].pe_order < MIN_PE_ORDER);
    assert_eq!(r.inputs[0].rms, 0.0);
    assert_eq!(r.inputs[0].mean, 5000.0);
    // Its regressor columns are dead: two directions of the full model.
    assert_eq!(r.regressor.identifiable, 2);
    assert!(
        r.regressor
            .deficient_directions
            .iter()
            .all(|d| d.columns.iter().all(|c| c.column.starts_with("tau_Y(t-"))),
        "{:?}",
        r.regressor.deficient_directions
    );
}

/// The same DOF drowned in output noise: coherence decides, not Good.
#[test]
fn heavy_output_noise_is_insufficient_by_coherence() {
    let rec = sway_log(36_000, 0.05, 11);
    let r = quality_report(&rec, &sway_spec()).unwrap();
    let d = &r.dofs[0];
    assert_eq!(d.verdict, Verdict::Insufficient, "{}", d.reason);
    assert!(d.evidence.median_coherence.unwrap() < MIN_MEDIAN_COHERENCE);
    assert!(
        d.reason.starts_with("sway: median coherence "),
        "{}",
        d.reason
    );
    assert!(d.reason.contains("from tau_Y to v"), "{}", d.reason);
    assert!(
        d.reason
            .contains("fly it again with twice the amplitude or a slower PRBS clock"),
        "{}",
        d.reason
    );
}

/// Moderate noise on a strongly low-passed output: coherence ≥ 0.5 over
/// most of the input's band but ≥ 0.8 only at low frequency — Weak, and
/// the reason says where coherence falls short.
#[test]
fn coherence_good_over_part_of_the_band_is_weak() {
    let mut rng = Rng::new(21);
    let n = 36_000;
    let x = rng.binary(n, 2, 1.0);
    // |H| falls 26 dB over the input's band (0–4 Hz).
    let y = add_noise(&first_order(&x, 0.95, 0.05), &mut rng, 0.04);
    let rec = record(10.0, vec![("tau_Y", x), ("v", y)]);
    let r = quality_report(&rec, &sway_spec()).unwrap();
    let d = &r.dofs[0];
    let frac = d.evidence.coherent_fraction.unwrap();
    assert!(frac < MIN_COHERENT_FRACTION, "{frac}");
    assert!(
        d.evidence.median_coherence.unwrap() >= MIN_MEDIAN_COHERENCE,
        "{}",
        d.reason
    );
    assert_eq!(d.verdict, Verdict::Weak, "{}", d.reason);
    assert!(
        d.reason.starts_with("sway: coherence ≥ 0.8 over only "),
        "{}",
        d.reason
    );
    assert!(
        d.reason.contains("(coherence below 0.8 above "),
        "{}",
        d.reason
    );
    assert!(!d.evidence.nyquist_warning);
}

/// A record too short for two Welch segments cannot show coherence.
#[test]
fn fewer_than_two_segments_is_insufficient() {
    let rec = sway_log(80, 1e-4, 5);
    let r = quality_report(&rec, &sway_spec()).unwrap();
    assert_eq!(r.welch.n_segments, 1);
    let d = &r.dofs[0];
    assert_eq!(d.verdict, Verdict::Insufficient, "{}", d.reason);
    assert!(d.reason.contains("1 Welch segment(s)"), "{}", d.reason);
    assert!(d.reason.contains("log at least 9.6 s"), "{}", d.reason);
}
