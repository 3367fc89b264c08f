//! Predicted against empirical precision: per parameter the ratio of the
//! spread over the truth's seeds to the predicted std, their summary and
//! the table written for the README.

use super::*;

/// One parameter: predicted std, empirical std over seeds, mean reported
/// std on the truth runs.
#[derive(Debug, Clone)]
pub struct Comparison {
    pub key: Key,
    pub predicted: Option<f64>,
    pub empirical: f64,
    pub reported: Option<f64>,
    /// Mean estimate over the truth's seeds.
    pub mean: f64,
    /// The value the prediction's identification returned.
    pub expected: f64,
    /// Empirical std over noise seeds of the project's own simulator
    /// flying the plan with the prior (the noise-only spread the
    /// prediction's machinery gives), when computed.
    pub self_spread: Option<f64>,
}

impl Comparison {
    /// empirical / predicted (∞ without a prediction).
    pub fn ratio(&self) -> f64 {
        match self.predicted {
            Some(p) if p > 0.0 => self.empirical / p,
            _ => f64::INFINITY,
        }
    }

    /// empirical / mean reported std on the truth runs.
    pub fn reported_ratio(&self) -> f64 {
        match self.reported {
            Some(p) if p > 0.0 => self.empirical / p,
            _ => f64::INFINITY,
        }
    }

    /// Within [1/F, F].
    pub fn within(&self) -> bool {
        in_factor(self.ratio())
    }

    /// mean reported std on the truth runs / predicted std.
    pub fn reported_over_predicted(&self) -> f64 {
        match (self.reported, self.predicted) {
            (Some(r), Some(p)) if p > 0.0 => r / p,
            _ => f64::INFINITY,
        }
    }

    /// empirical std on the truth / empirical std on the project's simulator.
    pub fn truth_over_self(&self) -> f64 {
        match self.self_spread {
            Some(p) if p > 0.0 => self.empirical / p,
            _ => f64::INFINITY,
        }
    }

    /// Structurally zero: no spread and no predicted std.
    pub fn structural_zero(&self) -> bool {
        let tiny = 1e-12 * self.mean.abs().max(1e-300);
        self.empirical <= tiny && self.predicted.is_none_or(|p| p <= tiny)
    }

    pub fn name(&self) -> String {
        let (g, s, u) = &self.key;
        match u {
            Some(u) => format!("{g} {s} @{u}"),
            None => format!("{g} {s}"),
        }
    }
}

/// Per parameter of the prediction, the comparison with the seeds'
/// estimates (parameters missing in any seed are left out and counted).
pub fn compare(pred: &PrecisionPrediction, seeds: &[Estimates]) -> (Vec<Comparison>, usize) {
    let mut out = Vec::new();
    let mut missing = 0;
    for p in &pred.parameters {
        let k = key(&p.group, &p.symbol, p.grid_speed_mps);
        let vals: Vec<(f64, Option<f64>)> =
            seeds.iter().filter_map(|e| e.get(&k).copied()).collect();
        if vals.len() != seeds.len() || vals.len() < 2 {
            missing += 1;
            continue;
        }
        let n = vals.len() as f64;
        let mean = vals.iter().map(|v| v.0).sum::<f64>() / n;
        let var = vals.iter().map(|v| (v.0 - mean).powi(2)).sum::<f64>() / (n - 1.0);
        let rep: Vec<f64> = vals.iter().filter_map(|v| v.1).collect();
        let reported = (rep.len() == vals.len()).then(|| rep.iter().sum::<f64>() / n);
        out.push(Comparison {
            key: k,
            predicted: p.predicted_std,
            empirical: var.sqrt(),
            reported,
            mean,
            expected: p.expected_value,
            self_spread: None,
        });
    }
    (out, missing)
}

/// Within [1/F, F].
pub fn in_factor(r: f64) -> bool {
    (1.0 / FACTOR..=FACTOR).contains(&r)
}

