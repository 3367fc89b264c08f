//! Load test of a running service on loopback: the figures of issue 17's
//! "bounded cost" (GET of a model, `/api/health` latency, an identify job's
//! time) measured idle and under `--clients` concurrent readers.
//!
//! ```sh
//! target/release/seatrial --demo --db /tmp/load.db --listen 127.0.0.1:8099 &
//! cargo run --release --example load_test -- --base http://127.0.0.1:8099
//! ```
//!
//! It refuses a non-loopback address and stops after `--seconds` per phase.

use std::time::{Duration, Instant};

use http_body_util::{BodyExt, Full};
use hyper::body::Bytes;
use hyper_util::client::legacy::Client;
use hyper_util::client::legacy::connect::HttpConnector;
use hyper_util::rt::TokioExecutor;
use serde_json::Value;

type Http = Client<HttpConnector, Full<Bytes>>;

struct Args {
    base: String,
    clients: usize,
    seconds: f64,
}

fn args() -> Args {
    let mut a = Args {
        base: "http://127.0.0.1:8080".into(),
        clients: 32,
        seconds: 20.0,
    };
    let mut it = std::env::args().skip(1);
    while let Some(k) = it.next() {
        let v = it.next().unwrap_or_default();
        match k.as_str() {
            "--base" => a.base = v.trim_end_matches('/').to_string(),
            "--clients" => a.clients = v.parse().expect("--clients: a whole number"),
            "--seconds" => a.seconds = v.parse().expect("--seconds: a number"),
            _ => panic!("unknown argument {k} (--base URL, --clients N, --seconds S)"),
        }
    }
    let host = a
        .base
        .trim_start_matches("http://")
        .split(['/', ':'])
        .next()
        .unwrap_or("");
    assert!(
        matches!(host, "127.0.0.1" | "localhost" | "[") || host.starts_with("127."),
        "the load test runs against loopback only, not {host}"
    );
    a
}

/// One request: status, body bytes, seconds.
async fn send(http: &Http, method: &str, url: &str, body: Option<&Value>) -> (u16, Bytes, f64) {
    let mut req = hyper::Request::builder()
        .method(method)
        .uri(url)
        .header("accept-encoding", "gzip");
    let body = match body {
        Some(v) => {
            req = req.header("content-type", "application/json");
            Full::new(Bytes::from(v.to_string()))
        }
        None => Full::new(Bytes::new()),
    };
    let t0 = Instant::now();
    let resp = http
        .request(req.body(body).unwrap())
        .await
        .expect("request failed");
    let status = resp.status().as_u16();
    let bytes = resp.into_body().collect().await.expect("body").to_bytes();
    (status, bytes, t0.elapsed().as_secs_f64())
}

async fn json(http: &Http, method: &str, url: &str, body: Option<&Value>) -> Value {
    let mut req = hyper::Request::builder().method(method).uri(url);
    let b = match body {
        Some(v) => {
            req = req.header("content-type", "application/json");
            Full::new(Bytes::from(v.to_string()))
        }
        None => Full::new(Bytes::new()),
    };
    let resp = http
        .request(req.body(b).unwrap())
        .await
        .expect("request failed");
    let status = resp.status();
    let bytes = resp.into_body().collect().await.expect("body").to_bytes();
    assert!(
        status.is_success(),
        "{method} {url}: {status} {}",
        String::from_utf8_lossy(&bytes)
    );
    serde_json::from_slice(&bytes).expect("JSON")
}

fn quantile(xs: &mut [f64], q: f64) -> f64 {
    if xs.is_empty() {
        return f64::NAN;
    }
    xs.sort_by(f64::total_cmp);
    xs[((xs.len() - 1) as f64 * q).round() as usize]
}

