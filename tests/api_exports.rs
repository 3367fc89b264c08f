//! The numeric exports told true: identified models (λ LPV and N4SID of a
//! flown ROV campaign, the parallel EKF's DP ship) exported as `.npz`,
//! `ss_json` and `ss_csv`; the arrays read back equal to the stored
//! matrices bit for bit, the state-space matrices reproduce the service's
//! own ZOH step response (`GET /api/models/{id}?h=`), and
//! `tests/python/check_exports.py` loads the same files with numpy/scipy
//! (and the `.m` script with Octave when installed) and reproduces that
//! response to 1e-9. `make test` installs numpy and scipy (`make py-deps`);
//! without them the Python half says so and is skipped, except under CI.

mod common;

use std::path::Path;

use common::flights::{flown_campaign, linear_truth, planned_campaign, upload_planned};
use common::{TestApp, dp_profile, identified, run_job};
use nalgebra::{DMatrix, DVector};
use seatrial::jobs::{JobRegistry, JobsConfig};
use seatrial_core::identification::document::from_rows;
use seatrial_core::identification::npz::{NpyArray, NpyData, read_npz};
use seatrial_core::models::state_space::StateSpace;
use serde_json::{Value, json};

const STEPS: usize = 200;

async fn app() -> TestApp {
    TestApp::with_jobs(JobRegistry::production(), JobsConfig::default()).await
}

fn matrix(v: &Value) -> DMatrix<f64> {
    from_rows(&serde_json::from_value(v.clone()).unwrap()).expect("rectangular")
}

/// y(k) = C x(k) + D u(k), x(k+1) = Φ x(k) + Γ u(k) from x = 0 under a unit
/// step on every input: STEPS rows of outputs.
fn step(
    phi: &DMatrix<f64>,
    gamma: &DMatrix<f64>,
    c: &DMatrix<f64>,
    d: &DMatrix<f64>,
) -> Vec<Vec<f64>> {
    let u = DVector::from_element(gamma.ncols(), 1.0);
    let mut x = DVector::zeros(phi.nrows());
    (0..STEPS)
        .map(|_| {
            let y = c * &x + d * &u;
            x = phi * &x + gamma * &u;
            y.iter().copied().collect()
        })
        .collect()
}

fn close(a: &[Vec<f64>], b: &[Vec<f64>], tol: f64, what: &str) {
    let scale = a.iter().flatten().fold(1e-300f64, |m, x| m.max(x.abs()));
    for (ra, rb) in a.iter().zip(b) {
        for (x, y) in ra.iter().zip(rb) {
            assert!(
                (x - y).abs() <= tol * scale,
                "{what}: {x} vs {y} (scale {scale})"
            );
        }
    }
}

fn array<'a>(arrays: &'a [NpyArray], name: &str) -> &'a NpyArray {
    arrays
        .iter()
        .find(|a| a.name == name)
        .unwrap_or_else(|| panic!("no array {name} in the npz"))
}

fn floats(arrays: &[NpyArray], name: &str) -> Vec<f64> {
    match &array(arrays, name).data {
        NpyData::F64(v) => v.clone(),
        NpyData::Str(_) => panic!("{name} holds text"),
    }
}

fn flat(m: &Value) -> Vec<f64> {
    m.as_array()
        .unwrap()
        .iter()
        .flat_map(|r| r.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()))
        .collect()
}

async fn export(app: &TestApp, mid: &str, query: &str) -> common::Resp {
    let r = app
        .call(
            "GET",
            &format!("/api/models/{{id}}/export?{query}"),
            &[mid],
            None,
        )
        .await;
    assert_eq!(r.status, 200, "{query}: {}", r.text);
    r
}

