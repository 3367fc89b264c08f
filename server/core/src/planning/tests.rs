//! Plan-level tests: the thesis's experiment counts, limits respected by every
//! sample, determinism, PE and the errors that name their field.

use super::campaign::DofExcitation;
use super::examples::{supply_vessel, supply_vessel_campaign, surveyor_campaign, surveyor_rov};
use super::*;
use crate::signals;

fn rov_campaign() -> CampaignSpec {
    surveyor_campaign(42)
}

fn dp_campaign() -> CampaignSpec {
    supply_vessel_campaign(7)
}

#[test]
fn rov_plan_has_the_thesis_counts_and_totals() {
    let plan = generate_plan(&surveyor_rov(), &rov_campaign()).unwrap();
    let t = &plan.totals;
    // Static: surge alone + ±5 other DOFs = 11 per grid speed (the thesis's 88 over 8 speeds).
    assert_eq!(t.per_family["static"], 7 * 11);
    assert_eq!(t.per_family["dynamic"], 7 * 6);
    assert_eq!(t.per_family["recursive"], 7);
    assert_eq!(t.per_family["validation"], 1);
    assert_eq!(t.experiments, 77 + 42 + 7 + 1);
    let sum: f64 = plan
        .experiments
        .iter()
        .map(|e| e.experiment.duration_s)
        .sum();
    assert!((t.run_time_s - sum).abs() < 1e-6);
    assert!((t.total_time_s - sum - 60.0 * t.experiments as f64).abs() < 1e-6);
    // Run order: seq 1.. and grid speeds non-decreasing before validation.
    let mut last = 0.0;
    for (i, e) in plan.experiments.iter().enumerate() {
        assert_eq!(e.experiment.seq as usize, i + 1);
        if let Some(u) = e.experiment.grid_speed_mps {
            assert!(u >= last);
            last = u;
        }
    }
    let val = plan.experiments.last().unwrap();
    assert_eq!(val.experiment.family, ExperimentFamily::Validation);
    assert!(val.experiment.duration_s >= 300.0);
    // Durations follow the thesis minima.
    for e in &plan.experiments {
        let min = match e.experiment.family {
            ExperimentFamily::Static => 20.0,
            ExperimentFamily::Dynamic => 30.0,
            ExperimentFamily::Recursive => 100.0,
            _ => 300.0,
        };
        assert!(e.experiment.duration_s >= min, "{}", e.experiment.code);
    }
}

#[test]
fn every_sample_respects_amplitude_and_rate_limits() {
    for (v, c) in [
        (surveyor_rov(), rov_campaign()),
        (supply_vessel(), dp_campaign()),
    ] {
        let plan = generate_plan(&v, &c).unwrap();
        for p in &plan.experiments {
            let fs = p.schedule.sample_rate_hz;
            for (ch, x) in p.experiment.channels.iter().zip(&p.schedule.values) {
                assert_eq!(x.len(), p.schedule.len());
                for w in x.windows(2) {
                    if let Some(r) = ch.rate_limit {
                        assert!(
                            (w[1] - w[0]).abs() * fs <= r * (1.0 + 1e-9),
                            "{} {}",
                            p.experiment.code,
                            ch.column
                        );
                    }
                }
                assert!(
                    x.iter().all(|s| s.abs() <= ch.limit + 1e-12),
                    "{} {}",
                    p.experiment.code,
                    ch.column
                );
            }
        }
    }
}

#[test]
fn static_runs_hold_the_level_and_dynamic_runs_hold_the_grid_speed() {
    let plan = generate_plan(&surveyor_rov(), &rov_campaign()).unwrap();
    let sway_minus = plan
        .experiments
        .iter()
        .find(|e| e.experiment.code == "STA-1kn-sway--r1")
        .expect("static sway − at 1 kn");
    let col = sway_minus
        .schedule
        .columns
        .iter()
        .position(|c| c == "v_ref")
        .unwrap();
    let v = &sway_minus.schedule.values[col];
    let level = -0.5 * 1.5 * KNOT;
    // Ends at the level, and holds it for at least the last 20 s + 5T.
    let fs = sway_minus.schedule.sample_rate_hz;
    let hold = ((20.0 + 15.0) * fs) as usize;
    assert!(
        v[v.len() - hold..]
            .iter()
            .all(|x| (x - level).abs() < 1e-12)
    );
    let u = &sway_minus.schedule.values[0];
    assert!(
        u.iter().all(|x| (x - KNOT).abs() < 1e-12),
        "surge held at 1 kn"
    );

    let dyn_roll = plan
        .experiments
        .iter()
        .find(|e| e.experiment.code == "DYN-2kn-roll-r1")
        .unwrap();
    let a = dyn_roll.experiment.channels[3].analysis.as_ref().unwrap();
    assert!(a.pe_order >= a.pe_required);
    let [_, hi] = a.band_hz.unwrap();
    assert!(
        hi > 1.0 / (2.0 * std::f64::consts::PI * 1.5),
        "band reaches the roll corner"
    );
}

