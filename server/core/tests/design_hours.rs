//! Design for precision per ship-hour on the Surveyor ROV (the project's
//! own simulator and the thesis-like reference prior): the designed
//! campaign reaches, within the current plan's ship time, a D criterion the
//! rule-based plan needs at least twice the hours for — and the
//! identification itself confirms it: flown over noise realisations and
//! identified, the designed plan's parameters are at least as precise as
//! those of the rule-based plan repeated three times over (three times the
//! ship hours).

use seatrial_core::design::{
    PredictSettings, Prior, PriorSource, design_campaign, predict_precision,
};
use seatrial_core::estimation::NoProgress;
use seatrial_core::planning::examples::{surveyor_campaign, surveyor_rov};
use seatrial_core::planning::generate_plan;

#[test]
fn the_designed_surveyor_campaign_needs_fewer_than_half_the_ship_hours() {
    let profile = surveyor_rov();
    let spec = surveyor_campaign(7);
    let prior = Prior::reference(&profile).unwrap();
    let Prior::Rov(truth) = &prior else {
        panic!("the Surveyor's prior is an ROV")
    };
    let d = design_campaign(&profile, &spec, truth, None, &mut NoProgress).unwrap();
    eprintln!(
        "current {:.2} h D {:.3}; design {:.2} h D {:.3} (rel std {:.3}); rule-based needs {:.2} h: ratio {:.2}",
        d.current.hours,
        d.current.criterion,
        d.design.hours,
        d.design.criterion,
        d.design.relative_std,
        d.rule_hours_for_equal_precision,
        d.hours_ratio
    );
    assert!(d.design.hours <= d.budget_hours + 1e-9);
    assert!((d.budget_hours - d.current.hours).abs() < 1e-9);
    assert!(d.design.criterion < d.current.criterion);
    assert!(d.hours_ratio >= 2.0, "ratio {}", d.hours_ratio);
    assert!(!d.extrapolated);
    // Fronts rise in hours and fall in D.
    for f in [&d.designed_front, &d.rule_front] {
        for w in f.windows(2) {
            assert!(w[1].hours > w[0].hours && w[1].criterion < w[0].criterion);
        }
    }
    // The identification confirms it: the design in its hours against the
    // rule-based plan flown three times over.
    let settings = PredictSettings {
        realisations: 10,
        ..PredictSettings::default()
    };
    let mut thrice = spec.clone();
    thrice.repetitions = Some(3);
    let mut predicted = Vec::new();
    for s in [&d.spec, &thrice] {
        let plan = generate_plan(&profile, s).unwrap();
        let p = predict_precision(
            &profile,
            &plan,
            &prior,
            PriorSource::Reference,
            &settings,
            &mut NoProgress,
        )
        .unwrap();
        eprintln!(
            "{:.2} h: {} of {} determined, geometric mean relative std {:?}",
            p.ship_hours, p.determined, p.total, p.geometric_mean_relative_std
        );
        predicted.push((p.ship_hours, p.geometric_mean_relative_std.unwrap()));
    }
    let (designed, rule) = (predicted[0], predicted[1]);
    assert!(rule.0 >= 2.0 * designed.0, "{rule:?} vs {designed:?}");
    assert!(
        designed.1 <= rule.1,
        "design {designed:?} vs rule ×3 {rule:?}"
    );
}
