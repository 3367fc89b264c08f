//! Static runs synthesized from Fossen's general g(η) (1994, eq. 4.6) with
//! known W, B, r_G, r_B and tether moment, with thrust, attitude and
//! velocity noise, and the estimate checked against the truth.

use nalgebra::DMatrix;

use super::*;
use crate::rng::SplitMix64;

struct Truth {
    w: f64,
    b: f64,
    r_g: [f64; 3],
    r_b: [f64; 3],
    tether: f64,
}

impl Truth {
    fn rov() -> Self {
        // A 5-t work-class ROV, origin 0.1 m above the CoG, CoB 0.25 m
        // above the origin.
        Truth {
            w: 5000.0 * 9.81,
            b: 48_500.0,
            r_g: [0.0, 0.0, 0.1],
            r_b: [0.0, 0.0, -0.25],
            tether: -1570.0,
        }
    }

    /// Fossen (1994) eq. 4.6, every term, plus τ_θ in pitch.
    fn tau_static(&self, phi: f64, theta: f64) -> [f64; 6] {
        let (w, b) = (self.w, self.b);
        let [xg, yg, zg] = self.r_g;
        let [xb, yb, zb] = self.r_b;
        let (sp, cp) = phi.sin_cos();
        let (st, ct) = theta.sin_cos();
        [
            (w - b) * st,
            -(w - b) * ct * sp,
            -(w - b) * ct * cp,
            -(yg * w - yb * b) * ct * cp + (zg * w - zb * b) * ct * sp,
            (zg * w - zb * b) * st + (xg * w - xb * b) * ct * cp + self.tether,
            -(xg * w - xb * b) * ct * sp - (yg * w - yb * b) * st,
        ]
    }

    fn params(&self) -> RestoringParams {
        RestoringParams {
            weight_minus_buoyancy_n: self.w - self.b,
            zg_weight_minus_zb_buoyancy_nm: self.r_g[2] * self.w - self.r_b[2] * self.b,
            tether_pitch_moment_nm: self.tether,
        }
    }
}

struct Noise {
    force: f64,
    moment: f64,
    angle: f64,
    velocity: f64,
}

const QUIET: Noise = Noise {
    force: 0.0,
    moment: 0.0,
    angle: 0.0,
    velocity: 0.0,
};

struct Run {
    nu: DMatrix<f64>,
    eta: DMatrix<f64>,
    tau: DMatrix<f64>,
    /// τ − g_true(η_true): the dynamic part plus thrust noise.
    dynamic: DMatrix<f64>,
    /// Sample ranges of the holds.
    holds: Vec<(usize, usize)>,
}

const H: f64 = 0.1;
const HOLD_S: f64 = 30.0;
const MOVE_S: f64 = 6.0;

/// Holds at (φ, θ) in degrees joined by manoeuvres in which the vehicle
/// moves (surge speed, pitch/roll rates) and the thrusters work against
/// more than g(η).
fn static_run(truth: &Truth, holds_deg: &[(f64, f64)], noise: &Noise, seed: u64) -> Run {
    let mut rng = SplitMix64::new(seed);
    let hold = (HOLD_S / H) as usize;
    let mv = (MOVE_S / H) as usize;
    let n = holds_deg.len() * hold + (holds_deg.len() - 1) * mv;
    let (mut nu, mut eta, mut tau) = (
        DMatrix::zeros(n, 6),
        DMatrix::zeros(n, 6),
        DMatrix::zeros(n, 6),
    );
    let mut dynamic = DMatrix::zeros(n, 6);
    let mut holds = Vec::new();
    let mut t = 0;
    for (i, &(phi_d, theta_d)) in holds_deg.iter().enumerate() {
        let (phi, theta) = (phi_d.to_radians(), theta_d.to_radians());
        holds.push((t, t + hold));
        for _ in 0..hold {
            let g = truth.tau_static(phi, theta);
            for j in 0..6 {
                let sigma = if j < 3 { noise.force } else { noise.moment };
                let e = sigma * rng.normal();
                tau[(t, j)] = g[j] + e;
                dynamic[(t, j)] = e;
                let vs = noise.velocity * if j < 3 { 1.0 } else { 0.2 };
                nu[(t, j)] = vs * rng.normal();
            }
            eta[(t, 3)] = phi + noise.angle * rng.normal();
            eta[(t, 4)] = theta + noise.angle * rng.normal();
            eta[(t, 2)] = 120.0;
            t += 1;
        }
        if let Some(&(phi2_d, theta2_d)) = holds_deg.get(i + 1) {
            let (phi2, theta2) = (phi2_d.to_radians(), theta2_d.to_radians());
            for k in 0..mv {
                let s = (k as f64 + 0.5) / mv as f64;
                let (ph, th) = (phi + s * (phi2 - phi), theta + s * (theta2 - theta));
                let bump = (std::f64::consts::PI * s).sin();
                nu[(t, 0)] = 0.3 * bump;
                nu[(t, 3)] = (phi2 - phi) / MOVE_S;
                nu[(t, 4)] = (theta2 - theta) / MOVE_S + 0.05 * bump;
                eta[(t, 3)] = ph;
                eta[(t, 4)] = th;
                let g = truth.tau_static(ph, th);
                for j in 0..6 {
                    let d = 800.0 * bump * (j as f64 + 1.0);
                    tau[(t, j)] = g[j] + d;
                    dynamic[(t, j)] = d;
                }
                t += 1;
            }
        }
    }
    Run {
        nu,
        eta,
        tau,
        dynamic,
        holds,
    }
}

