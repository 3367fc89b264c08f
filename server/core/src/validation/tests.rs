//! `validate` on a toy first-order model whose residual statistics are
//! known in closed form.
//!
//! Equation-error (ARX) plant y(t) = a·y(t−1) + b·u(t−1) + e(t), e white
//! N(0, σ²), u white N(0, 1). With the true parameters:
//! - 1-step error e(t): white, fit₁ = 1 − σ/s_y, s_y² = (b² + σ²)/(1 − a²);
//! - k-step error Σ_{j<k} a^j e(t−j): MA(k−1), fit_k = 1 − σ·√((1 − a^{2k})/(1 − a²))/s_y;
//! - simulation error Σ_j a^j e(t−j): fit_sim = 1 − σ/(s_y·√(1 − a²));
//! - a free run restarted from the measured y every R samples has the
//!   error Σ_{j<τ} a^j e(t−j) τ samples into its window, so
//!   fit_R = 1 − σ·√((R − (1 − a^{2R})/(1 − a²)) / (R·(1 − a²)))/s_y.
//!
//! Output-error plant x(t) = a·x(t−1) + b·u(t−1), y = x + v: the same
//! predictor leaves v(t) − a·v(t−1), an MA(1) with r(1) = −a/(1 + a²), so
//! fit₁ = 1 − σ·√(1 + a²)/s_y with s_y² = b²/(1 − a²) + σ², and the free-run
//! simulation leaves v itself: fit_sim = 1 − σ/s_y.

use nalgebra::DMatrix;

use super::*;
use crate::rng::SplitMix64;

/// y(t) = a·y(t−1) + Σ gain·u_i(t − delay): (input, delay ≥ 1, gain).
struct FirstOrder {
    a: f64,
    terms: Vec<(usize, usize, f64)>,
}

impl FirstOrder {
    fn drive(&self, u: &DMatrix<f64>, t: usize) -> f64 {
        self.terms
            .iter()
            .filter(|(_, d, _)| t >= *d)
            .map(|(i, d, g)| g * u[(t - d, *i)])
            .sum()
    }
}

impl Predictor for FirstOrder {
    fn output_names(&self) -> Vec<String> {
        vec!["w".to_owned()]
    }

    fn predict_k_step(&self, rec: &ValidationRecord<'_>, k: usize) -> DMatrix<f64> {
        let n = rec.y.nrows();
        let mut out = DMatrix::from_element(n, 1, f64::NAN);
        for t in k..n {
            let mut x = rec.y[(t - k, 0)];
            for s in t - k + 1..=t {
                x = self.a * x + self.drive(rec.u, s);
            }
            out[(t, 0)] = x;
        }
        out
    }

    fn simulate(&self, rec: &ValidationRecord<'_>) -> DMatrix<f64> {
        let n = rec.y.nrows();
        let mut out = DMatrix::zeros(n, 1);
        let mut x = rec.y[(0, 0)];
        out[(0, 0)] = x;
        for t in 1..n {
            x = self.a * x + self.drive(rec.u, t);
            out[(t, 0)] = x;
        }
        out
    }
}

struct Data {
    u: DMatrix<f64>,
    y: DMatrix<f64>,
}

/// A record of `plant` driven by white inputs, with equation-error noise
/// (`output_error` false) or measurement noise (true) of std `sigma`.
fn record(
    plant: &FirstOrder,
    inputs: usize,
    n: usize,
    sigma: f64,
    output_error: bool,
    seed: u64,
) -> Data {
    let mut rng = SplitMix64::new(seed);
    let u = DMatrix::from_fn(n, inputs, |_, _| rng.normal());
    let mut y = DMatrix::zeros(n, 1);
    let mut x = 0.0;
    for t in 0..n {
        let noise = sigma * rng.normal();
        if output_error {
            x = plant.a * x + plant.drive(&u, t);
            y[(t, 0)] = x + noise;
        } else {
            x = plant.a * x + plant.drive(&u, t) + noise;
            y[(t, 0)] = x;
        }
    }
    Data { u, y }
}

