//! Plan adherence.

use super::*;

/// The logged force is the schedule (planned at 20 Hz) started 57.3 s into
/// a 10 Hz log, through a slight lag and noise: the lag is found, and the
/// run is followed. Flown at half amplitude it is not, and the DOF is Weak.
#[test]
fn plan_adherence_finds_the_lag_and_flags_half_amplitude() {
    let mut rng = Rng::new(33);
    let plan_fs = 20.0;
    let plan = rng.binary(6000, 40, 1000.0); // 300 s, 2 s clock
    let plan_at = |t: f64| plan[((t * plan_fs).round() as usize).min(plan.len() - 1)];
    let n = 4000; // 400 s at 10 Hz
    let lag_s = 57.3;
    let logged = |gain: f64, rng: &mut Rng| -> Vec<f64> {
        let raw: Vec<f64> = (0..n)
            .map(|k| {
                let t = k as f64 / 10.0 - lag_s;
                if (0.0..300.0).contains(&t) {
                    gain * plan_at(t)
                } else {
                    0.0
                }
            })
            .collect();
        add_noise(&first_order(&raw, 0.3, 0.7), rng, 20.0)
    };
    for (gain, followed) in [(1.0, true), (0.5, false)] {
        let x = logged(gain, &mut rng);
        let v = add_noise(&first_order(&x, 0.95, 5e-6), &mut rng, 1e-4);
        let rec = record(10.0, vec![("tau_Y", x), ("v", v)]);
        let mut spec = sway_spec();
        spec.planned = Some(PlannedReference {
            sample_rate_hz: plan_fs,
            columns: vec![("tau_Y".into(), "sway_prbs".into(), plan.clone())],
        });
        let r = quality_report(&rec, &spec).unwrap();
        let a = &r.adherence[0];
        assert!((a.lag_s - lag_s).abs() <= 0.15, "lag {}", a.lag_s);
        assert!(a.correlation > 0.95, "r {}", a.correlation);
        assert!(
            (a.amplitude_ratio.unwrap() - gain).abs() < 0.05 * gain,
            "ratio {:?}",
            a.amplitude_ratio
        );
        assert!((a.coverage - 1.0).abs() < 1e-9, "coverage {}", a.coverage);
        assert_eq!(a.followed, followed, "{}", a.message);
        let d = &r.dofs[0];
        assert_eq!(d.evidence.plan_followed, Some(followed));
        if followed {
            assert!(a.nrmse.unwrap() < 0.3, "nrmse {:?}", a.nrmse);
            assert_eq!(d.verdict, Verdict::Good, "{}", d.reason);
        } else {
            assert!(a.message.contains("amplitude ratio 0.49"), "{}", a.message);
            assert!(a.message.contains("outside 0.7–1.3"), "{}", a.message);
            assert_eq!(d.verdict, Verdict::Weak, "{}", d.reason);
            assert!(
                d.reason.contains("did not follow the planned sway_prbs"),
                "{}",
                d.reason
            );
            assert!(r.warnings.iter().any(|w| w.contains("sway_prbs")));
        }
    }
}

/// A log that ends half-way through the schedule: coverage says so.
#[test]
fn plan_coverage_counts_the_logged_part() {
    let mut rng = Rng::new(44);
    let plan = rng.binary(3000, 20, 1.0); // 300 s at 10 Hz
    let n = 1500;
    let x: Vec<f64> = (0..n)
        .map(|k| if k >= 300 { plan[k - 300] } else { 0.0 })
        .collect();
    let v = add_noise(&first_order(&x, 0.9, 0.1), &mut rng, 1e-3);
    let rec = record(10.0, vec![("tau_Y", x), ("v", v)]);
    let mut spec = sway_spec();
    spec.planned = Some(PlannedReference {
        sample_rate_hz: 10.0,
        columns: vec![("tau_Y".into(), "p".into(), plan)],
    });
    let r = quality_report(&rec, &spec).unwrap();
    let a = &r.adherence[0];
    assert!((a.lag_s - 30.0).abs() < 1e-9, "{}", a.lag_s);
    assert!(
        (a.coverage - 1200.0 / 3000.0).abs() < 1e-9,
        "{}",
        a.coverage
    );
    assert!(a.correlation > 0.999);
    assert!(!a.followed);
    assert!(a.message.contains("coverage 40 % < 90 %"), "{}", a.message);
}