fn record(run: &Run) -> StaticRecord<'_> {
    StaticRecord {
        h: H,
        nu: &run.nu,
        eta: &run.eta,
        tau: &run.tau,
    }
}

const PLAN: [(f64, f64); 7] = [
    (0.0, 0.0),
    (0.0, 10.0),
    (0.0, 5.0),
    (0.0, -5.0),
    (0.0, -10.0),
    (8.0, 0.0),
    (-8.0, 0.0),
];

#[test]
fn g_is_fossens_general_form_with_the_thesis_centre_of_buoyancy() {
    let truth = Truth::rov();
    let p = truth.params();
    let mut rng = SplitMix64::new(1);
    for _ in 0..100 {
        let (phi, theta) = (rng.uniform_in(-1.0, 1.0), rng.uniform_in(-1.0, 1.0));
        let g = p.g(&[3.0, -2.0, 100.0, phi, theta, 0.7]);
        let want = truth.tau_static(phi, theta);
        for j in 0..6 {
            assert!(
                (g[j] - want[j]).abs() < 1e-9 * 5e4,
                "dof {j}: {} vs {}",
                g[j],
                want[j]
            );
        }
    }
}

#[test]
fn noise_free_runs_give_the_exact_parameters_and_gamma() {
    let truth = Truth::rov();
    let run = static_run(&truth, &PLAN, &QUIET, 0);
    let est = estimate_restoring(&[record(&run)], &RestoringSettings::default()).unwrap();
    let (p, want) = (est.params, truth.params());
    assert!((p.weight_minus_buoyancy_n - want.weight_minus_buoyancy_n).abs() < 1e-8);
    assert!((p.zg_weight_minus_zb_buoyancy_nm - want.zg_weight_minus_zb_buoyancy_nm).abs() < 1e-8);
    assert!((p.tether_pitch_moment_nm - want.tether_pitch_moment_nm).abs() < 1e-8);
    // One segment per hold, inside it, covering it.
    assert_eq!(est.segments.len(), PLAN.len());
    for (s, &(a, b)) in est.segments.iter().zip(&run.holds) {
        assert_eq!((s.start, s.end), (a, b));
        assert!((s.duration_s - HOLD_S).abs() < 1e-9);
    }
    assert!((est.segments[1].pitch_deg - 10.0).abs() < 1e-9);
    // γ = τ − g(η) is exactly the part of τ that is not restoring wherever
    // the attitude holds over the step (γ averages g over each step).
    let gamma = p.gamma(&run.tau, &run.eta).unwrap();
    let n = gamma.nrows();
    let held: Vec<usize> = (0..n - 1)
        .filter(|&k| (0..6).all(|j| run.eta[(k, j)] == run.eta[(k + 1, j)]))
        .collect();
    assert!(
        held.len() > n / 2,
        "{} of {n} steps hold the attitude",
        held.len()
    );
    let err = held
        .iter()
        .map(|&k| (gamma.row(k) - run.dynamic.row(k)).abs().max())
        .fold(0.0, f64::max);
    assert!(err < 1e-8, "γ error {err}");
    assert!(est.residual_rms.iter().all(|r| *r < 1e-8));
}

