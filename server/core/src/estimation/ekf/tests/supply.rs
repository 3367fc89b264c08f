//! Proof on the supply vessel: the six manoeuvres simulated from the paper's
//! numbers, identified by the staged parallel EKF (N = 2 per stage).

use nalgebra::DMatrix;

use super::super::*;
use crate::simulation::dp_ship::{
    DpRun, DpShip, THETA_NAMES, TrialConfig, paper, simulate_campaign,
};
use crate::validation::{Predictor, ValidationRecord, nrmse_fit};

fn stages(runs: &[DpRun]) -> Vec<DpStage<'_>> {
    let data = |i: usize| RunData {
        u: &runs[i].u,
        z: &runs[i].eta,
    };
    vec![
        DpStage {
            name: "SI1".into(),
            free: SI1_FREE.to_vec(),
            runs: vec![data(0), data(1)],
        },
        DpStage {
            name: "SI2".into(),
            free: SI2_FREE.to_vec(),
            runs: vec![data(2), data(3)],
        },
        DpStage {
            name: "SI3".into(),
            free: SI3_FREE.to_vec(),
            runs: vec![data(4), data(5)],
        },
    ]
}

#[test]
fn staged_parallel_ekf_recovers_the_supply_vessel() {
    let (truth, trial, runs, cfg) = super::supply_campaign(2024);
    let mut reports = Vec::new();
    let mut sink = |f: f64, stage: &str| {
        reports.push((f, stage.to_string()));
        Ok(())
    };
    let id = identify_dp_ship(&cfg, &stages(&runs), &mut sink).unwrap();
    let mut worst: f64 = 0.0;
    for (i, name) in THETA_NAMES.iter().enumerate() {
        let err = (id.theta[i] - paper::THETA[i]) / paper::THETA[i];
        eprintln!(
            "θ″{} {:>6} {:>10.6} truth {:>10.6} err {:>7.3} % σ {:.2e}",
            i + 1,
            name,
            id.theta[i],
            paper::THETA[i],
            100.0 * err,
            id.theta_std[i]
        );
        // The error is consistent with the filter's own σ.
        assert!(
            (id.theta[i] - paper::THETA[i]).abs() < 4.0 * id.theta_std[i],
            "θ″{}",
            i + 1
        );
        worst = worst.max(err.abs());
    }
    eprintln!("A″ {:.5}", id.a);
    eprintln!("B″ {:.5}", id.b);
    assert!(worst < 0.05, "worst θ″ error {:.2} %", 100.0 * worst);

    // B″ = M⁻¹·T·K (eq. 52) to one unit of the printed fourth decimal, both
    // against the truth and against the print where the truth reproduces it.
    let b_true = truth.state_space_b();
    for i in 0..3 {
        for j in 0..6 {
            assert!((id.b[(i, j)] - b_true[(i, j)]).abs() < 1e-4, "B″[{i},{j}]");
            if (b_true[(i, j)] - paper::B_STATE_SPACE[i][j]).abs() < 5e-5 {
                assert!((id.b[(i, j)] - paper::B_STATE_SPACE[i][j]).abs() < 1e-4);
            }
        }
    }
    // A″ = M⁻¹·A_h·M (eq. 51): the diagonal to 1 %; the couplings absorb the
    // θ″3, θ″4 errors amplified by M (∂A″32/∂A_h32 = (M⁻¹)33·M22 ≈ 15).
    let a_true = truth.state_space_a();
    for i in 0..3 {
        assert!(
            (id.a[(i, i)] / a_true[(i, i)] - 1.0).abs() < 0.01,
            "A″[{i},{i}]"
        );
        assert!((id.a[(i, i)] / paper::A_STATE_SPACE[i][i] - 1.0).abs() < 0.01);
    }
    assert!((id.a - a_true).abs().max() < 2.5e-3);
    assert_eq!(
        (id.a[(0, 1)], id.a[(0, 2)], id.a[(1, 0)], id.a[(2, 0)]),
        (0.0, 0.0, 0.0, 0.0)
    );

    // Bias estimates follow the true slowly varying b_h (surge, SI1 run 0).
    let stage1 = &id.stages[0];
    let b_hat = stage1.bias[0].column(0);
    let b_true = runs[0].bias.column(0);
    let tail = 300..600;
    let rms = (tail
        .clone()
        .map(|k| (b_hat[k] - b_true[k]).powi(2))
        .sum::<f64>()
        / 300.0)
        .sqrt();
    assert!(rms < 0.3 * b_true.amax().max(1e-4), "bias rms error {rms}");
    // Innovations are white-ish and of the measurement's size.
    let e = &stage1.innovations[0];
    let std = (e.view((50, 0), (550, 1)).norm_squared() / 550.0).sqrt();
    assert!(std / trial.position_noise_std < 1.3, "innovation σ {std}");
    // Progress covers both sweeps of the three stages and ends at 1.
    assert!(reports.windows(2).all(|w| w[0].0 <= w[1].0));
    assert!((reports.last().unwrap().0 - 1.0).abs() < 1e-12);
    assert!(reports.iter().any(|r| r.1 == "SI2"));
}

