//! Issue 17's bounded cost per request and input checks: wide headers,
//! unbounded warnings, absurd rates, control characters in names and
//! messages, bare-CR files, the 413 body and the milliseconds heuristic.

mod common;

use common::{Resp, TestApp, rov_campaign_id as rov_campaign, rov_log as log, rov_profile};
use serde_json::{Value, json};

async fn upload(app: &TestApp, cid: &str, parts: &[(&str, Option<&str>, &str)]) -> Resp {
    let r = app.upload_run(cid, parts).await;
    app.check_contract("POST", "/api/campaigns/{id}/runs", &r);
    r
}

#[tokio::test]
async fn a_header_of_100_000_columns_is_refused_fast_naming_the_limit() {
    let app = TestApp::new().await;
    let cid = rov_campaign(&app).await;
    let mut header = vec!["t".to_string()];
    header.extend((1..100_000).map(|i| format!("c{i}")));
    let csv = format!("{}\n", header.join(","));
    let started = std::time::Instant::now();
    let r = upload(&app, &cid, &[("file", Some("wide.csv"), &csv)]).await;
    let took = started.elapsed();
    assert_eq!(r.status, 422, "{}", r.text);
    assert!(
        r.json["message"]
            .as_str()
            .unwrap()
            .contains("limit of 10000"),
        "{}",
        r.text
    );
    assert_eq!(r.json["line"], 1);
    assert!(took.as_secs_f64() < 3.0, "{took:?}");
}

#[tokio::test]
async fn ignored_column_warnings_are_bounded() {
    let app = TestApp::new().await;
    let cid = rov_campaign(&app).await;
    let csv = log();
    let mut lines = csv.lines();
    let header = lines.next().unwrap();
    let extra = 500;
    let names: Vec<String> = (0..extra).map(|i| format!("note{i}")).collect();
    let cells = vec!["x"; extra].join(",");
    let mut wide = format!("{header},{}\n", names.join(","));
    for l in lines {
        wide.push_str(&format!("{l},{cells}\n"));
    }
    let r = upload(&app, &cid, &[("file", Some("notes.csv"), &wide)]).await;
    assert_eq!(r.status, 201, "{}", r.text);
    let warnings = r.json["summary"]["warnings"].as_array().unwrap();
    let ignored = warnings
        .iter()
        .filter(|w| w["message"].as_str().unwrap().contains("ignored"))
        .count();
    assert_eq!(ignored, 21, "{warnings:#?}");
    assert!(
        warnings
            .iter()
            .any(|w| w["message"].as_str().unwrap().starts_with("… and 480 more"))
    );
}

