//! The log contract, the measurement noise and seeds, and errors that name the field.

use super::*;

#[test]
fn logs_parse_with_the_project_parser_and_carry_the_profile_columns() {
    let mut four = surveyor_rov();
    four.name = "Four-DOF ROV".into();
    four.dofs = vec![Dof::Surge, Dof::Sway, Dof::Heave, Dof::Yaw];
    four.limits.remove(&Dof::Roll);
    four.limits.remove(&Dof::Pitch);
    let truth = RovTruth::surveyor_like();
    let s = TrialSettings {
        max_duration_s: Some(10.0),
        ..TrialSettings::default()
    };
    for profile in [surveyor_rov(), four] {
        let plan = plan_of(&profile, Quantity::Velocity);
        let planned = find(&plan, "REC-1kn-r1");
        let run = fly_experiment(&profile, &truth, planned, &s).unwrap();
        let opts = ParseOptions::for_vessel(&profile, LogRole::Single, None);
        let parsed = parse_log(run.csv.as_bytes(), &opts).unwrap();
        let required = required_columns(&profile, LogRole::Single, None);
        assert_eq!(parsed.table.names, required[1..].to_vec());
        assert!(parsed.ignored_columns.is_empty());
        assert_eq!(parsed.rows, run.record.len());
        // 10 s at the logger rate, t from 0.
        assert_eq!(parsed.rows, (10.0 * profile.logger_rate_hz) as usize + 1);
        assert_eq!(parsed.table.t, run.record.t);
        let dt = 1.0 / profile.logger_rate_hz;
        assert!((parsed.table.t[1] - dt).abs() < 1e-12);
        // Values round-trip exactly.
        for &d in &profile.dofs {
            let i = d.index();
            let col = |name: &str| parsed.table.column(name).unwrap().to_vec();
            let of = |m: &DMatrix<f64>| m.column(i).iter().copied().collect::<Vec<_>>();
            assert_eq!(col(d.force_column()), of(&run.record.tau_commanded));
            assert_eq!(col(d.velocity_symbol()), of(&run.record.nu));
            assert_eq!(col(pose_column(d)), of(&run.record.eta));
        }
        // Unmodeled DOFs are left passive.
        for d in Dof::ALL.iter().filter(|d| !profile.dofs.contains(d)) {
            assert_eq!(run.drives[d.index()], Drive::Passive);
            assert_eq!(run.record.tau_commanded.column(d.index()).amax(), 0.0);
        }
    }
}

#[test]
fn noise_has_the_set_spread_and_runs_reproduce_by_seed() {
    let profile = surveyor_rov();
    let truth = RovTruth::surveyor_like();
    let plan = plan_of(&profile, Quantity::Velocity);
    let planned = find(&plan, "VAL-r1");
    let noise = MeasurementNoise {
        nu: [0.02, 0.01, 0.03, 0.004, 0.005, 0.006],
        eta: [0.5, 0.4, 0.05, 0.002, 0.003, 0.004],
    };
    let s = TrialSettings {
        noise,
        seed: 42,
        max_duration_s: Some(200.0),
        ..TrialSettings::default()
    };
    let a = fly_experiment(&profile, &truth, planned, &s).unwrap();
    let n = a.record.len();
    assert_eq!(n, 2001);
    // std error of a std over 2001 draws ≈ 1.6 %: allow 4σ.
    for i in 0..6 {
        let e_nu = rms((0..n).map(|k| a.record.nu[(k, i)] - a.record.nu_true[(k, i)]));
        assert!((e_nu / noise.nu[i] - 1.0).abs() < 0.065, "ν[{i}]: {e_nu}");
        let e_eta = rms((0..n).map(|k| wrap_pi(a.record.eta[(k, i)] - a.record.eta_true[(k, i)])));
        assert!(
            (e_eta / noise.eta[i] - 1.0).abs() < 0.065,
            "η[{i}]: {e_eta}"
        );
    }
    // Heading is logged wrapped to (−π, π].
    assert!(
        a.record
            .eta
            .column(5)
            .iter()
            .all(|p| p.abs() <= std::f64::consts::PI)
    );
    let again = fly_experiment(&profile, &truth, planned, &s).unwrap();
    assert_eq!(again, a);
    let other =
        fly_experiment(&profile, &truth, planned, &TrialSettings { seed: 43, ..s }).unwrap();
    assert_ne!(other.csv, a.csv);
    // The noise is the logger's: it does not feed back into the flight.
    assert_eq!(other.record.nu_true, a.record.nu_true);

    // A campaign gives each run its own seed.
    let runs = fly_campaign(&profile, &truth, &plan, &s, |e| {
        e.family == ExperimentFamily::Dynamic && e.grid_index == Some(0)
    })
    .unwrap();
    assert_eq!(runs.len(), 6);
    assert!(runs.windows(2).all(|w| w[0].seq < w[1].seq));
    let n0 = |r: &FlownRun| r.record.nu[(0, 2)] - r.record.nu_true[(0, 2)];
    assert_ne!(n0(&runs[0]), n0(&runs[1]));
    let single = fly_experiment(
        &profile,
        &truth,
        &plan.experiments[runs[3].seq as usize - 1],
        &TrialSettings {
            seed: run_seed(42, runs[3].seq),
            ..s
        },
    )
    .unwrap();
    assert_eq!(single, runs[3]);
}