#[test]
fn plans_are_deterministic_for_a_seed() {
    let a = generate_plan(&surveyor_rov(), &rov_campaign()).unwrap();
    let b = generate_plan(&surveyor_rov(), &rov_campaign()).unwrap();
    assert_eq!(a, b);
    let mut c = rov_campaign();
    c.seed = 43;
    let c = generate_plan(&surveyor_rov(), &c).unwrap();
    let rec = |p: &Plan| {
        p.experiments
            .iter()
            .find(|e| e.experiment.family == ExperimentFamily::Recursive)
            .unwrap()
            .schedule
            .values[1]
            .clone()
    };
    assert_ne!(rec(&a), rec(&c));
}

#[test]
fn recursive_channels_are_uncorrelated() {
    let plan = generate_plan(&surveyor_rov(), &rov_campaign()).unwrap();
    let rec = plan
        .experiments
        .iter()
        .find(|e| e.experiment.family == ExperimentFamily::Recursive)
        .unwrap();
    // Sway and heave share T = 3 s, so they are shifts of one m-sequence:
    // their normalized correlation must be near 0 (−1/M for a full period).
    let x = &rec.schedule.values[1];
    let y = &rec.schedule.values[2];
    let dot: f64 = x.iter().zip(y).map(|(a, b)| a * b).sum();
    let nx: f64 = x.iter().map(|a| a * a).sum::<f64>().sqrt();
    let ny: f64 = y.iter().map(|a| a * a).sum::<f64>().sqrt();
    assert!(
        (dot / (nx * ny)).abs() < 0.1,
        "correlation {}",
        dot / (nx * ny)
    );
    for ch in &rec.experiment.channels {
        let a = ch.analysis.as_ref().unwrap();
        assert!(a.pe_order >= 12, "{}: PE {}", ch.column, a.pe_order);
    }
}

#[test]
fn dp_plan_has_the_three_decoupled_manoeuvres_twice() {
    let plan = generate_plan(&supply_vessel(), &dp_campaign()).unwrap();
    let codes: Vec<&str> = plan
        .experiments
        .iter()
        .map(|e| e.experiment.code.as_str())
        .collect();
    assert_eq!(
        codes,
        [
            "SI1-0m/s-r1",
            "SI1-0m/s-r2",
            "SI2-0m/s-r1",
            "SI2-0m/s-r2",
            "SI3-0m/s-r1",
            "SI3-0m/s-r2"
        ]
    );
    let excited = |i: usize| -> Vec<&str> {
        plan.experiments[i]
            .experiment
            .channels
            .iter()
            .filter(|c| c.excited)
            .map(|c| c.column.as_str())
            .collect()
    };
    assert_eq!(excited(0), ["thr_1", "thr_2"]);
    assert_eq!(excited(2), ["thr_3", "thr_4", "thr_5"]);
    assert_eq!(excited(4), ["thr_6"]);
    let s1 = &plan.experiments[0].schedule.values;
    assert_eq!(s1[0], s1[1], "main propellers share one signal (K1 = K2)");
    let s2 = &plan.experiments[2].schedule.values;
    assert_eq!(s2[2], s2[3], "the aft tunnel pair shares a signal");
    assert_ne!(s2[2], s2[4], "stern and bow are driven independently");
    assert_ne!(
        s1[0], plan.experiments[1].schedule.values[0],
        "repetitions differ"
    );
    // DP runs last ≥ 600 s, and the surge clock follows T ≈ 88 s.
    assert!(
        plan.experiments
            .iter()
            .all(|e| e.experiment.duration_s >= 600.0)
    );
}

#[test]
fn impossible_requests_name_the_field_and_limit() {
    let rov = surveyor_rov();
    let mut c = rov_campaign();
    c.grid.speeds.push(4.5);
    let e = generate_plan(&rov, &c).unwrap_err();
    assert_eq!(e.field, "grid.speeds[7]");
    assert!((e.limit.unwrap() - 4.3 * KNOT).abs() < 1e-12);

    let mut c = rov_campaign();
    c.excitation.per_dof.insert(
        Dof::Roll,
        DofExcitation {
            amplitude: Some(0.5),
            ..Default::default()
        },
    );
    // Roll is excited by attitude: its amplitude is an angle, at most the
    // profile's max_angle (10° without one), not the 0.3 rad/s rate limit.
    let e = generate_plan(&rov, &c).unwrap_err();
    assert_eq!(e.field, "excitation.per_dof.roll.amplitude");
    assert_eq!(e.limit, Some(super::statics::STATIC_ATTITUDE_RAD));

    let mut c = rov_campaign();
    c.excitation.per_dof.insert(
        Dof::Yaw,
        DofExcitation {
            clock_period_s: Some(45.0),
            ..Default::default()
        },
    );
    let e = generate_plan(&rov, &c).unwrap_err();
    assert_eq!(e.field, "excitation.per_dof.yaw.clock_period_s");
    assert_eq!(e.limit, Some(30.0));

    let mut c = dp_campaign();
    c.repetitions = Some(1);
    assert_eq!(
        generate_plan(&supply_vessel(), &c).unwrap_err().field,
        "repetitions"
    );

    let mut c = rov_campaign();
    c.durations.validation_s = 200.0;
    let e = generate_plan(&rov, &c).unwrap_err();
    assert_eq!(
        (e.field.as_str(), e.limit),
        ("durations.validation_s", Some(300.0))
    );

    let mut c = rov_campaign();
    c.families.push(ExperimentFamily::DpSurge);
    assert_eq!(generate_plan(&rov, &c).unwrap_err().field, "families[4]");
}

