//! External reference schedules flown on the truth: equivalence with the
//! truth's own runs, determinism, attitude hold, open-loop force channels.

use nalgebra::{DMatrix, Vector6};
use seatrial_truth::campaign::{Channel, ExternalRun};
use seatrial_truth::controller::{ControllerConfig, Envelope};
use seatrial_truth::rng::Rng;
use seatrial_truth::{
    CampaignSpec, Dof, NoiseSpec, Role, Run, SignalKind, Vessel, campaign_as_external,
    external_envelope, fly_campaign, fly_external, fly_external_campaign, fly_external_runs,
    run_seed,
};

/// A short campaign: one grid speed, a static and a sway and a pitch run.
fn short_spec() -> CampaignSpec {
    CampaignSpec {
        grid_speeds: vec![1.0],
        dynamic_dofs: vec![Dof::Sway, Dof::Pitch],
        static_duration_s: (60.0, 70.0),
        dynamic_duration_s: (120.0, 130.0),
        validation_duration_s: 60.0,
        ..CampaignSpec::default()
    }
}

/// The default campaign's envelope, tuned from `seed`.
fn controller(v: &Vessel, seed: u64) -> ControllerConfig {
    let env = Envelope {
        u_max: 2.0,
        amplitude: CampaignSpec::default().amplitude,
    };
    ControllerConfig::tune(v, &env, &mut Rng::new(seed))
}

fn constant(x: f64, n: usize) -> Channel {
    Channel::Velocity(vec![x; n])
}

/// Surge at `u` for `secs` at 10 Hz, every other DOF held.
fn surge_run(u: f64, secs: f64) -> ExternalRun {
    let n = (secs * 10.0) as usize;
    ExternalRun::new(
        "surge",
        10.0,
        [
            constant(u, n),
            Channel::Hold,
            Channel::Hold,
            Channel::Hold,
            Channel::Hold,
            Channel::Hold,
        ],
    )
}

fn max_abs_diff(a: &DMatrix<f64>, b: &DMatrix<f64>, rows: std::ops::Range<usize>) -> f64 {
    rows.flat_map(|i| (0..a.ncols()).map(move |j| (i, j)))
        .map(|(i, j)| (a[(i, j)] - b[(i, j)]).abs())
        .fold(0.0, f64::max)
}

fn mean(m: &DMatrix<f64>, col: usize, rows: std::ops::Range<usize>) -> f64 {
    let n = rows.len() as f64;
    rows.map(|i| m[(i, col)]).sum::<f64>() / n
}

#[test]
fn own_runs_flown_as_external_schedules_reproduce_the_campaign() {
    let seed = 31;
    let v = Vessel::draw(seed);
    let spec = short_spec();
    let c = fly_campaign(&v, &spec, seed);
    let (cfg, ext) = campaign_as_external(&v, &spec, seed);
    assert_eq!(cfg, c.controller);
    assert_eq!(ext.len(), c.runs.len());

    // The static run: pre-roll and lead-in both hold u₀, so the flights are
    // the same flight, bit for bit.
    let own = &c.runs[0];
    assert_eq!(own.meta.role, Role::Static);
    let r = fly_external(&v, &cfg, &ext[0], &spec.noise, run_seed(seed, 0));
    assert_eq!(r.log.tau, own.log.tau);
    assert_eq!(r.log.nu, own.log.nu);
    assert_eq!(r.log.eta, own.log.eta);
    assert_eq!(r.truth.nu, own.truth.nu);
    assert_eq!(r.truth.eta, own.truth.eta);
    assert_eq!(r.truth.tau_cmd_20hz, own.truth.tau_cmd_20hz);
    assert_eq!(r.meta.role, Role::Static);
    assert_eq!(r.meta.excited, Vec::<Dof>::new());
    assert_eq!(r.meta.signal, SignalKind::Constant);
    assert!((r.meta.grid_speed.unwrap() - 1.0).abs() < 1e-12);
    assert_eq!(r.meta.duration_s, own.meta.duration_s);

    // Excited runs: the campaign's pre-roll holds the operating point, the
    // lead-in the first sample; with the same noise the two converge.
    for i in [1, 2] {
        let own = &c.runs[i];
        let r = fly_external(&v, &cfg, &ext[i], &spec.noise, run_seed(seed, i));
        assert_eq!(r.meta.role, Role::Dynamic);
        assert_eq!(r.meta.excited, own.meta.excited, "{}", own.meta.name);
        assert_eq!(r.meta.signal, own.meta.signal, "{}", own.meta.name);
        assert!((r.meta.amplitude - own.meta.amplitude).abs() < 1e-12);
        let (a, b) = (
            r.meta.switch_time_s.unwrap(),
            own.meta.switch_time_s.unwrap(),
        );
        assert!((a - b).abs() < 1e-9, "{}: {a} vs {b}", own.meta.name);
        let n = r.log.t.len();
        assert_eq!(n, own.log.t.len());
        let late = 600..n; // after 60 s
        let dnu = max_abs_diff(&r.truth.nu, &own.truth.nu, late.clone());
        let dtau = max_abs_diff(&r.log.tau, &own.log.tau, late.clone());
        let tau_scale = own.log.tau.amax();
        assert!(dnu < 1e-4, "{}: ν differs by {dnu}", own.meta.name);
        assert!(
            dtau < 1e-3 * tau_scale,
            "{}: τ differs by {dtau} (scale {tau_scale})",
            own.meta.name
        );
        let dang = late
            .map(|k| {
                (r.truth.eta[(k, 3)] - own.truth.eta[(k, 3)])
                    .abs()
                    .max((r.truth.eta[(k, 4)] - own.truth.eta[(k, 4)]).abs())
            })
            .fold(0.0, f64::max);
        assert!(dang < 1e-4, "{}: φ, θ differ by {dang}", own.meta.name);
    }
}