/// Measured feedback: without noise it flies exactly as true feedback; with
/// noise the log still carries the set spread about the truth, and the
/// noise moves the vehicle through the loop (the true ν differs by seed).
#[test]
fn measured_feedback_logs_what_the_controller_read_and_moves_the_vehicle() {
    let profile = surveyor_rov();
    let truth = RovTruth::surveyor_like();
    let plan = plan_of(&profile, Quantity::Velocity);
    let planned = find(&plan, "VAL-r1");
    let base = TrialSettings {
        max_duration_s: Some(200.0),
        ..quiet()
    };
    let measured = TrialSettings {
        feedback: Feedback::Measured,
        ..base
    };
    assert_eq!(
        fly_experiment(&profile, &truth, planned, &base).unwrap(),
        fly_experiment(&profile, &truth, planned, &measured).unwrap()
    );
    let noise = MeasurementNoise::default();
    let s = |seed| TrialSettings {
        noise,
        seed,
        ..measured
    };
    let a = fly_experiment(&profile, &truth, planned, &s(1)).unwrap();
    let b = fly_experiment(&profile, &truth, planned, &s(2)).unwrap();
    let n = a.record.len();
    for i in 0..6 {
        let e = rms((0..n).map(|k| a.record.nu[(k, i)] - a.record.nu_true[(k, i)]));
        assert!((e / noise.nu[i] - 1.0).abs() < 0.065, "ν[{i}]: {e}");
    }
    assert_ne!(a.record.nu_true, b.record.nu_true);
    // … but it stays a flight of the same plan: the true velocities differ
    // by less than the noise itself.
    let d = rms((0..n).map(|k| a.record.nu_true[(k, 1)] - b.record.nu_true[(k, 1)]));
    assert!(d > 0.0 && d < 2.0 * noise.nu[1], "sway: {d}");
}

#[test]
fn bad_input_is_a_typed_error_naming_the_field() {
    let profile = surveyor_rov();
    let truth = RovTruth::surveyor_like();
    let plan = plan_of(&profile, Quantity::Velocity);
    let planned = find(&plan, "DYN-1kn-yaw-r1");
    let field = |p: &VesselProfile, t: &RovTruth, x: &PlannedExperiment, s: &TrialSettings| {
        fly_experiment(p, t, x, s).unwrap_err().field()
    };
    let mut s = quiet();
    s.noise.nu[1] = f64::NAN;
    assert_eq!(field(&profile, &truth, planned, &s), "settings.noise.nu[v]");
    let s = TrialSettings {
        max_duration_s: Some(-1.0),
        ..quiet()
    };
    assert_eq!(
        field(&profile, &truth, planned, &s),
        "settings.max_duration_s"
    );
    let s = TrialSettings {
        substeps: 0,
        ..quiet()
    };
    assert_eq!(field(&profile, &truth, planned, &s), "settings.substeps");

    let mut p = profile.clone();
    p.logger_rate_hz = 3.0;
    assert_eq!(
        field(&p, &truth, planned, &quiet()),
        "profile.logger_rate_hz"
    );
    let dp = crate::planning::examples::supply_vessel();
    assert_eq!(field(&dp, &truth, planned, &quiet()), "profile.kind");
    let mut p = profile.clone();
    p.limits.get_mut(&Dof::Yaw).unwrap().max_force = -1.0;
    assert_eq!(
        field(&p, &truth, planned, &quiet()),
        "profile.limits.yaw.max_force"
    );

    let mut x = planned.clone();
    x.schedule.columns[2] = "depth".into();
    assert_eq!(field(&profile, &truth, &x, &quiet()), "schedule.columns[2]");
    let mut x = planned.clone();
    x.schedule.values[3][7] = f64::INFINITY;
    assert_eq!(
        field(&profile, &truth, &x, &quiet()),
        "schedule.values[3][7]"
    );
    let mut x = planned.clone();
    x.schedule.values[4].pop();
    assert_eq!(field(&profile, &truth, &x, &quiet()), "schedule.values[4]");
    let mut x = planned.clone();
    x.schedule.sample_rate_hz = 10.0;
    assert_eq!(
        field(&profile, &truth, &x, &quiet()),
        "schedule.sample_rate_hz"
    );
    let mut x = planned.clone();
    x.schedule.columns.remove(5);
    x.schedule.values.remove(5);
    assert_eq!(field(&profile, &truth, &x, &quiet()), "schedule.columns");

    let mut t = truth.clone();
    t.m[(0, 0)] = -1.0;
    let err = fly_experiment(&profile, &t, planned, &quiet()).unwrap_err();
    assert!(matches!(err, TrialError::Simulation { .. }), "{err}");
    assert!(err.to_string().starts_with("DYN-1kn-yaw-r1: "));
}

#[test]
fn every_run_of_the_surveyor_campaign_flies_and_parses() {
    let profile = surveyor_rov();
    let truth = RovTruth::surveyor_like();
    let plan = plan_of(&profile, Quantity::Velocity);
    let s = TrialSettings {
        max_duration_s: Some(20.0),
        seed: 7,
        ..TrialSettings::default()
    };
    let runs = fly_campaign(&profile, &truth, &plan, &s, |_| true).unwrap();
    assert_eq!(runs.len(), plan.experiments.len());
    let opts = ParseOptions::for_vessel(&profile, LogRole::Single, None);
    for run in &runs {
        let parsed = parse_log(run.csv.as_bytes(), &opts).unwrap();
        assert_eq!(parsed.rows, run.record.len(), "{}", run.code);
    }
}