#[test]
fn poor_persistence_of_excitation_is_refused() {
    // Without slew limits, a square wave of half period 0.4 s is seen by the
    // 10 Hz logger as 4 samples per level: PE order 4 < the 12 a 6-DOF
    // recursive run needs.
    let mut rov = surveyor_rov();
    for l in rov.limits.values_mut() {
        l.max_accel = None;
    }
    let mut c = rov_campaign();
    c.families = vec![ExperimentFamily::Recursive];
    c.excitation.per_dof.insert(
        Dof::Heave,
        DofExcitation {
            signal: Some(SignalKind::Square),
            clock_period_s: Some(0.4),
            ..Default::default()
        },
    );
    let e = generate_plan(&rov, &c).unwrap_err();
    assert_eq!(e.field, "excitation");
    assert!(e.message.contains("order 4"), "{}", e.message);
    assert_eq!(e.limit, Some(12.0));
}

#[test]
fn other_shapes_plan_and_stay_within_limits() {
    for s in [
        SignalKind::Square,
        SignalKind::Multisine,
        SignalKind::RandomBinary,
    ] {
        let mut c = rov_campaign();
        c.excitation.signal = s;
        c.grid.speeds = vec![1.0, 2.0];
        let plan = generate_plan(&surveyor_rov(), &c).unwrap_or_else(|e| panic!("{s:?}: {e}"));
        let dynamic = plan
            .experiments
            .iter()
            .find(|e| e.experiment.code == "DYN-1kn-sway-r1")
            .unwrap();
        let x = &dynamic.schedule.values[1];
        let a = dynamic.experiment.channels[1].amplitude;
        assert!(x.iter().any(|v| v.abs() > 0.5 * a), "{s:?} excites");
        if s == SignalKind::Multisine {
            assert!(
                signals::crest_factor(x) < 2.5,
                "{s:?}: crest {}",
                signals::crest_factor(x)
            );
        }
    }
}

#[test]
fn force_schedules_use_tau_columns_and_force_limits() {
    let mut c = rov_campaign();
    c.excitation.quantity = Quantity::Force;
    c.families = vec![ExperimentFamily::Dynamic];
    c.grid.speeds = vec![1.0];
    let plan = generate_plan(&surveyor_rov(), &c).unwrap();
    let cols = &plan.experiments[1].schedule.columns;
    assert_eq!(
        cols,
        &["u_ref", "tau_Y", "tau_Z", "tau_K", "tau_M", "tau_N"]
    );
    let ch = &plan.experiments[1].experiment.channels[1];
    assert_eq!(ch.limit, 6000.0);
    assert_eq!(ch.rate_limit, Some(3000.0));
}

#[test]
fn dp_validation_drives_thruster_groups_independently() {
    let mut c = dp_campaign();
    c.families.push(ExperimentFamily::Validation);
    let plan = generate_plan(&supply_vessel(), &c).unwrap();
    let val = &plan.experiments.last().unwrap().schedule.values;
    assert_eq!(val[0], val[1], "main propellers share a signal");
    assert_ne!(val[0], val[2], "main and tunnel groups differ");
    assert_ne!(val[2], val[5], "tunnel and azimuth groups differ");
}

#[test]
fn holds_carry_no_excitation_figures_and_seeds_fit_json() {
    let plan = generate_plan(&surveyor_rov(), &rov_campaign()).unwrap();
    let surge_static = &plan.experiments[0].experiment;
    assert_eq!(surge_static.code, "STA-0.5kn-surge-r1");
    assert!(surge_static.channels.iter().all(|c| c.analysis.is_none()));
    for p in &plan.experiments {
        for c in &p.experiment.channels {
            let json = serde_json::to_value(&c.waveform).unwrap();
            if let Some(seed) = json.get("seed") {
                assert!(seed.as_u64().unwrap() < (1 << 53));
            }
        }
    }
    let mut c = rov_campaign();
    c.seed = 1 << 60;
    assert_eq!(
        generate_plan(&surveyor_rov(), &c).unwrap_err().field,
        "seed"
    );
}