fn run(model: &FirstOrder, d: &Data, settings: &ValidationSettings) -> ValidationReport {
    let rec = ValidationRecord {
        h: 0.1,
        u: &d.u,
        y: &d.y,
    };
    validate(model, &rec, settings).unwrap()
}

const A: f64 = 0.9;
const B: f64 = 0.5;
const SIGMA: f64 = 0.2;
const N: usize = 20_000;

fn truth() -> FirstOrder {
    FirstOrder {
        a: A,
        terms: vec![(0, 1, B)],
    }
}

#[test]
fn true_model_has_white_residuals_and_the_analytic_fits() {
    let s = ValidationSettings::default();
    let k = s.k as i32;
    let sy = ((B * B + SIGMA * SIGMA) / (1.0 - A * A)).sqrt();
    let want1 = 1.0 - SIGMA / sy;
    let wantk = 1.0 - SIGMA * ((1.0 - A.powi(2 * k)) / (1.0 - A * A)).sqrt() / sy;
    let wants = 1.0 - SIGMA / (sy * (1.0 - A * A).sqrt());
    // h = 0.1 s, restart every 10 s: R = 100 samples.
    let r = 100.0;
    let a2 = A * A;
    let wantr =
        1.0 - SIGMA * ((r - (1.0 - a2.powf(r)) / (1.0 - a2)) / (r * (1.0 - a2))).sqrt() / sy;
    let want = [want1, wantk, wantr, wants];
    let mut white = 0;
    let seeds = 8;
    let mut mean_fit = [0.0; 4];
    for seed in 0..seeds {
        let d = record(&truth(), 1, N, SIGMA, false, 40 + seed);
        let r = run(&truth(), &d, &s);
        let c = &r.channels[0];
        // Observed spread of the fits between records of N = 20 000 ≈ 0.005.
        let fits = [
            c.fit_one_step,
            c.fit_k_step,
            c.fit_restarted,
            c.fit_simulation,
        ]
        .map(Option::unwrap);
        assert_eq!((c.restarted.windows, c.restarted.diverged), (200, 0));
        assert_eq!(c.diverged, Divergences::default());
        for ((f, want), m) in fits.iter().zip(want).zip(&mut mean_fit) {
            assert!((f - want).abs() < 0.025, "fit {f} vs {want}");
            *m += f / seeds as f64;
        }
        // 1-step residual std is σ.
        assert!((c.one_step.as_ref().unwrap().std / SIGMA - 1.0).abs() < 0.03);
        white += usize::from(c.residuals_white && c.k_step.as_ref().unwrap().white);
        assert!(c.input_correlations.iter().all(|x| !x.leak));
        if seed == 0 {
            assert_eq!(c.verdict, "residuals white");
        }
    }
    assert!(
        white as u64 >= seeds - 1,
        "white in {white}/{seeds} records"
    );
    // The mean over records is within its standard error (≈ 0.002).
    for (m, want) in mean_fit.iter().zip(want) {
        assert!((m - want).abs() < 0.008, "mean fit {m} vs {want}");
    }
}

#[test]
fn wrong_pole_is_flagged_as_unmodelled_dynamics_with_input_leak() {
    let s = ValidationSettings::default();
    let d = record(&truth(), 1, N, SIGMA, false, 7);
    let good = run(&truth(), &d, &s);
    let wrong = FirstOrder {
        a: 0.6,
        terms: vec![(0, 1, B)],
    };
    let r = run(&wrong, &d, &s);
    let c = &r.channels[0];
    assert!(!c.residuals_white && !c.k_step.as_ref().unwrap().white);
    assert!(c.one_step.as_ref().unwrap().whiteness_p_value < 1e-50);
    assert!(
        c.verdict.contains("residual correlated at lags 1–"),
        "{}",
        c.verdict
    );
    assert!(c.verdict.contains("unmodelled dynamics"));
    // e' = e + (0.9 − 0.6)·y(t−1), and y(t−1) carries u(t−2) first.
    let x = &c.input_correlations[0];
    assert!(x.leak && x.peak_lag == 2, "{x:?}");
    assert!(
        c.verdict
            .contains("input u_1 leaks into the residual at lag 2: missing coupling or delay")
    );
    assert!(c.fit_one_step.unwrap() < good.channels[0].fit_one_step.unwrap() - 0.05);
    // Its residual is Gaussian: correlation alone must not read as non-normal.
    assert!(!c.verdict.contains("not normal"), "{}", c.verdict);
}