#[test]
fn constant_surge_reference_reaches_the_damping_steady_state() {
    let v = Vessel::draw(32);
    let cfg = controller(&v, 32);
    let u = 1.2;
    let r = fly_external(&v, &cfg, &surge_run(u, 120.0), &NoiseSpec::none(), 5);
    let n = r.log.t.len();
    assert_eq!(n, 1200);
    let tail = n - 300..n;
    let u_ss = mean(&r.truth.nu, 0, tail.clone());
    assert!((u_ss - u).abs() < 1e-3 * u, "u_ss {u_ss}");
    // X = D(u) u at pure surge (C(ν)ν has no X part there; θ ≈ 0)
    let d = v.damping_linear[0]
        + v.damping_linear_per_speed[0] * u.abs()
        + v.damping_quadratic[0] * u.abs();
    let tau_x = mean(&r.log.tau, 0, tail.clone());
    assert!(
        (tau_x - d * u).abs() < 0.01 * d * u,
        "τ_X {tau_x} vs D(u)u {}",
        d * u
    );
    // the logged τ is the autopilot's command (every second 20 Hz sample)
    for k in 0..n {
        assert_eq!(r.log.tau.row(k), r.truth.tau_cmd_20hz.row(2 * k));
    }
    assert_eq!(r.log.t[0], 0.0);
    assert_eq!(r.meta.role, Role::Static);
    assert_eq!(r.meta.speeds, vec![u]);
    assert_eq!(r.meta.grid_speed, Some(u));
}

fn sway_prbs_run(n: usize) -> ExternalRun {
    let mut x = Vec::with_capacity(n);
    let mut reg: u16 = 0x5A;
    for k in 0..n {
        if k % 30 == 0 {
            reg = ((reg << 1) | (((reg >> 8) ^ (reg >> 4)) & 1)) & 0x1FF;
        }
        x.push(if reg & 1 == 1 { 0.2 } else { -0.2 });
    }
    let mut run = surge_run(1.0, n as f64 / 10.0);
    run.name = "sway".into();
    run.channels[1] = Channel::Velocity(x);
    run
}