/// Fills in the noise-only spread over `seeds` of the project's own
/// simulator (the predictions' expected values).
pub fn add_self_spread(c: &mut [Comparison], own: &[PrecisionPrediction]) {
    let est: Vec<Estimates> = own.iter().map(estimates_of_prediction).collect();
    for x in c.iter_mut() {
        let vals: Vec<f64> = est
            .iter()
            .filter_map(|e| e.get(&x.key).map(|v| v.0))
            .collect();
        if vals.len() == est.len() && vals.len() > 1 {
            let n = vals.len() as f64;
            let m = vals.iter().sum::<f64>() / n;
            x.self_spread =
                Some((vals.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt());
        }
    }
}

/// Summary of a comparison.
pub struct Summary {
    pub compared: usize,
    pub skipped_zero: usize,
    pub within: usize,
    pub share: f64,
    pub median_ratio: f64,
    pub median_reported_ratio: f64,
    pub reported_within: usize,
    /// Parameters whose predicted std bounds the spread: empirical ≤ F × predicted.
    pub bounded: usize,
    /// Parameters whose reported std on the truth is within F× of the prediction.
    pub reported_predicted_within: usize,
    pub median_reported_over_predicted: f64,
    /// Parameters whose truth spread is within F× of the project's
    /// simulator's spread (when computed).
    pub self_within: usize,
    pub median_truth_over_self: f64,
    /// Median over parameters of |truth mean − predicted value| / predicted std.
    pub median_offset_in_predicted_std: f64,
}

fn median(mut x: Vec<f64>) -> f64 {
    x.sort_by(f64::total_cmp);
    if x.is_empty() {
        return f64::NAN;
    }
    let n = x.len();
    if n % 2 == 1 {
        x[n / 2]
    } else {
        0.5 * (x[n / 2 - 1] + x[n / 2])
    }
}

pub fn summarize(c: &[Comparison]) -> Summary {
    let live: Vec<&Comparison> = c.iter().filter(|c| !c.structural_zero()).collect();
    let within = live.iter().filter(|c| c.within()).count();
    let reported_within = live
        .iter()
        .filter(|c| in_factor(c.reported_ratio()))
        .count();
    let bounded = live.iter().filter(|c| c.ratio() <= FACTOR).count();
    let reported_predicted_within = live
        .iter()
        .filter(|c| in_factor(c.reported_over_predicted()))
        .count();
    let self_within = live
        .iter()
        .filter(|c| in_factor(c.truth_over_self()))
        .count();
    Summary {
        compared: live.len(),
        skipped_zero: c.len() - live.len(),
        within,
        share: within as f64 / live.len().max(1) as f64,
        median_ratio: median(live.iter().map(|c| c.ratio()).collect()),
        median_reported_ratio: median(live.iter().map(|c| c.reported_ratio()).collect()),
        reported_within,
        bounded,
        reported_predicted_within,
        median_reported_over_predicted: median(
            live.iter().map(|c| c.reported_over_predicted()).collect(),
        ),
        self_within,
        median_truth_over_self: median(live.iter().map(|c| c.truth_over_self()).collect()),
        median_offset_in_predicted_std: median(
            live.iter()
                .filter_map(|c| c.predicted.map(|p| (c.mean - c.expected).abs() / p))
                .collect(),
        ),
    }
}

/// One row per compared parameter (structural zeros left out): name,
/// predicted std, empirical std, mean estimate, and the plan's ship hours.
pub fn write_tsv(path: &str, c: &[Comparison], hours: f64) -> std::io::Result<()> {
    use std::fmt::Write as _;
    let mut out = String::from("parameter\tpredicted\tempirical\tmean\thours\n");
    for c in c.iter().filter(|c| !c.structural_zero()) {
        let pred = c.predicted.map_or(String::new(), |v| format!("{v:e}"));
        let _ = writeln!(
            out,
            "{}\t{pred}\t{:e}\t{:e}\t{hours}",
            c.name(),
            c.empirical,
            c.mean
        );
    }
    std::fs::write(path, out)
}

/// Prints the table (worst ratio first when `sorted`) and the summary.
pub fn print_table(c: &[Comparison], seeds: usize) -> Summary {
    let mut live: Vec<&Comparison> = c.iter().filter(|c| !c.structural_zero()).collect();
    live.sort_by(|a, b| {
        let d = |c: &Comparison| c.ratio().ln().abs();
        d(b).total_cmp(&d(a))
    });
    println!(
        "{:<36} {:>11} {:>11} {:>11} {:>11} {:>8} {:>8} {:>8} {:>8}",
        "parameter",
        "predicted",
        "empirical",
        "reported",
        "own-sim",
        "emp/pred",
        "emp/rep",
        "rep/pred",
        "emp/own"
    );
    for c in &live {
        let f = |v: Option<f64>| v.map_or("—".to_string(), |v| format!("{v:.3e}"));
        // A ratio without its denominator (no own-simulator spread asked
        // for, or a zero std) is shown as "—", never as inf.
        let r = |v: f64| {
            if v.is_finite() {
                format!("{v:.3}")
            } else {
                "—".to_string()
            }
        };
        println!(
            "{:<36} {:>11} {:>11.3e} {:>11} {:>11} {:>8} {:>8} {:>8} {:>8}{}",
            c.name(),
            f(c.predicted),
            c.empirical,
            f(c.reported),
            f(c.self_spread),
            r(c.ratio()),
            r(c.reported_ratio()),
            r(c.reported_over_predicted()),
            r(c.truth_over_self()),
            if c.within() { "" } else { "  ✗" }
        );
    }
    let s = summarize(c);
    println!(
        "{seeds} seeds: {} of {} parameters within {FACTOR}× ({:.1} %), {} structurally zero skipped; median empirical/predicted {:.3}; empirical/reported(on truth) within {FACTOR}×: {} ({:.1} %), median {:.3}",
        s.within,
        s.compared,
        100.0 * s.share,
        s.skipped_zero,
        s.median_ratio,
        s.reported_within,
        100.0 * s.reported_within as f64 / s.compared.max(1) as f64,
        s.median_reported_ratio
    );
    let pct = |k: usize| 100.0 * k as f64 / s.compared.max(1) as f64;
    println!(
        "predicted std ≥ empirical/{FACTOR} (a bound): {} ({:.1} %); reported std on the truth within {FACTOR}× of the prediction: {} ({:.1} %), median reported/predicted {:.3}",
        s.bounded,
        pct(s.bounded),
        s.reported_predicted_within,
        pct(s.reported_predicted_within),
        s.median_reported_over_predicted
    );
    println!(
        "median |truth mean − predicted value| / predicted std: {:.3}",
        s.median_offset_in_predicted_std
    );
    if c.iter().any(|c| c.self_spread.is_some()) {
        println!(
            "truth spread within {FACTOR}× of the project's simulator's noise-only spread: {} ({:.1} %), median truth/own {:.3}",
            s.self_within,
            pct(s.self_within),
            s.median_truth_over_self
        );
    }
    s
}