#[test]
fn missing_input_leaks_at_its_delay_while_residuals_stay_white() {
    let plant = FirstOrder {
        a: A,
        terms: vec![(0, 1, B), (1, 2, 0.4)],
    };
    let d = record(&plant, 2, N, SIGMA, false, 8);
    let s = ValidationSettings {
        input_names: vec!["tau_Z".into(), "tau_M".into()],
        ..Default::default()
    };
    let r = run(&truth(), &d, &s);
    let c = &r.channels[0];
    // The predictor uses measured y, so the missing term enters once: the
    // residual e + 0.4·u₂(t−2) is white, only the cross-correlation sees it.
    assert!(c.residuals_white, "{}", c.verdict);
    assert!(!c.input_correlations[0].leak);
    let x = &c.input_correlations[1];
    assert!(x.leak && x.peak_lag == 2);
    // r = 0.4/√(0.4² + σ²) at lag 2.
    assert!((x.peak_value - 0.4 / (0.16f64 + SIGMA * SIGMA).sqrt()).abs() < 0.03);
    assert!(
        c.verdict
            .contains("input tau_M leaks into the residual at lag 2"),
        "{}",
        c.verdict
    );
}

#[test]
fn measurement_noise_gives_the_ma1_residual_of_theory() {
    let s = ValidationSettings::default();
    let d = record(&truth(), 1, N, SIGMA, true, 9);
    let r = run(&truth(), &d, &s);
    let c = &r.channels[0];
    let sy = (B * B / (1.0 - A * A) + SIGMA * SIGMA).sqrt();
    let want1 = 1.0 - SIGMA * (1.0 + A * A).sqrt() / sy;
    assert!(
        (c.fit_one_step.unwrap() - want1).abs() < 0.01,
        "{:?} vs {want1}",
        c.fit_one_step
    );
    assert!((c.fit_simulation.unwrap() - (1.0 - SIGMA / sy)).abs() < 0.01);
    let r1 = -A / (1.0 + A * A);
    let one_step = c.one_step.as_ref().unwrap();
    assert!((one_step.autocorrelation.values[1] - r1).abs() < 0.03);
    assert!(!c.residuals_white);
    assert!(
        c.verdict.contains("residual correlated at lag"),
        "{}",
        c.verdict
    );
    // MA(1) Gaussian: P(sign change) = arccos(r₁)/π ≈ 0.67 > ½.
    let zc = &one_step.zero_crossings;
    let want = (zc.expected * 2.0) * r1.acos() / std::f64::consts::PI;
    assert!((zc.count as f64 - want).abs() < 5.0 * want.sqrt());
    assert!(c.verdict.contains("too many zero crossings"));
}