#[test]
fn same_seed_same_csv_other_seed_other_noise_same_truth() {
    let v = Vessel::draw(33);
    let cfg = controller(&v, 33);
    let run = sway_prbs_run(900);
    let noise = NoiseSpec::default();
    let a = fly_external(&v, &cfg, &run, &noise, 1);
    let b = fly_external(&v, &cfg, &run, &noise, 1);
    let c = fly_external(&v, &cfg, &run, &noise, 2);
    assert_eq!(a.single_csv(), b.single_csv());
    assert_eq!(a, b);
    assert_ne!(a.single_csv(), c.single_csv());
    // the noise differs and is independent: the two noise sequences of u
    // are uncorrelated and each has the specified σ
    let na = a.log.nu.column(0) - a.truth.nu.column(0);
    let nc = c.log.nu.column(0) - c.truth.nu.column(0);
    let corr = na.dot(&nc) / (na.norm() * nc.norm());
    assert!(corr.abs() < 0.1, "noise correlation {corr}");
    let sigma = (na.norm_squared() / na.len() as f64).sqrt();
    assert!((sigma - noise.velocity_linear).abs() < 0.15 * noise.velocity_linear);
    // the noise-free truth: the start pose and schedule do not depend on the
    // seed; only the autopilot's reaction to its noisy measurements does
    // (the autopilot feeds the measurement noise back, so the true ν of two
    // seeds differ by a fraction of the noise: ~0.15 σ in u, v, w, up to
    // ~0.8 σ in the stiff roll loop's p)
    for j in 0..6 {
        let d = a.truth.nu.column(j) - c.truth.nu.column(j);
        let rms = (d.norm_squared() / d.len() as f64).sqrt();
        let bound = if j < 3 { 0.3 } else { 1.0 } * noise.nu_std(j);
        assert!(rms < bound, "true ν_{j} of two seeds differ by {rms} rms");
    }
    // without noise the truth is the same, exactly
    let quiet = NoiseSpec::none();
    let qa = fly_external(&v, &cfg, &run, &quiet, 1);
    let qc = fly_external(&v, &cfg, &run, &quiet, 2);
    assert_eq!(qa.truth, qc.truth);
    assert_eq!(qa.single_csv(), qc.single_csv());
    assert_eq!(qa.meta.excited, vec![Dof::Sway]);
    assert_eq!(qa.meta.signal, SignalKind::Prbs);
    assert!((qa.meta.switch_time_s.unwrap() - 3.0).abs() < 1e-9);
    assert!((qa.meta.amplitude - 0.2).abs() < 1e-12);
}

#[test]
fn external_campaign_is_reproducible_and_shares_one_autopilot() {
    let v = Vessel::draw(34);
    let runs = vec![surge_run(0.8, 40.0), sway_prbs_run(400)];
    let noise = NoiseSpec::default();
    let (cfg_a, a) = fly_external_campaign(&v, &runs, &noise, 9);
    let (cfg_b, b) = fly_external_campaign(&v, &runs, &noise, 9);
    assert_eq!(cfg_a, cfg_b);
    assert_eq!(a, b);
    let env = external_envelope(&runs);
    assert!((env.u_max - 1.0).abs() < 1e-12);
    assert!((env.amplitude[1] - 0.2).abs() < 1e-12);
    // runs follow each other on one control clock with one clock offset
    assert!(a[1].meta.start_s > a[0].meta.start_s + a[0].meta.duration_s);
    assert_eq!(a[0].meta.clock_offset_s, a[1].meta.clock_offset_s);
    // run i's noise is run_seed(seed, i): flying it alone gives the same log
    let alone = fly_external(&v, &cfg_a, &runs[1], &noise, run_seed(9, 1));
    assert_eq!(alone.log.nu, a[1].log.nu);
    assert_eq!(alone.log.tau, a[1].log.tau);
    // a fixed autopilot, other seeds: other noise
    let c = fly_external_runs(&v, &cfg_a, &runs, &noise, 10);
    assert_ne!(c[1].log.nu, a[1].log.nu);
    for r in a.iter().chain(&c) {
        assert!(r.meta.saturated_fraction < 0.02, "{}", r.meta.name);
    }
}

/// `cfg` with the team's ĝ equal to the truth's g.
fn exact_restoring(v: &Vessel, mut cfg: ControllerConfig) -> ControllerConfig {
    cfg.nominal_w_minus_b = v.w_minus_b;
    cfg.nominal_zg_w_minus_zb_b = v.zg_w_minus_zb_b();
    cfg
}

/// Surge at 0.5 m/s for 90 s with `pitch` on the pitch channel.
fn pitch_run(pitch: Channel) -> ExternalRun {
    let mut run = surge_run(0.5, 90.0);
    run.channels[4] = pitch;
    run
}

