//! Validation of models that blow up: divergence is a finding with the
//! right channel and time, never a huge number, and every number of the
//! report is finite.
//!
//! The record: surge and pitch of M ν̇ + D̄ ν = γ, decoupled, sampled at
//! h = 0.1 s for 200 s, noise free. Surge is driven by a ±500 N square
//! wave (M = 5000 kg, D̄ = 1000 kg/s, exact ZOH recursion); pitch decays
//! from q₀ = 0.1 rad/s unforced, q(t) = q₀e^{−t} (M = 2000, D̄ = 2000).
//! The model has the right surge and a pitch damping of the wrong sign,
//! A = +1 /s, so its pitch free run is q̂(t) = q₀e^{t}: it leaves the
//! plausible band at t* = ln(upper/q₀), where upper = q̄ + 100·(max q − min q)
//! of the measured pitch.

use nalgebra::DMatrix;
use serde_json::Value;

use super::*;
use crate::models::LinearVesselModel;
use crate::planning::dof::Dof;

const H: f64 = 0.1;
const N: usize = 2000;
const Q0: f64 = 0.1;

/// γ (N × 2) and the measured ν (N × 2).
fn record() -> (DMatrix<f64>, DMatrix<f64>) {
    let gamma = DMatrix::from_fn(N, 2, |k, j| {
        if j == 0 && (k / 200) % 2 == 0 {
            500.0
        } else if j == 0 {
            -500.0
        } else {
            0.0
        }
    });
    let (m, d) = (5000.0, 1000.0);
    let phi = (-d / m * H).exp();
    let mut nu = DMatrix::zeros(N, 2);
    for k in 0..N {
        if k > 0 {
            nu[(k, 0)] = phi * nu[(k - 1, 0)] + (1.0 - phi) / d * gamma[(k - 1, 0)];
        }
        nu[(k, 1)] = Q0 * (-(k as f64) * H).exp();
    }
    (gamma, nu)
}

fn model(pitch_damping: f64) -> LinearVesselModel {
    LinearVesselModel::new(
        vec![Dof::Surge, Dof::Pitch],
        DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![5000.0, 2000.0])),
        DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![1000.0, pitch_damping])),
    )
    .unwrap()
}

/// Every number finite and |x| ≤ 1e15; `null` only where the report says a
/// value may be missing; no `inf`, `NaN` or absurd exponent in any text.
pub(crate) fn assert_all_finite(v: &Value, path: &str) {
    const MAY_BE_NULL: [&str; 10] = [
        "fit_one_step",
        "fit_k_step",
        "fit_restarted",
        "fit_simulation",
        "one_step",
        "k_step",
        "restarted",
        "simulation",
        "ljung_box",
        "plot_correlation",
    ];
    match v {
        Value::Number(n) => {
            let x = n.as_f64().unwrap();
            assert!(x.is_finite() && x.abs() <= 1e15, "{path} = {x}");
        }
        Value::String(s) => {
            let lower = s.to_lowercase();
            assert!(
                !lower.contains("nan") && !lower.contains("inf"),
                "{path}: {s}"
            );
            for (i, _) in s.match_indices('e') {
                let exp: String = s[i + 1..]
                    .chars()
                    .skip_while(|c| *c == '-' || *c == '+')
                    .take_while(char::is_ascii_digit)
                    .collect();
                let big = exp.parse::<u32>().is_ok_and(|e| e >= 16);
                assert!(!big, "{path}: absurd magnitude in {s}");
            }
        }
        Value::Null => {
            let key = path.rsplit('.').next().unwrap_or("");
            let in_plot = path.contains(".plot.");
            assert!(
                in_plot || MAY_BE_NULL.contains(&key),
                "{path} is null: a number that was not finite?"
            );
        }
        Value::Array(a) => a
            .iter()
            .enumerate()
            .for_each(|(i, x)| assert_all_finite(x, &format!("{path}[{i}]"))),
        Value::Object(o) => o
            .iter()
            .for_each(|(k, x)| assert_all_finite(x, &format!("{path}.{k}"))),
        Value::Bool(_) => {}
    }
}

fn validate_on_record(m: &LinearVesselModel) -> ValidationReport {
    let (gamma, nu) = record();
    let rec = ValidationRecord {
        h: H,
        u: &gamma,
        y: &nu,
    };
    validate(m, &rec, &ValidationSettings::default()).unwrap()
}