/// Exports model `mid` into `dir` as `<tag>.*`, checks them against the
/// stored document and the service's ZOH at `h`, and returns the view.
async fn exported(app: &TestApp, mid: &str, tag: &str, h: f64, dir: &Path) -> Value {
    let view = app
        .call(
            "GET",
            "/api/models/{id}?h={h}",
            &[mid, &h.to_string()],
            None,
        )
        .await;
    assert_eq!(view.status, 200, "{}", view.text);
    let view = view.json;
    let doc = &view["document"];
    let npz = export(app, mid, &format!("format=npz&h={h}")).await;
    assert_eq!(npz.content_type, "application/octet-stream");
    let arrays = read_npz(&npz.bytes).unwrap();
    let ss = export(app, mid, "format=ss_json").await.json;
    let ss_csv = export(app, mid, "format=ss_csv").await.text;
    assert_eq!(ss["format"], "seatrial-ss/1");

    // The npz holds the stored matrices exactly, and the service's own ZOH.
    let discrete = view["discrete"]["points"].as_array().unwrap();
    let ad = floats(&arrays, "Ad");
    let phis: Vec<f64> = discrete.iter().flat_map(|p| flat(&p["phi"])).collect();
    assert_eq!(ad, phis, "{tag}: A_d is the service's Φ");
    assert_eq!(floats(&arrays, "h"), vec![h]);
    let kind = doc["kind"].as_str().unwrap();
    match kind {
        "lpv" => {
            let points = doc["lpv"]["points"].as_array().unwrap();
            for (key, field) in [
                ("M", "m"),
                ("Dbar", "d_bar"),
                ("A", "a"),
                ("B", "b"),
                ("M_std", "m_std"),
            ] {
                let stored: Vec<f64> = points.iter().flat_map(|p| flat(&p[field])).collect();
                assert_eq!(floats(&arrays, key), stored, "{tag}: {key}");
            }
            let speeds: Vec<f64> = points
                .iter()
                .map(|p| p["speed_mps"].as_f64().unwrap())
                .collect();
            assert_eq!(floats(&arrays, "grid_speeds_mps"), speeds);
            let n = points[0]["m"].as_array().unwrap().len();
            assert_eq!(array(&arrays, "A").shape, vec![points.len(), n, n]);
            let loads: Vec<f64> = points
                .iter()
                .flat_map(|p| match p["load"].as_array() {
                    Some(b) => b.iter().map(|x| x.as_f64().unwrap()).collect(),
                    None => vec![0.0; n],
                })
                .collect();
            assert_eq!(floats(&arrays, "b"), loads);
        }
        "dp_ship" => {
            let dp = &doc["dp_ship"];
            assert_eq!(floats(&arrays, "A"), flat(&dp["a_si"]));
            assert_eq!(floats(&arrays, "B"), flat(&dp["b_si"]));
            assert_eq!(floats(&arrays, "M_bis"), flat(&dp["m"]));
            assert_eq!(floats(&arrays, "A_h_bis"), flat(&dp["a_h"]));
        }
        _ => {
            let s = &doc["state_space"];
            for (key, field) in [
                ("A", "phi"),
                ("B", "gamma"),
                ("C", "c"),
                ("D", "d"),
                ("K", "k"),
            ] {
                assert_eq!(floats(&arrays, key), flat(&s[field]), "{tag}: {key}");
            }
        }
    }
    let NpyData::Str(outputs) = &array(&arrays, "output_names").data else {
        panic!("output_names")
    };
    let named: Vec<&str> = ss["outputs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["name"].as_str().unwrap())
        .collect();
    assert_eq!(outputs, &named);
    assert!(
        named.iter().all(|n| !n.starts_with('y')),
        "{tag}: real channel names, got {named:?}"
    );

    // The state-space matrices reproduce the service's ZOH step response.
    let mut steps = Vec::new();
    for (i, p) in ss["points"].as_array().unwrap().iter().enumerate() {
        let (a, b, c, d) = (
            matrix(&p["A"]),
            matrix(&p["B"]),
            matrix(&p["C"]),
            matrix(&p["D"]),
        );
        let (phi, gamma) = (matrix(&discrete[i]["phi"]), matrix(&discrete[i]["gamma"]));
        let service = step(&phi, &gamma, &c, &d);
        let (pa, pb) = if ss["sample_time_s"] == 0.0 {
            let z = StateSpace::new(a, b.clone(), c.clone(), d.clone())
                .and_then(|s| s.discretize_zoh(h))
                .unwrap();
            (z.phi().clone(), z.gamma().clone())
        } else {
            assert_eq!(ss["sample_time_s"].as_f64(), Some(h));
            (a, b)
        };
        close(
            &step(&pa, &pb, &c, &d),
            &service,
            1e-12,
            &format!("{tag} point {i}"),
        );
        // The CSV holds the same numbers, named.
        for (r, row) in p["A"].as_array().unwrap().iter().enumerate() {
            let rn = ss["states"][r]["name"].as_str().unwrap();
            let cn = ss["states"][0]["name"].as_str().unwrap();
            let v = row[0].as_f64().unwrap();
            let speed = p["grid_speed_mps"]
                .as_f64()
                .map(|s| s.to_string())
                .unwrap_or_default();
            let line = format!(
                "\n{i},{speed},{},A,{r},0,{rn},{cn},",
                ss["sample_time_s"].as_f64().unwrap()
            );
            let at = ss_csv
                .find(&line)
                .unwrap_or_else(|| panic!("{tag}: {line:?} not in the CSV"));
            let value: f64 = ss_csv[at + 1..]
                .lines()
                .next()
                .unwrap()
                .rsplit(',')
                .next()
                .unwrap()
                .parse()
                .unwrap();
            assert_eq!(value, v);
        }
        steps.push(service);
    }

    std::fs::write(dir.join(format!("{tag}.npz")), &npz.bytes).unwrap();
    std::fs::write(dir.join(format!("{tag}-ss.json")), ss.to_string()).unwrap();
    std::fs::write(dir.join(format!("{tag}-view.json")), view.to_string()).unwrap();
    std::fs::write(
        dir.join(format!("{tag}-step.json")),
        json!({ "h": h, "steps": STEPS, "points": steps }).to_string(),
    )
    .unwrap();
    let m = export(app, mid, "format=matlab").await;
    std::fs::write(dir.join(format!("{tag}.m")), m.text).unwrap();
    let mat = export(app, mid, &format!("format=mat&h={h}")).await;
    assert_eq!(mat.content_type, "application/octet-stream");
    assert!(mat.bytes.starts_with(b"MATLAB 5.0 MAT-file"), "{tag}.mat");
    std::fs::write(dir.join(format!("{tag}.mat")), &mat.bytes).unwrap();
    view
}

/// Runs the Python check on `dir`; skipped (with a message) when numpy or
/// scipy are missing outside CI.
fn python_check(dir: &Path) {
    let have = std::process::Command::new("python3")
        .args(["-c", "import numpy, scipy"])
        .status()
        .is_ok_and(|s| s.success());
    if !have {
        assert!(
            std::env::var_os("CI").is_none(),
            "numpy and scipy are needed under CI (make py-deps)"
        );
        eprintln!(
            "numpy/scipy not installed: skipping tests/python/check_exports.py (make py-deps)"
        );
        return;
    }
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/python/check_exports.py");
    let out = std::process::Command::new("python3")
        .arg(&script)
        .arg(dir)
        .output()
        .unwrap();
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    eprintln!("{text}");
    assert!(out.status.success(), "check_exports.py failed:\n{text}");
    assert!(text.contains("0 failed"), "{text}");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn rov_models_export_true_npz_and_state_space() {
    let app = app().await;
    let cid = flown_campaign(&app, &linear_truth()).await;
    let lpv = identified(&app, &cid, "lambda_kf").await;
    let job = run_job(
        &app,
        json!({ "kind": "identify", "campaign_id": cid, "method": "n4sid", "settings": { "order": 6 } }),
    )
    .await;
    let n4sid = job["result"]["model_id"].as_str().unwrap().to_string();

    // A name beyond ASCII reaches the file name through filename*.
    let r = app
        .call(
            "PATCH",
            "/api/models/{id}",
            &[&lpv],
            Some(json!({ "name": "Ærø ROV ψ-test" })),
        )
        .await;
    assert_eq!(r.status, 200, "{}", r.text);
    let npz = export(&app, &lpv, "format=npz").await;
    let cd = npz.headers["content-disposition"].to_str().unwrap();
    assert!(
        cd.ends_with("filename*=UTF-8''%C3%86r%C3%B8_ROV_%CF%88-test-v1.npz"),
        "{cd}"
    );
    assert!(
        cd.starts_with("attachment; filename=\"_r__ROV__-test-v1.npz\"; "),
        "{cd}"
    );
    // Without ?h= the npz discretizes at the vessel's log interval (10 Hz).
    assert_eq!(floats(&read_npz(&npz.bytes).unwrap(), "h"), vec![0.1]);
    let meta = match &array(&read_npz(&npz.bytes).unwrap(), "metadata").data {
        NpyData::Str(s) => serde_json::from_str::<Value>(&s[0]).unwrap(),
        NpyData::F64(_) => panic!(),
    };
    assert_eq!(meta["name"], "Ærø ROV ψ-test");

    let dir = tempfile::tempdir().unwrap();
    exported(&app, &lpv, "lpv", 0.05, dir.path()).await;
    let view = exported(&app, &n4sid, "n4sid", 0.1, dir.path()).await;
    assert_eq!(view["document"]["kind"], "state_space");
    // Its channels carry the logs' names: in validation and in the CSV, which
    // holds Φ, Γ, C, D, K and the operating point after the poles.
    let outputs: Vec<&str> = view["validation"][0]["report"]["channels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["output"].as_str().unwrap())
        .collect();
    assert_eq!(outputs, ["u", "v", "w", "p", "q", "r"]);
    let csv = export(&app, &n4sid, "format=csv").await.text;
    for needle in [
        "\npoles,",
        "\nΦ,\"Φ[x1,x1]\",,",
        "\nC,\"C[u,x1]\",,",
        "\nu0,u0[tau_X],,",
        "\nK,\"K[x6,r]\",,",
    ] {
        assert!(csv.contains(needle), "{needle:?} not in\n{csv}");
    }
    // An N4SID model is discrete at its own h: ss at another h is refused.
    let r = app
        .call(
            "GET",
            "/api/models/{id}/export?format=ss_json&h=0.05",
            &[&n4sid],
            None,
        )
        .await;
    assert_eq!(
        (r.status.as_u16(), r.json["field"].as_str()),
        (422, Some("h")),
        "{}",
        r.text
    );
    // The ZOH form of an LPV model at the controller's h.
    let zoh = export(&app, &lpv, "format=ss_json&h=0.05").await.json;
    assert_eq!(zoh["sample_time_s"], 0.05);
    let bad = app
        .call(
            "GET",
            "/api/models/{id}/export?format=npz&h=0",
            &[&lpv],
            None,
        )
        .await;
    assert_eq!(
        (bad.status.as_u16(), bad.json["field"].as_str()),
        (422, Some("h"))
    );
    python_check(dir.path());
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn dp_ship_model_exports_true_npz_and_state_space() {
    use seatrial_core::planning::examples::{supply_vessel, supply_vessel_trial_campaign};
    use seatrial_core::planning::generate_plan;
    use seatrial_core::simulation::dp_ship::{DpFlightSettings, DpShip, fly_dp_campaign};
    let app = app().await;
    let spec = supply_vessel_trial_campaign(1995);
    let (cid, plan) =
        planned_campaign(&app, dp_profile(), serde_json::to_value(&spec).unwrap()).await;
    let core_plan = generate_plan(&supply_vessel(), &spec).unwrap();
    let flown = fly_dp_campaign(
        &supply_vessel(),
        &DpShip::supply_vessel(),
        &core_plan,
        &DpFlightSettings::supply_vessel(2024),
        |_| true,
    )
    .unwrap();
    for run in flown {
        upload_planned(&app, &cid, &plan, &run.code, &run.csv).await;
    }
    let job = run_job(
        &app,
        json!({ "kind": "identify", "campaign_id": cid, "method": "parallel_ekf", "settings": { "sweeps": 2 } }),
    )
    .await;
    let mid = job["result"]["model_id"].as_str().unwrap().to_string();
    let dir = tempfile::tempdir().unwrap();
    let view = exported(&app, &mid, "dp", 0.5, dir.path()).await;
    assert_eq!(view["document"]["kind"], "dp_ship");
    let ss = export(&app, &mid, "format=ss_json").await.json;
    let units: Vec<&str> = ss["states"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["unit"].as_str().unwrap())
        .collect();
    assert_eq!(units, ["m/s", "m/s", "rad/s"]);
    python_check(dir.path());
}

/// `tests/python/client_e2e.py` creates the Surveyor from this file; it
/// stays the core's profile (`UPDATE_FIXTURES=1` rewrites it).
#[test]
fn the_client_script_uses_the_surveyor_profile() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/python/surveyor_rov.json");
    let want = serde_json::to_string_pretty(&common::rov_profile()).unwrap() + "\n";
    if std::env::var_os("UPDATE_FIXTURES").is_some() {
        std::fs::write(&path, &want).unwrap();
    }
    let have = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        have == want,
        "{} is stale: UPDATE_FIXTURES=1 cargo test --release --test api_exports",
        path.display()
    );
}