#[test]
fn stated_uncertainty_covers_the_truth() {
    let truth = Truth::rov();
    let want = truth.params();
    let noise = Noise {
        force: 150.0,
        moment: 120.0,
        angle: 0.05f64.to_radians(),
        velocity: 0.004,
    };
    let seeds = 60;
    let mut within1 = [0usize; 3];
    let mut within2 = [0usize; 3];
    let mut z2 = [0.0; 3];
    for seed in 0..seeds {
        // Two separate experiments, never concatenated.
        let a = static_run(&truth, &PLAN[..4], &noise, 100 + seed);
        let b = static_run(&truth, &PLAN[4..], &noise, 900 + seed);
        let est =
            estimate_restoring(&[record(&a), record(&b)], &RestoringSettings::default()).unwrap();
        assert_eq!(est.segments.len(), PLAN.len());
        assert_eq!(est.segments[5].record, 1);
        let got = [
            (
                est.params.weight_minus_buoyancy_n,
                est.std.weight_minus_buoyancy_n,
                want.weight_minus_buoyancy_n,
            ),
            (
                est.params.zg_weight_minus_zb_buoyancy_nm,
                est.std.zg_weight_minus_zb_buoyancy_nm,
                want.zg_weight_minus_zb_buoyancy_nm,
            ),
            (
                est.params.tether_pitch_moment_nm,
                est.std.tether_pitch_moment_nm,
                want.tether_pitch_moment_nm,
            ),
        ];
        // The std a known noise gives: segment means of 300 samples, so
        // σ/√300 per equation, through (AᵀA)⁻¹ of the segment regressors.
        let (mut s11, mut s12) = (0.0, 0.0);
        for g in &est.segments {
            s11 += g.regressors[0].powi(2) + g.regressors[1].powi(2);
            s12 += g.regressors[0];
        }
        let s22 = est.segments.len() as f64;
        let det = s11 * s22 - s12 * s12;
        let per_mean = |sigma: f64| sigma / (HOLD_S / H).sqrt();
        let expected = [
            per_mean(noise.force) / s22.sqrt(),
            per_mean(noise.moment) * (s22 / det).sqrt(),
            per_mean(noise.moment) * (s11 / det).sqrt(),
        ];
        for (i, (x, s, t)) in got.iter().enumerate() {
            // A variance estimated on 12–20 dof: within a factor ≈ 2.
            let ratio = s / expected[i];
            assert!(
                (0.45..=1.8).contains(&ratio),
                "param {i}: std {s}, expected {}",
                expected[i]
            );
            let z = (x - t) / s;
            within1[i] += usize::from(z.abs() < 1.0);
            within2[i] += usize::from(z.abs() < 2.0);
            z2[i] += z * z / seeds as f64;
        }
    }
    // Nominal coverage (t with 12–20 dof): ≈ 67 % within 1σ, ≈ 94 % within
    // 2σ; E z² ≈ 1.1. Bounds allow for 60 draws (binomial sd ≈ 6 %).
    for i in 0..3 {
        let (c1, c2) = (
            within1[i] as f64 / seeds as f64,
            within2[i] as f64 / seeds as f64,
        );
        assert!((0.48..=0.86).contains(&c1), "param {i}: 1σ coverage {c1}");
        assert!(c2 >= 0.83, "param {i}: 2σ coverage {c2}");
        assert!((0.5..=2.0).contains(&z2[i]), "param {i}: mean z² {}", z2[i]);
    }
}

#[test]
fn level_holds_only_say_which_experiment_is_missing() {
    let truth = Truth::rov();
    let noise = Noise {
        force: 50.0,
        moment: 50.0,
        angle: 0.0,
        velocity: 0.002,
    };
    let run = static_run(&truth, &[(0.0, 0.0); 4], &noise, 3);
    let err = estimate_restoring(&[record(&run)], &RestoringSettings::default()).unwrap_err();
    assert!(
        matches!(err, RestoringError::NotIdentifiable { .. }),
        "{err}"
    );
    assert_eq!(err.field(), "eta.theta");
    assert!(
        err.message()
            .contains("static holds at two or more pitch angles"),
        "{err}"
    );
    assert!(err.message().contains("4 steady segments"));
    // One hold only: too few segments, with what to record.
    let one = static_run(&truth, &[(0.0, 5.0)], &noise, 4);
    let err = estimate_restoring(&[record(&one)], &RestoringSettings::default()).unwrap_err();
    assert!(matches!(
        err,
        RestoringError::TooFewSteadySegments {
            found: 1,
            required: 3,
            ..
        }
    ));
    assert_eq!(err.field(), "segments");
}