#[test]
fn a_pitch_free_run_with_a_positive_eigenvalue_diverges_at_the_analytic_time() {
    let report = validate_on_record(&model(-2000.0));
    let json = serde_json::to_value(&report).unwrap();
    assert_all_finite(&json, "report");

    let (surge, pitch) = (&report.channels[0], &report.channels[1]);
    // The measured pitch band: mean + 100 ranges.
    let q: Vec<f64> = (0..N).map(|k| Q0 * (-(k as f64) * H).exp()).collect();
    let mean = q.iter().sum::<f64>() / N as f64;
    let upper = mean + 100.0 * (q[0] - q[N - 1]);
    let t_star = (upper / Q0).ln();
    assert!((t_star - 4.605).abs() < 0.01, "t* = {t_star}");

    let d = pitch
        .diverged
        .simulation
        .as_ref()
        .expect("pitch free run diverged");
    assert_eq!(d.dof, Some(Dof::Pitch));
    assert_eq!(d.output, "q");
    assert_eq!(d.reason, DivergenceReason::OutOfRange);
    assert!(t_star <= d.t_s && d.t_s < t_star + H, "t = {}", d.t_s);
    assert_eq!(d.after_s, d.t_s);
    assert_eq!(pitch.fit_simulation, None);
    assert!(
        pitch
            .verdict
            .contains("free-run simulation diverged at t = 4.7 s in pitch (q)"),
        "{}",
        pitch.verdict
    );
    // The plot stops at the divergence.
    let p = &pitch.plot;
    let last = p.simulated.iter().rposition(Option::is_some).unwrap();
    assert!(p.time_s[last] < d.t_s && p.time_s[last + 1] >= d.t_s);

    // Restarted every 10 s: only the first window starts large enough to
    // pass the band (from q(10 s) = q₀e^{−10} it would need 14.6 s).
    assert_eq!((pitch.restarted.windows, pitch.restarted.diverged), (20, 1));
    let r = pitch.diverged.restarted.as_ref().unwrap();
    assert_eq!((r.t_s, r.after_s), (d.t_s, d.t_s));
    assert!(pitch.fit_restarted.is_some_and(f64::is_finite));
    assert!(
        pitch.verdict.contains(
            "1 of 20 free runs restarted every 10.0 s diverged, the first at t = 4.7 s, 4.7 s after its restart; fit over the other 19: < −1000 %"
        ),
        "{}",
        pitch.verdict
    );
    // One second ahead grows e² relative to the truth: no divergence.
    assert!(pitch.diverged.one_step.is_none() && pitch.diverged.k_step.is_none());
    assert!(pitch.one_step.is_some() && pitch.fit_k_step.is_some());

    // Surge is decoupled and right: its fits stand.
    assert_eq!(surge.diverged, Divergences::default());
    for f in [
        surge.fit_one_step,
        surge.fit_k_step,
        surge.fit_restarted,
        surge.fit_simulation,
    ] {
        assert!(f.unwrap() > 0.999_999, "{f:?}");
    }
}

#[test]
fn a_model_that_explodes_within_one_sample_has_no_fit_at_any_horizon() {
    // A = +200 /s: ×e²⁰ per sample.
    let report = validate_on_record(&model(-400_000.0));
    let json = serde_json::to_value(&report).unwrap();
    assert_all_finite(&json, "report");
    let pitch = &report.channels[1];
    let d = &pitch.diverged;
    let one = d.one_step.as_ref().expect("1-step diverged");
    assert_eq!((one.t_s, one.after_s), (H, H));
    assert_eq!(d.k_step.as_ref().unwrap().after_s, 10.0 * H);
    assert_eq!(d.simulation.as_ref().unwrap().t_s, H);
    assert_eq!(pitch.restarted.diverged, pitch.restarted.windows);
    for f in [
        pitch.fit_one_step,
        pitch.fit_k_step,
        pitch.fit_restarted,
        pitch.fit_simulation,
    ] {
        assert_eq!(f, None);
    }
    assert!(pitch.one_step.is_none() && pitch.k_step.is_none());
    assert!(!pitch.residuals_white && pitch.input_correlations.is_empty());
    assert!(
        pitch
            .verdict
            .starts_with("1-step prediction diverged at t = 0.1 s in pitch (q)")
    );
    assert!(pitch.plot.one_step.iter().all(Option::is_none));
}

#[test]
fn the_finite_walk_catches_a_nan_and_an_absurd_number() {
    let mut json = serde_json::to_value(validate_on_record(&model(2000.0))).unwrap();
    assert_all_finite(&json, "report");
    json["channels"][0]["one_step"]["rms"] = Value::Null;
    let caught = std::panic::catch_unwind(|| assert_all_finite(&json, "report"));
    assert!(caught.is_err(), "a NaN (null) in a number field must fail");
    let mut big = serde_json::to_value(validate_on_record(&model(2000.0))).unwrap();
    big["channels"][1]["verdict"] = Value::String("fit -7.3e35".into());
    let caught = std::panic::catch_unwind(|| assert_all_finite(&big, "report"));
    assert!(caught.is_err(), "an absurd number in text must fail");
}
