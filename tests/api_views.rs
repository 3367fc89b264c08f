//! The engineer's plot data over REST: a flown ROV campaign identified by
//! the λ-filter (continuous LPV) and by N4SID (discrete), then its Bode
//! (alone and over a run's empirical H1 and coherence), poles and zeros,
//! step and impulse responses, Hankel singular values, a run's time plot
//! with window statistics, and the overlay compare of three models. The
//! numbers are checked against the stored matrices (poles = eig A, the DC
//! gain −C A⁻¹ B at low frequency and at the end of the step), every answer
//! against its documented schema and for finite numbers, and each
//! parameter's error is a 4xx naming it.

mod common;

use common::finite::{assert_finite_json, get_finite};
use common::flights::{flown_campaign, linear_truth};
use common::{TestApp, identified};
use nalgebra::DMatrix;
use seatrial::jobs::{JobRegistry, JobsConfig};
use seatrial_core::identification::document::from_rows;
use serde_json::Value;

fn matrix(v: &Value) -> DMatrix<f64> {
    from_rows(&serde_json::from_value(v.clone()).unwrap()).expect("rectangular")
}

async fn status_field(app: &TestApp, template: &str, args: &[&str]) -> (u16, String) {
    let r = app.call("GET", template, args, None).await;
    (
        r.status.as_u16(),
        r.json["field"].as_str().unwrap_or("").to_string(),
    )
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn plot_data_of_identified_models_and_of_a_run() {
    let app = TestApp::with_jobs(JobRegistry::production(), JobsConfig::default()).await;
    let cid = flown_campaign(&app, &linear_truth()).await;
    let lpv = identified(&app, &cid, "lambda_kf").await;
    let n4 = identified(&app, &cid, "n4sid").await;
    let view = get_finite(&app, "/api/models/{id}", &[&lpv]).await;
    let points = view["document"]["lpv"]["points"]
        .as_array()
        .unwrap()
        .clone();
    let val_run = view["validation_run_ids"][0].as_str().unwrap().to_string();
    let n_dof = view["document"]["dofs"].as_array().unwrap().len();

    // Poles: the eigenvalues of each grid point's A, in the s plane.
    let pz = get_finite(&app, "/api/models/{id}/poles", &[&lpv]).await;
    let maps = pz["points"].as_array().unwrap();
    assert_eq!(maps.len(), points.len());
    for (map, point) in maps.iter().zip(&points) {
        assert_eq!(map["plane"], "s");
        assert_eq!(map["grid_speed_mps"], point["speed_mps"]);
        let eig = matrix(&point["a"]).complex_eigenvalues();
        let poles = map["poles"].as_array().unwrap();
        assert_eq!(poles.len(), n_dof);
        for p in poles {
            let (re, im) = (p["re"].as_f64().unwrap(), p["im"].as_f64().unwrap());
            assert!(
                eig.iter()
                    .any(|z| (z.re - re).abs() + (z.im - im).abs() < 1e-9 * (1.0 + z.norm())),
                "pole {re}+{im}j not an eigenvalue of A: {eig:?}"
            );
        }
        assert_eq!(map["channels"].as_array().unwrap().len(), n_dof * n_dof);
    }
    assert!(pz["zeros_are"].as_str().unwrap().contains("SISO"));

    // Bode: the lowest frequency reads the DC gain −A⁻¹B of a stable point.
    let fr = get_finite(
        &app,
        "/api/models/{id}/frequency-response?points=300",
        &[&lpv],
    )
    .await;
    let freqs = fr["freqs_hz"].as_array().unwrap();
    assert_eq!(freqs.len(), 300);
    let step = get_finite(&app, "/api/models/{id}/step-response?kind=step", &[&lpv]).await;
    for (k, point) in points.iter().enumerate() {
        let a = matrix(&point["a"]);
        if a.complex_eigenvalues().iter().any(|z| z.re >= 0.0) {
            continue;
        }
        let dc = -(a.clone().try_inverse().unwrap() * matrix(&point["b"]));
        let ch = &fr["points"][k]["channels"][0];
        assert_eq!(ch["unit"], "m/s per N", "{ch}");
        let low = 10f64.powf(ch["magnitude_db"][0].as_f64().unwrap() / 20.0);
        assert!(
            (low - dc[(0, 0)].abs()).abs() < 0.01 * dc[(0, 0)].abs(),
            "{low} vs {}",
            dc[(0, 0)]
        );
        // The step settles on the same gain (six time constants: within 0.5 %).
        let s = &step["points"][k]["channels"][0];
        let last = s["values"]
            .as_array()
            .unwrap()
            .last()
            .unwrap()
            .as_f64()
            .unwrap();
        assert!(
            (last - dc[(0, 0)]).abs() < 0.005 * dc[(0, 0)].abs(),
            "{last} vs {}",
            dc[(0, 0)]
        );
        assert!(s.get("diverged_at_s").is_none());
    }
    let imp = get_finite(
        &app,
        "/api/models/{id}/step-response?kind=impulse&t_end_s=20",
        &[&lpv],
    )
    .await;
    assert_eq!(imp["kind"], "impulse");
    let t = imp["points"][0]["time_s"].as_array().unwrap();
    assert!((t.last().unwrap().as_f64().unwrap() - 20.0).abs() < 1e-9);

    // Over a run's H1: the run's grid, its coherence in [0, 1].
    let fr = get_finite(
        &app,
        "/api/models/{id}/frequency-response?run_id={r}",
        &[&lpv, &val_run],
    )
    .await;
    let run = &fr["run"];
    assert_eq!(run["run_id"], val_run.as_str());
    let chans = run["channels"].as_array().unwrap();
    assert!(!chans.is_empty(), "{run}");
    let c0 = &chans[0];
    assert!(c0["input"].as_str().unwrap().starts_with("tau_"), "{c0}");
    let n = fr["freqs_hz"].as_array().unwrap().len();
    assert_eq!(c0["coherence"].as_array().unwrap().len(), n);
    assert!(
        c0["coherence"]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(Value::as_f64)
            .all(|g| (0.0..=1.0 + 1e-12).contains(&g))
    );

    // Hankel singular values: descending, positive; N4SID also its subspace values.
    let hv = get_finite(&app, "/api/models/{id}/hankel", &[&lpv]).await;
    let v: Vec<f64> = hv["points"][0]["values"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert_eq!(v.len(), n_dof);
    assert!(
        v.windows(2).all(|w| w[0] >= w[1]) && v.iter().all(|x| *x > 0.0),
        "{v:?}"
    );
    let hv = get_finite(&app, "/api/models/{id}/hankel", &[&n4]).await;
    let nv = get_finite(&app, "/api/models/{id}", &[&n4]).await;
    assert_eq!(
        hv["subspace"]["order"],
        nv["document"]["state_space"]["order"]
    );
    assert!(!hv["subspace"]["values"].as_array().unwrap().is_empty());
    let pz = get_finite(&app, "/api/models/{id}/poles", &[&n4]).await;
    assert_eq!(pz["points"][0]["plane"], "z");
    // A discrete model's Bode stops at its Nyquist frequency.
    let fr = get_finite(&app, "/api/models/{id}/frequency-response", &[&n4]).await;
    let h = nv["document"]["state_space"]["h"].as_f64().unwrap();
    let top = fr["freqs_hz"]
        .as_array()
        .unwrap()
        .last()
        .unwrap()
        .as_f64()
        .unwrap();
    assert!(
        top <= 0.5 / h * (1.0 + 1e-12),
        "{top} vs Nyquist {}",
        0.5 / h
    );
    get_finite(&app, "/api/models/{id}/step-response?kind=impulse", &[&n4]).await;

    // A run's time plot, then a window with its statistics.
    let tr = get_finite(&app, "/api/runs/{id}/traces?points=400", &[&val_run]).await;
    let names: Vec<&str> = tr["channels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["name"].as_str().unwrap())
        .collect();
    assert!(
        names.contains(&"tau_X") && names.contains(&"u"),
        "{names:?}"
    );
    let unit = |tr: &Value, n: &str| {
        tr["channels"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["name"] == n)
            .unwrap()["unit"]
            .clone()
    };
    assert_eq!(unit(&tr, "tau_X"), "N");
    assert_eq!(unit(&tr, "u"), "m/s");
    assert!(tr["stride"].as_u64().unwrap() > 1 && tr["time_s"].as_array().unwrap().len() <= 402);
    let [t0, t1] = [
        tr["record_s"][0].as_f64().unwrap(),
        tr["record_s"][1].as_f64().unwrap(),
    ];
    let (a, b) = (t0 + 10.0, t0 + 20.0);
    let w = get_finite(
        &app,
        "/api/runs/{id}/traces?from_s={a}&to_s={b}",
        &[&val_run, &a.to_string(), &b.to_string()],
    )
    .await;
    assert_eq!(w["stride"], 1);
    assert!(
        (w["window_s"][0].as_f64().unwrap() - a).abs() < 0.11
            && w["window_s"][1].as_f64().unwrap() <= b + 1e-9
    );
    let u = w["channels"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["name"] == "u")
        .unwrap();
    let shown: Vec<f64> = u["values"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(Value::as_f64)
        .collect();
    let mean = shown.iter().sum::<f64>() / shown.len() as f64;
    assert_eq!(u["stats"]["n"].as_u64().unwrap() as usize, shown.len());
    assert!((u["stats"]["mean"].as_f64().unwrap() - mean).abs() < 1e-12 * (1.0 + mean.abs()));
    assert!(t1 > b);

    // Three models overlaid on one run.
    let r = app
        .call(
            "GET",
            "/api/models/compare?a={a}&b={b}&more={m}&run_id={r}",
            &[&lpv, &n4, &lpv, &val_run],
            None,
        )
        .await;
    assert_eq!(r.status, 200, "{}", r.text);
    assert_eq!(r.json["models"].as_array().unwrap().len(), 3);
    assert_finite_json(&r.json, "compare");

    // Errors name the parameter (a 400 of a malformed value names it too).
    let more = [lpv.as_str(); 5].join(",");
    let compare = "/api/models/compare?a={a}&b={b}&more={m}&run_id={r}";
    let cases: [(&str, Vec<&str>, u16, &str); 9] = [
        (
            "/api/models/{id}/step-response?t_end_s=-1",
            vec![&lpv],
            422,
            "t_end_s",
        ),
        (
            "/api/models/{id}/step-response?kind=ramp",
            vec![&lpv],
            400,
            "kind",
        ),
        (
            "/api/models/{id}/frequency-response?points=1",
            vec![&lpv],
            422,
            "points",
        ),
        (
            "/api/models/{id}/frequency-response?run_id=nope",
            vec![&lpv],
            404,
            "run_id",
        ),
        ("/api/models/{id}/hankel?h=0.5", vec![&n4], 422, "h"),
        ("/api/models/{id}/poles", vec!["no-such-model"], 404, ""),
        (
            "/api/runs/{id}/traces?from_s=1e9",
            vec![&val_run],
            422,
            "to_s",
        ),
        (
            "/api/runs/{id}/traces?points=3",
            vec![&val_run],
            422,
            "points",
        ),
        (compare, vec![&lpv, &lpv, &more, &val_run], 422, "more"),
    ];
    for (template, args, status, field) in cases {
        let (s, f) = status_field(&app, template, &args).await;
        assert_eq!((s, f.as_str()), (status, field), "{template}");
    }
}