#[test]
fn plot_series_are_thinned_unless_full_resolution_is_asked() {
    let d = record(&truth(), 1, 5000, SIGMA, false, 3);
    let s = ValidationSettings {
        plot_points: 400,
        ..Default::default()
    };
    let r = run(&truth(), &d, &s);
    let p = &r.channels[0].plot;
    assert_eq!(p.stride, 13);
    assert_eq!(p.time_s.len(), 5000usize.div_ceil(13));
    assert!(p.time_s.len() <= 400);
    assert!((p.time_s[1] - 1.3).abs() < 1e-12);
    assert_eq!(p.measured[2], d.y[(26, 0)]);
    assert!(p.k_step[0].is_none() && p.one_step[0].is_none() && p.simulated[0].is_some());
    // Restarted every 10 s = 100 samples: exact at each restart.
    assert_eq!(p.restarted[0], Some(d.y[(0, 0)]));
    assert_eq!(r.restart_s, 10.0);
    let full = run(
        &truth(),
        &d,
        &ValidationSettings {
            full_resolution: true,
            ..Default::default()
        },
    );
    assert_eq!(full.channels[0].plot.measured.len(), 5000);
    // The report serializes with engineer-readable names; NaN becomes null.
    let json = serde_json::to_value(&r).unwrap();
    let ch = &json["channels"][0];
    assert!(ch["fit_one_step"].is_number() && ch["plot"]["k_step"][0].is_null());
    assert_eq!(ch["verdict"], "residuals white");
    assert!(ch["one_step"]["zero_crossings"]["expected"].is_number());
    // Settings default field by field.
    let s: ValidationSettings = serde_json::from_str(r#"{"k": 5}"#).unwrap();
    assert_eq!((s.k, s.max_lag, s.confidence), (5, 50, 0.99));
}

struct Broken;

impl Predictor for Broken {
    fn output_names(&self) -> Vec<String> {
        vec!["w".to_owned()]
    }
    fn predict_k_step(&self, rec: &ValidationRecord<'_>, _k: usize) -> DMatrix<f64> {
        let mut m = DMatrix::zeros(rec.y.nrows(), 1);
        m[(100, 0)] = f64::NAN;
        m
    }
    fn simulate(&self, rec: &ValidationRecord<'_>) -> DMatrix<f64> {
        DMatrix::zeros(rec.y.nrows(), 2)
    }
}

#[test]
fn bad_records_settings_and_models_are_named_errors() {
    let d = record(&truth(), 1, 500, SIGMA, false, 1);
    let s = ValidationSettings::default();
    let rec = |u: &'_ DMatrix<f64>, y: &'_ DMatrix<f64>| {
        validate(&truth(), &ValidationRecord { h: 0.1, u, y }, &s).map(|_| ())
    };
    let short_u = d.u.rows(0, 400).into_owned();
    assert_eq!(rec(&short_u, &d.y).unwrap_err().field(), "u");
    let mut y_nan = d.y.clone();
    y_nan[(42, 0)] = f64::NAN;
    assert!(matches!(
        rec(&d.u, &y_nan),
        Err(ValidationError::NonFinite { index: 42, .. })
    ));
    let tiny = d.y.rows(0, 40).into_owned();
    let tiny_u = d.u.rows(0, 40).into_owned();
    assert_eq!(rec(&tiny_u, &tiny).unwrap_err().field(), "y");
    let recd = ValidationRecord {
        h: 0.1,
        u: &d.u,
        y: &d.y,
    };
    for (bad, field) in [
        (
            ValidationSettings {
                k: 0,
                ..Default::default()
            },
            "settings.k",
        ),
        (
            ValidationSettings {
                max_lag: 5,
                ..Default::default()
            },
            "settings.max_lag",
        ),
        (
            ValidationSettings {
                confidence: 0.0,
                ..Default::default()
            },
            "settings.confidence",
        ),
        (
            ValidationSettings {
                input_names: vec!["a".into(), "b".into()],
                ..Default::default()
            },
            "settings.input_names",
        ),
    ] {
        assert_eq!(validate(&truth(), &recd, &bad).unwrap_err().field(), field);
    }
    let bad_h = ValidationRecord { h: 0.0, ..recd };
    assert_eq!(validate(&truth(), &bad_h, &s).unwrap_err().field(), "h");
    let e = validate(&Broken, &recd, &s).unwrap_err();
    assert!(matches!(e, ValidationError::ModelOutput { .. }));
    assert_eq!(e.field(), "simulate");
}