#[test]
fn a_thrust_step_at_constant_attitude_splits_the_segment() {
    // The vehicle stays level and still, but the heave thrust steps by
    // 20 σ halfway: not one static condition but two.
    let truth = Truth::rov();
    let noise = Noise {
        force: 40.0,
        moment: 40.0,
        angle: 0.0,
        velocity: 0.002,
    };
    let mut run = static_run(&truth, &[(0.0, 0.0)], &noise, 5);
    let n = run.tau.nrows();
    for t in n / 2..n {
        run.tau[(t, 2)] += 800.0;
    }
    let segs = find_steady_segments(&record(&run), 0, &SteadySettings::default()).unwrap();
    assert_eq!(segs.len(), 2, "{segs:?}");
    assert_eq!(segs[1].start, n / 2);
    assert!((segs[1].tau_mean[2] - segs[0].tau_mean[2] - 800.0).abs() < 20.0);
}

#[test]
fn malformed_records_are_named_errors() {
    let truth = Truth::rov();
    let run = static_run(&truth, &PLAN[..3], &QUIET, 0);
    let s = RestoringSettings::default();
    let five = run.tau.columns(0, 5).into_owned();
    let bad = StaticRecord {
        tau: &five,
        ..record(&run)
    };
    assert_eq!(estimate_restoring(&[bad], &s).unwrap_err().field(), "tau");
    let mut eta = run.eta.clone();
    eta[(12, 4)] = f64::NAN;
    let bad = StaticRecord {
        eta: &eta,
        ..record(&run)
    };
    assert!(matches!(
        estimate_restoring(&[bad], &s),
        Err(RestoringError::NonFinite { index: 12, .. })
    ));
    let bad = StaticRecord {
        h: -1.0,
        ..record(&run)
    };
    assert_eq!(estimate_restoring(&[bad], &s).unwrap_err().field(), "h");
    assert_eq!(estimate_restoring(&[], &s).unwrap_err().field(), "records");
    let p = truth.params();
    assert_eq!(p.gamma(&five, &run.eta).unwrap_err().field(), "tau");
    let short = run.eta.rows(0, 10).into_owned();
    assert_eq!(p.gamma(&run.tau, &short).unwrap_err().field(), "eta");
    let settings = RestoringSettings {
        steady: SteadySettings {
            min_duration_s: 0.0,
            ..Default::default()
        },
        ..Default::default()
    };
    assert_eq!(
        estimate_restoring(&[record(&run)], &settings)
            .unwrap_err()
            .field(),
        "settings.steady.min_duration_s"
    );
}

/// γ holds the restoring averaged over each sample interval: for a pitch
/// angle rising linearly, row k is τ_k − g at t_k + h/2 to second order
/// (the ZOH the models downstream assume), not g at t_k.
#[test]
fn gamma_takes_the_restoring_at_the_middle_of_each_step() {
    let p = RestoringParams {
        weight_minus_buoyancy_n: 0.0,
        zg_weight_minus_zb_buoyancy_nm: 10_000.0,
        tether_pitch_moment_nm: 0.0,
    };
    let (n, h, rate) = (50, 0.1, 0.02); // θ(t) = 0.02 rad/s · t
    let tau = DMatrix::zeros(n, 6);
    let eta = DMatrix::from_fn(n, 6, |k, j| if j == 4 { rate * k as f64 * h } else { 0.0 });
    let gamma = p.gamma(&tau, &eta).unwrap();
    for k in 0..n - 1 {
        let mid = 10_000.0 * (rate * (k as f64 + 0.5) * h).sin();
        // Trapezoid vs midpoint: |error| ≤ K·(rate·h)²/8.
        assert!(
            (gamma[(k, 4)] + mid).abs() < 1e-3,
            "row {k}: {} vs {}",
            gamma[(k, 4)],
            -mid
        );
    }
}