#[test]
fn identified_ship_predicts_validation_runs() {
    let (truth, trial, runs, cfg) = super::supply_campaign(77);
    let model = |ship: DpShip| IdentifiedDpShip {
        ship,
        r: cfg.r,
        p0_h: cfg.p0_h,
        p0_b: cfg.p0_b,
        q_h: cfg.q_h,
        q_b: cfg.q_b,
    };
    let good = model(truth.clone());
    let mut wrong_ship = truth.clone();
    wrong_ship.a_h *= 3.0;
    wrong_ship.k *= 0.5;
    let wrong = model(wrong_ship);
    assert_eq!(good.output_names(), ["x", "y", "psi"]);
    for run in [&runs[2], &runs[5]] {
        let rec = ValidationRecord {
            h: trial.h,
            u: &run.u,
            y: &run.eta,
        };
        let fit = |p: &DMatrix<f64>, c: usize| {
            nrmse_fit(run.eta_true.column(c).as_slice(), p.column(c).as_slice()).unwrap()
        };
        let k = 20;
        let pg = good.predict_k_step(&rec, k);
        let pw = wrong.predict_k_step(&rec, k);
        assert!(pg.row(k - 1)[0].is_nan() && pg.row(k)[0].is_finite());
        for c in 0..3 {
            assert!(fit(&pg, c) > 0.9, "k-step fit {c}: {}", fit(&pg, c));
            assert!(fit(&pg, c) > fit(&pw, c));
        }
        // Free run from the initial pose at rest: only the (unknown) bias
        // separates it from the truth.
        let sg = good.simulate(&rec);
        let sw = wrong.simulate(&rec);
        assert!(
            fit(&sg, 2) > 0.3 && fit(&sg, 2) > fit(&sw, 2),
            "{}",
            fit(&sg, 2)
        );
        // The state pass returns the true momentum up to noise.
        let states = good.estimate_states(&rec).unwrap();
        let nu_hat = states.columns(0, 3) * truth.m_inv().transpose();
        let err = (&nu_hat - &run.nu).rows(100, 500).abs().max();
        assert!(err < 0.1 * run.nu.amax(), "ν error {err}");
    }
}

/// θ″ errors (fractions) of the staged EKF on the paper's manoeuvres for one
/// truth seed, with `tune` applied to the configuration and `n2` samples in
/// the SI2 runs.
fn errors_for_seed(
    seed: u64,
    tune: &dyn Fn(&mut DpIdentConfig),
    n2: usize,
) -> ([f64; 9], [f64; 9]) {
    use crate::rng::mix;
    use crate::simulation::dp_ship::{Manoeuvre, manoeuvre_inputs, simulate_trial};
    let truth = DpShip::supply_vessel();
    let trial = TrialConfig::supply_vessel();
    let mut runs = simulate_campaign(&truth, &trial, paper::SAMPLES_PER_RUN, seed);
    if n2 != paper::SAMPLES_PER_RUN {
        for rep in 0..2u64 {
            let k = 2 + rep;
            let u = manoeuvre_inputs(Manoeuvre::SwayYaw, n2, mix(seed ^ (2 * k + 1)));
            let eta0 = [0.0, 0.0, Manoeuvre::SwayYaw.initial_heading()];
            runs[k as usize] = simulate_trial(
                &truth,
                Manoeuvre::SwayYaw,
                &u,
                eta0,
                &trial,
                mix(seed ^ (2 * k + 2)),
            );
        }
    }
    let mut cfg = DpIdentConfig::supply_vessel(&trial);
    tune(&mut cfg);
    let id = identify_dp_ship(&cfg, &stages(&runs), &mut crate::estimation::NoProgress).unwrap();
    (
        std::array::from_fn(|i| id.theta[i] / paper::THETA[i] - 1.0),
        std::array::from_fn(|i| id.theta_std[i] / paper::THETA[i].abs()),
    )
}

/// Seeds 1–12: how often each θ″ lands within 5 % under position noise, for
/// the tuning choices of the robustness study (`cargo test --release -p
/// seatrial-core seed_sweep -- --ignored --nocapture`).
#[test]
#[ignore = "seed sweep, ≈ 10 s in release"]
fn seed_sweep_of_the_staged_ekf() {
    type Tune = Box<dyn Fn(&mut DpIdentConfig)>;
    let variants: Vec<(&str, Tune, usize)> = vec![
        ("baseline", Box::new(|_| {}), 600),
        ("sweeps 4", Box::new(|c| c.sweeps = 4), 600),
        ("q_h 1e-9", Box::new(|c| c.q_h = [1e-9; 3]), 600),
        ("q_h 1e-11", Box::new(|c| c.q_h = [1e-11; 3]), 600),
        ("q_theta 1e-12", Box::new(|c| c.q_theta = 1e-12), 600),
        ("SI2 1200 samples", Box::new(|_| {}), 1200),
        ("SI2 1200, q_h 1e-9", Box::new(|c| c.q_h = [1e-9; 3]), 1200),
        ("SI2 1800 samples", Box::new(|_| {}), 1800),
        ("SI2 1800, q_h 1e-9", Box::new(|c| c.q_h = [1e-9; 3]), 1800),
    ];
    for (name, tune, n2) in &variants {
        let mut hits = [0usize; 9];
        let mut line = String::new();
        for seed in 1..=12u64 {
            let (err, rel_std) = errors_for_seed(seed, tune.as_ref(), *n2);
            for i in 0..9 {
                hits[i] += usize::from(err[i].abs() < 0.05);
            }
            line.push_str(&format!(
                " {:+.1}%(σ{:.1}%)",
                100.0 * err[2],
                100.0 * rel_std[2]
            ));
        }
        eprintln!("{name:>18}: within 5 % per θ″ {hits:?}; θ″3 per seed:{line}");
    }
}
