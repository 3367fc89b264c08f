//! A real but simple job kind for the tests: `sum` adds the Basel series
//! Σ 1/k² (k = 1…n) in `steps` chunks, reporting progress after each, with
//! optional waiting (`step_ms`) or CPU burning (`spin_ms`) per chunk so a job
//! lasts long enough to be watched, cancelled or killed.

#![allow(dead_code)]

use std::time::{Duration, Instant};

use seatrial::error::ApiError;
use seatrial::jobs::{
    BoxFuture, Compute, JobContext, JobFailure, JobHandler, JobRegistry, JobsConfig, compute,
};
use seatrial::storage::jobs::{Job, JobRequest};
use serde::Deserialize;
use serde_json::json;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SumSettings {
    pub n: u64,
    #[serde(default = "default_steps")]
    pub steps: u64,
    #[serde(default)]
    pub step_ms: u64,
    #[serde(default)]
    pub spin_ms: u64,
    /// Fail (as a computation may) when this chunk is reached.
    #[serde(default)]
    pub fail_at: Option<u64>,
}

fn default_steps() -> u64 {
    10
}

pub struct SumSeries;

impl SumSeries {
    fn settings(req: &JobRequest) -> Result<SumSettings, ApiError> {
        let s: SumSettings = serde_json::from_value(req.settings.clone())
            .map_err(|e| ApiError::invalid("settings", format!("invalid settings: {e}")))?;
        if s.n == 0 || s.n > 1_000_000_000 {
            return Err(ApiError::invalid("settings.n", "n must be in 1 … 10⁹"));
        }
        if s.steps == 0 || s.steps > s.n.max(1) {
            return Err(ApiError::invalid(
                "settings.steps",
                "steps must be in 1 … n",
            ));
        }
        if s.step_ms > 1000 || s.spin_ms > 1000 {
            return Err(ApiError::invalid(
                "settings.step_ms",
                "at most 1000 ms per step",
            ));
        }
        Ok(s)
    }
}

impl JobHandler for SumSeries {
    fn check<'a>(
        &'a self,
        _cx: &'a JobContext,
        req: &'a JobRequest,
    ) -> BoxFuture<'a, Result<(), ApiError>> {
        Box::pin(async move {
            match req.method.as_deref() {
                None | Some("basel") => {}
                Some(m) => {
                    return Err(ApiError::invalid(
                        "method",
                        format!("unknown method '{m}'; sum knows 'basel'"),
                    ));
                }
            }
            Self::settings(req).map(|_| ())
        })
    }

    fn load<'a>(
        &'a self,
        _cx: &'a JobContext,
        job: &'a Job,
    ) -> BoxFuture<'a, Result<Compute, JobFailure>> {
        Box::pin(async move {
            let s = Self::settings(&job.request).map_err(|e| JobFailure::new(e.to_string()))?;
            Ok(compute(move |progress| {
                let chunk = s.n.div_ceil(s.steps);
                let mut sum = 0.0f64;
                progress.update(0.0, "summing")?;
                for step in 0..s.steps {
                    if s.fail_at == Some(step) {
                        return Err(JobFailure::field(
                            "settings.fail_at",
                            format!("asked to fail at step {step}"),
                        ));
                    }
                    let lo = step * chunk + 1;
                    let hi = ((step + 1) * chunk).min(s.n);
                    for k in lo..=hi {
                        let k = k as f64;
                        sum += 1.0 / (k * k);
                    }
                    if s.step_ms > 0 {
                        std::thread::sleep(Duration::from_millis(s.step_ms));
                    }
                    let t = Instant::now();
                    let mut burn = 0u64;
                    while t.elapsed() < Duration::from_millis(s.spin_ms) {
                        burn = std::hint::black_box(burn.wrapping_mul(31).wrapping_add(7));
                    }
                    progress.update((step + 1) as f64 / s.steps as f64, "summing")?;
                }
                Ok(json!({ "sum": sum, "n": s.n }))
            }))
        })
    }
}

pub fn registry() -> JobRegistry {
    JobRegistry::new().with("sum", SumSeries)
}

/// Fast heartbeats, short leases: tests see progress and recovery quickly.
pub fn config(workers: usize) -> JobsConfig {
    JobsConfig {
        workers,
        lease: Duration::from_secs(1),
        heartbeat: Duration::from_millis(100),
        max_attempts: 3,
        poll: Duration::from_millis(100),
    }
}