/// Health latencies (s) probed one after another, 20 ms apart, until `until`.
async fn probe_health(http: Http, base: String, until: Instant) -> Vec<f64> {
    let mut out = Vec::new();
    while Instant::now() < until {
        let (s, _, dt) = send(&http, "GET", &format!("{base}/api/health"), None).await;
        assert_eq!(s, 200, "health answered {s}");
        out.push(dt);
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
    out
}

/// Submits an identify job and waits for it: its running time (s) from the
/// job record, or the wall time if the record lacks the times.
async fn identify_once(http: &Http, base: &str, campaign: &str) -> f64 {
    let job = json(
        http,
        "POST",
        &format!("{base}/api/jobs"),
        Some(&serde_json::json!({"kind": "identify", "campaign_id": campaign, "method": "lambda_kf"})),
    )
    .await;
    let id = job["id"].as_str().unwrap().to_string();
    let t0 = Instant::now();
    loop {
        tokio::time::sleep(Duration::from_millis(100)).await;
        let j = json(http, "GET", &format!("{base}/api/jobs/{id}"), None).await;
        match j["state"].as_str() {
            Some("succeeded") => {
                let t = |k: &str| {
                    j[k].as_str().and_then(|s| {
                        time::OffsetDateTime::parse(
                            s,
                            &time::format_description::well_known::Rfc3339,
                        )
                        .ok()
                    })
                };
                return match (t("started_at"), t("finished_at")) {
                    (Some(a), Some(b)) => (b - a).as_seconds_f64(),
                    _ => t0.elapsed().as_secs_f64(),
                };
            }
            Some("failed" | "cancelled" | "interrupted") => panic!("identify job ended {}", j),
            _ => {}
        }
        assert!(
            t0.elapsed() < Duration::from_secs(1800),
            "identify job did not end in 30 min"
        );
    }
}

#[tokio::main]
async fn main() {
    let a = args();
    let http: Http = Client::builder(TokioExecutor::new())
        .pool_max_idle_per_host(a.clients + 4)
        .build_http();
    let base = a.base.clone();

    // The first ROV campaign (λ-filter identification) and a model of it.
    let vessels = json(&http, "GET", &format!("{base}/api/vessels"), None).await;
    let rovs: Vec<&str> = vessels
        .as_array()
        .unwrap()
        .iter()
        .filter(|v| v["profile"]["kind"] == "rov6")
        .filter_map(|v| v["id"].as_str())
        .collect();
    let campaigns = json(&http, "GET", &format!("{base}/api/campaigns"), None).await;
    let campaign = campaigns
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["vessel_id"].as_str().is_some_and(|v| rovs.contains(&v)))
        .expect("no ROV campaign: start the service with --demo")["id"]
        .as_str()
        .unwrap()
        .to_string();
    let models_of = format!("{base}/api/models?campaign_id={campaign}");
    let mut models = json(&http, "GET", &models_of, None).await;
    if models.as_array().is_none_or(|m| m.is_empty()) {
        identify_once(&http, &base, &campaign).await;
        models = json(&http, "GET", &models_of, None).await;
    }
    let model = models[0]["id"].as_str().unwrap().to_string();
    let runs = json(
        &http,
        "GET",
        &format!("{base}/api/campaigns/{campaign}/runs?limit=20"),
        None,
    )
    .await;
    let run_ids: Vec<String> = runs
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|r| r["id"].as_str().map(String::from))
        .collect();
    let mut reads = vec![
        format!("{base}/api/models/{model}"),
        format!("{base}/api/campaigns/{campaign}/runs"),
        format!("{base}/api/campaigns/{campaign}/coverage"),
        format!("{base}/api/models?campaign_id={campaign}"),
        format!("{base}/api/campaigns"),
        format!("{base}/"),
    ];
    for r in run_ids.iter().take(8) {
        reads.push(format!("{base}/api/runs/{r}"));
        reads.push(format!("{base}/api/runs/{r}/quality"));
    }

    // Model GET, idle.
    let mut model_get = Vec::new();
    for _ in 0..50 {
        let (s, _, dt) = send(&http, "GET", &reads[0], None).await;
        assert_eq!(s, 200);
        model_get.push(dt);
    }
    // Idle: health and one identify job.
    let until = Instant::now() + Duration::from_secs_f64(a.seconds.min(10.0));
    let health_idle = probe_health(http.clone(), base.clone(), until).await;
    let identify_idle = identify_once(&http, &base, &campaign).await;

    // Under load.
    let stop = Instant::now() + Duration::from_secs_f64(a.seconds);
    let mut clients = Vec::new();
    for c in 0..a.clients {
        let (http, reads) = (http.clone(), reads.clone());
        clients.push(tokio::spawn(async move {
            let (mut n, mut errors, mut lat) = (0usize, 0usize, Vec::new());
            let mut i = c;
            while Instant::now() < stop {
                let (s, _, dt) = send(&http, "GET", &reads[i % reads.len()], None).await;
                if s >= 500 {
                    errors += 1;
                }
                n += 1;
                i += 1;
                lat.push(dt);
            }
            (n, errors, lat)
        }));
    }
    tokio::time::sleep(Duration::from_millis(500)).await;
    let prober = tokio::spawn(probe_health(http.clone(), base.clone(), stop));
    let identify_loaded = identify_once(&http, &base, &campaign).await;
    let health_loaded = prober.await.unwrap();
    let (mut n, mut errors, mut lat) = (0, 0, Vec::new());
    for c in clients {
        let (cn, ce, cl) = c.await.unwrap();
        n += cn;
        errors += ce;
        lat.extend(cl);
    }
    let ms = |x: f64| x * 1e3;
    let (mut hi, mut hl, mut mg) = (health_idle, health_loaded, model_get);
    println!("| figure | value |");
    println!("|---|---|");
    println!(
        "| GET /api/models/{{id}} (gzip), idle, median | {:.1} ms |",
        ms(quantile(&mut mg, 0.5))
    );
    println!(
        "| /api/health idle p50 / p99 | {:.1} / {:.1} ms |",
        ms(quantile(&mut hi.clone(), 0.5)),
        ms(quantile(&mut hi, 0.99))
    );
    println!(
        "| /api/health under {} clients p50 / p99 | {:.1} / {:.1} ms ({} probes) |",
        a.clients,
        ms(quantile(&mut hl.clone(), 0.5)),
        ms(quantile(&mut hl, 0.99)),
        hl.len()
    );
    println!(
        "| reads under load | {n} in {:.0} s ({:.0}/s), median {:.1} ms, {errors} × 5xx |",
        a.seconds,
        n as f64 / a.seconds,
        ms(quantile(&mut lat, 0.5))
    );
    println!("| identify job idle | {identify_idle:.2} s |");
    println!(
        "| identify job under load | {identify_loaded:.2} s ({:.2}× idle) |",
        identify_loaded / identify_idle
    );
    if identify_loaded > a.seconds {
        println!("(the identify job outlasted the load phase: raise --seconds for a fair figure)");
    }
}