#[tokio::test]
async fn absurd_rates_are_refused_before_anything_is_stored() {
    let app = TestApp::new().await;
    let cid = rov_campaign(&app).await;
    let csv = log();
    for rate in ["1e-308", "0", "-5", "0.001", "20000"] {
        let meta = format!(r#"{{"rate_hz": {rate}}}"#);
        let r = upload(
            &app,
            &cid,
            &[("meta", None, &meta), ("file", Some("a.csv"), &csv)],
        )
        .await;
        assert_eq!(r.status, 422, "{rate}: {}", r.text);
        assert_eq!(r.json["field"], "meta.rate_hz");
        let msg = r.json["message"].as_str().unwrap();
        assert!(msg.contains("between 0.01 and 1000 Hz"), "{msg}");
        assert!(msg.len() < 120, "no 309-digit numbers: {msg}");
        assert!(r.json["run_id"].is_null(), "nothing recorded");
    }
    let r = app
        .call("GET", "/api/campaigns/{id}/runs", &[&cid], None)
        .await;
    assert_eq!(r.json.as_array().unwrap().len(), 0);
}

#[tokio::test]
async fn names_with_control_characters_are_refused_and_never_echoed() {
    let app = TestApp::new().await;
    let mut profile = rov_profile();
    profile["name"] = json!("Surveyor\u{1b}[2J\nROV");
    let r = app.call("POST", "/api/vessels", &[], Some(profile)).await;
    assert_eq!(r.status, 422, "{}", r.text);
    assert_eq!(r.json["field"], "name");
    assert!(
        r.json["message"]
            .as_str()
            .unwrap()
            .contains("control characters")
    );
    assert!(
        !r.text.contains("\\u001b") && !r.text.contains("\\n"),
        "{}",
        r.text
    );

    let cid = rov_campaign(&app).await;
    let r = app.call("GET", "/api/campaigns/{id}", &[&cid], None).await;
    let vid = r.json["vessel_id"].as_str().unwrap().to_string();
    let body = json!({
        "vessel_id": vid,
        "name": "trial\u{7}",
        "grid": { "unit": "kn", "speeds": [1.0] },
        "families": ["dynamic"],
        "seed": 5
    });
    let r = app.call("POST", "/api/campaigns", &[], Some(body)).await;
    assert_eq!(r.status, 422, "{}", r.text);
    assert_eq!(r.json["field"], "name");

    let meta = json!({ "name": "dive\r7" }).to_string();
    let r = upload(
        &app,
        &cid,
        &[("meta", None, &meta), ("file", Some("a.csv"), &log())],
    )
    .await;
    assert_eq!(r.status, 422, "{}", r.text);
    assert_eq!(r.json["field"], "meta.name");
    // Messages escape what they quote.
    let mut lines: Vec<String> = log().lines().map(str::to_string).collect();
    let mut cells: Vec<String> = lines[2].split(',').map(str::to_string).collect();
    cells[1] = "\u{1b}[31mred".to_string();
    lines[2] = cells.join(",");
    let bad = lines.join("\n");
    let r = upload(&app, &cid, &[("file", Some("b.csv"), &bad)]).await;
    assert_eq!(r.status, 422, "{}", r.text);
    assert_eq!(r.json["line"], 3, "{}", r.text);
    let msg = r.json["message"].as_str().unwrap();
    assert!(!msg.chars().any(char::is_control), "{msg:?}");
    assert!(msg.contains("\\u{1b}[31mred"), "{msg:?}");
}

#[tokio::test]
async fn a_bare_cr_file_reads_like_its_lf_twin() {
    let app = TestApp::new().await;
    let cid = rov_campaign(&app).await;
    let csv = log();
    let lf = upload(&app, &cid, &[("file", Some("lf.csv"), &csv)]).await;
    assert_eq!(lf.status, 201, "{}", lf.text);
    let cr = csv.replace('\n', "\r");
    let r = upload(&app, &cid, &[("file", Some("mac.csv"), &cr)]).await;
    assert_eq!(r.status, 201, "{}", r.text);
    assert_eq!(r.json["summary"]["rows"], lf.json["summary"]["rows"]);
    assert_eq!(
        r.json["summary"]["verdicts"],
        lf.json["summary"]["verdicts"]
    );
}

#[tokio::test]
async fn the_413_names_the_limit() {
    let app = TestApp::with_upload_limit(1 << 20).await;
    let cid = rov_campaign(&app).await;
    let big = "0,1\n".repeat(300_000);
    let r = upload(&app, &cid, &[("file", Some("big.csv"), &big)]).await;
    assert_eq!(r.status, 413, "{}", r.text);
    assert_eq!(r.json["limit"], 1048576.0);
    let msg = r.json["message"].as_str().unwrap();
    assert!(msg.contains("1048576 bytes (1 MB)"), "{msg}");
}

#[tokio::test]
async fn a_valid_29_hour_log_in_seconds_is_not_called_milliseconds() {
    let app = TestApp::new().await;
    let cid = rov_campaign(&app).await;
    // 29 h at 1 Hz: the tail of a real log, t in seconds since the start.
    let csv = log();
    let mut lines = csv.lines();
    let header = lines.next().unwrap().to_string();
    let rows: Vec<Vec<String>> = lines
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    let t_col = header.split(',').position(|c| c == "t").unwrap();
    let mut out = format!("{header}\n");
    for k in 0..29 * 3600 {
        let mut row = rows[k % rows.len()].clone();
        row[t_col] = format!("{k}");
        out.push_str(&row.join(","));
        out.push('\n');
    }
    let r = upload(&app, &cid, &[("file", Some("long.csv"), &out)]).await;
    assert_eq!(r.status, 201, "{}", r.text);
    let warnings: &Vec<Value> = r.json["summary"]["warnings"].as_array().unwrap();
    assert!(
        !warnings
            .iter()
            .any(|w| w["message"].as_str().unwrap().contains("milliseconds")),
        "{warnings:#?}"
    );
}

#[tokio::test]
async fn a_log_in_milliseconds_and_degrees_is_check_units_not_fly_again() {
    let app = TestApp::new().await;
    let cid = rov_campaign(&app).await;
    let csv = log();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let (t, phi) = (
        header.iter().position(|c| *c == "t").unwrap(),
        header.iter().position(|c| *c == "phi").unwrap(),
    );
    let mut out = format!("{}\n", header.join(","));
    for l in lines {
        let mut row: Vec<f64> = l.split(',').map(|v| v.parse().unwrap()).collect();
        row[t] *= 1000.0;
        row[phi] = (row[phi] + 0.2).to_degrees() * 20.0;
        let row: Vec<String> = row.iter().map(|v| v.to_string()).collect();
        out.push_str(&row.join(","));
        out.push('\n');
    }
    let r = upload(&app, &cid, &[("file", Some("ms_deg.csv"), &out)]).await;
    assert_eq!(r.status, 201, "{}", r.text);
    let s = &r.json["summary"];
    assert_eq!(s["check_units"], json!(["t", "phi"]), "{:#}", s["warnings"]);
    let units: Vec<&Value> = s["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|w| w["units"] == true)
        .collect();
    assert_eq!(units.len(), 2, "{units:#?}");
    let verdicts = s["verdicts"].as_array().unwrap();
    assert_eq!(verdicts.len(), 6);
    for v in verdicts {
        assert_eq!(v["verdict"], "check_units", "{v:#}");
        let reason = v["reason"].as_str().unwrap();
        assert!(reason.contains("check the log's units first"), "{reason}");
        assert!(
            reason.contains("milliseconds") && reason.contains("degrees"),
            "{reason}"
        );
        assert!(!reason.contains("twice the amplitude"), "{reason}");
    }
    // A log in the contract's units carries no such doubt.
    let r = upload(&app, &cid, &[("file", Some("ok.csv"), &csv)]).await;
    assert_eq!(r.status, 201, "{}", r.text);
    assert!(r.json["summary"].get("check_units").is_none());
    assert!(
        r.json["summary"]["verdicts"]
            .as_array()
            .unwrap()
            .iter()
            .all(|v| v["verdict"] != "check_units")
    );
}
