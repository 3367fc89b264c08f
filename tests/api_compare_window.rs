//! Comparing models on a window of a run (issue 16): `from_s`/`to_s` cut
//! the run before validation, so the fits are those of a log that held only
//! the window's rows; bad windows are 422s naming the parameter.

mod common;

use common::{Resp, TestApp, rov_profile, sim};
use serde_json::{Value, json};

fn id(r: &Resp) -> String {
    assert!(r.status.is_success(), "{}", r.text);
    r.json["id"].as_str().unwrap().to_string()
}

/// The rows of `csv` (header kept) whose time is within [from, to].
fn rows_within(csv: &str, from: f64, to: f64) -> String {
    let mut lines = csv.lines();
    let mut out = format!("{}\n", lines.next().unwrap());
    for l in lines {
        let t: f64 = l.split(',').next().unwrap().parse().unwrap();
        if (from..=to).contains(&t) {
            out.push_str(l);
            out.push('\n');
        }
    }
    out
}

/// The 1-step fits and the input–residual cross-correlation values of
/// every model and channel of a comparison, in order.
fn numbers(c: &Value) -> (Vec<f64>, Vec<f64>) {
    let (mut fits, mut xc) = (Vec::new(), Vec::new());
    for m in c["models"].as_array().unwrap() {
        for ch in m["report"]["channels"].as_array().unwrap() {
            fits.push(ch["fit_one_step"].as_f64().unwrap());
            for cc in ch["input_correlations"].as_array().unwrap() {
                xc.extend(
                    cc["values"]
                        .as_array()
                        .unwrap()
                        .iter()
                        .flat_map(Value::as_f64),
                );
            }
        }
    }
    (fits, xc)
}

fn close(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(x, y)| (x - y).abs() <= 1e-9 * (1.0 + x.abs().max(y.abs())))
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_windowed_comparison_is_the_comparison_on_the_cut_run() {
    let app = TestApp::new().await;
    let r = app
        .call("POST", "/api/vessels", &[], Some(rov_profile()))
        .await;
    let vid = id(&r);
    let body = json!({ "vessel_id": vid, "name": "window", "seed": 3,
                       "grid": { "unit": "kn", "speeds": [1.0] }, "families": ["dynamic"] });
    let cid = id(&app.call("POST", "/api/campaigns", &[], Some(body)).await);
    let csv = sim::csv(
        &sim::simulate(11, 10.0, 300.0, [300.0, 0.0, 0.0, 0.0, 0.0, 0.0], 2.0, 1e-3),
        &sim::all_columns(),
        0.0,
        1,
    );
    let upload = |name: &'static str, csv: String| {
        let app = &app;
        let cid = cid.clone();
        async move {
            let meta = json!({ "name": name }).to_string();
            id(&app
                .upload_run(
                    &cid,
                    &[("meta", None, &meta), ("file", Some("log.csv"), &csv)],
                )
                .await)
        }
    };
    let full = upload("full", csv.clone()).await;
    let cut = upload("cut", rows_within(&csv, 100.0, 200.0)).await;
    let a = common::stored_model(&app, &cid, &vid, None, &[]).await;
    let b = common::stored_model(&app, &cid, &vid, Some(&a), &[]).await;

    let compare = "/api/models/compare?a={a}&b={b}&run_id={r}";
    let whole = app.call("GET", compare, &[&a, &b, &full], None).await;
    assert_eq!(whole.status, 200, "{}", whole.text);
    let windowed = app
        .call(
            "GET",
            &format!("{compare}&from_s={{f}}&to_s={{t}}"),
            &[&a, &b, &full, "100", "200"],
            None,
        )
        .await;
    assert_eq!(windowed.status, 200, "{}", windowed.text);
    assert_eq!(
        windowed.json["window_s"],
        json!([100.0, 200.0]),
        "{}",
        windowed.text
    );
    let on_cut = app.call("GET", compare, &[&a, &b, &cut], None).await;
    assert_eq!(on_cut.status, 200, "{}", on_cut.text);

    let (fw, xw) = numbers(&windowed.json);
    let (fc, xc) = numbers(&on_cut.json);
    let (ff, xf) = numbers(&whole.json);
    assert!(!fw.is_empty() && !xw.is_empty(), "{}", windowed.text);
    assert!(close(&fw, &fc), "window {fw:?} vs cut run {fc:?}");
    assert!(
        close(&xw, &xc),
        "cross-correlations differ from the cut run's"
    );
    assert!(
        !close(&fw, &ff),
        "the window's fits equal the whole run's: {fw:?}"
    );
    assert!(!close(&xw, &xf));

    // Bad windows: 422 naming the parameter (400 for a non-number).
    for (q, status, field) in [
        ("from_s=200&to_s=100", 422, "to_s"),
        ("from_s=400", 422, "to_s"),
        ("to_s=-5", 422, "to_s"),
        ("from_s=abc", 400, "from_s"),
        ("from_s=inf", 422, "from_s"),
    ] {
        let r = app
            .call("GET", &format!("{compare}&{q}"), &[&a, &b, &full], None)
            .await;
        assert_eq!(
            (r.status.as_u16(), r.json["field"].as_str()),
            (status, Some(field)),
            "{q}: {}",
            r.text
        );
    }
}