#[test]
fn pitch_attitude_reference_is_held() {
    let v = Vessel::draw(35);
    let theta_ref = 0.1;
    let run = pitch_run(Channel::Attitude(vec![theta_ref; 900]));
    // With the team's ĝ exact the PD loop holds θ_ref within a few percent
    // (what remains is the hydrodynamic pitch moment at speed over Kp).
    let cfg = exact_restoring(&v, controller(&v, 35));
    let r = fly_external(&v, &cfg, &run, &NoiseSpec::none(), 3);
    let n = r.log.t.len();
    let tail = n - 300..n;
    let theta = mean(&r.truth.eta, 4, tail.clone());
    assert!(
        (theta - theta_ref).abs() < 0.03 * theta_ref,
        "θ_ss {theta} for θ_ref {theta_ref}"
    );
    // With the tuned autopilot (ĝ 20–40 % off, no integral in the attitude
    // loops) θ_ss sits where the PD loop's moment balances the truth's:
    // Kp (θ_ref − θ) + ĝ_M(θ) = g_M(θ) + (C(ν)ν + D(ν)ν)_M.
    let cfg = controller(&v, 35);
    let r = fly_external(&v, &cfg, &run, &NoiseSpec::none(), 3);
    let theta = mean(&r.truth.eta, 4, tail.clone());
    let phi = mean(&r.truth.eta, 3, tail.clone());
    let nu = Vector6::from_fn(|i, _| mean(&r.truth.nu, i, tail.clone()));
    let eta = Vector6::new(0.0, 0.0, 0.0, phi, theta, 0.0);
    let plant_m = v.restoring(&eta)[4] + v.hydrodynamic_force(&nu)[4];
    let theta_pred = theta_ref - (plant_m - cfg.nominal_restoring(phi, theta)[4]) / cfg.kp[4];
    assert!(
        (theta - theta_pred).abs() < 0.01 * theta_ref,
        "θ_ss {theta}, moment balance {theta_pred}"
    );
    assert!(
        (theta - theta_ref).abs() < 0.5 * theta_ref,
        "θ_ss {theta} for θ_ref {theta_ref}"
    );
}

#[test]
fn pitch_rate_reference_is_flown_as_an_integrated_attitude() {
    let v = Vessel::draw(36);
    let cfg = exact_restoring(&v, controller(&v, 36));
    // q_ref = +0.02 rad/s for 5 s: θ_ref ramps to 0.1 rad and stays
    let mut q = vec![0.0; 900];
    q[100..150].fill(0.02);
    let r = fly_external(
        &v,
        &cfg,
        &pitch_run(Channel::Velocity(q)),
        &NoiseSpec::none(),
        3,
    );
    assert_eq!(r.meta.excited, vec![Dof::Pitch]);
    let n = r.log.t.len();
    let theta = mean(&r.truth.eta, 4, n - 300..n);
    assert!(
        (theta - 0.1).abs() < 0.03 * 0.1,
        "θ_ss {theta} for ∫q_ref = 0.1"
    );
    // during the ramp θ follows θ_ref = 0.02 (t − 10) with a small lag
    let mid = mean(&r.truth.eta, 4, 125..126);
    assert!((mid - 0.05).abs() < 0.02, "θ(12.5 s) {mid}");
}

#[test]
fn force_channel_is_applied_open_loop() {
    let v = Vessel::draw(37);
    let cfg = controller(&v, 37);
    let u = 1.0;
    let x_trim = v.hydrodynamic_force(&Vector6::new(u, 0.0, 0.0, 0.0, 0.0, 0.0))[0];
    // 5 Hz schedule: τ_X steps between 0.8 and 1.0 of the 1 m/s drag
    let tau: Vec<f64> = (0..600)
        .map(|k| if k < 200 { 0.8 * x_trim } else { x_trim })
        .collect();
    let mut run = surge_run(0.0, 120.0);
    run.rate_hz = 5.0;
    run.channels[0] = Channel::Force(tau.clone());
    let r = fly_external(&v, &cfg, &run, &NoiseSpec::default(), 4);
    assert_eq!(r.meta.grid_speed, None);
    assert_eq!(r.meta.excited, vec![Dof::Surge]);
    let n = r.log.t.len();
    assert_eq!(n, 1200);
    for k in 0..n {
        assert_eq!(r.log.tau[(k, 0)], tau[k / 2], "row {k}");
        assert_eq!(r.truth.tau_applied[(k, 0)], tau[k / 2]);
    }
    // the vessel coasts to the speed where its drag equals the force
    let u_ss = mean(&r.truth.nu, 0, n - 200..n);
    assert!((u_ss - u).abs() < 0.03 * u, "u_ss {u_ss}");
    // the other DOFs stay under the autopilot
    assert!(mean(&r.truth.nu, 1, n - 200..n).abs() < 0.02);
}

#[test]
#[should_panic(expected = "attitude channel drives yaw")]
fn attitude_channel_outside_roll_and_pitch_is_rejected() {
    let v = Vessel::draw(38);
    let mut run = surge_run(1.0, 10.0);
    run.channels[5] = Channel::Attitude(vec![0.1; 100]);
    let _: Run = fly_external(&v, &controller(&v, 38), &run, &NoiseSpec::none(), 1);
}
