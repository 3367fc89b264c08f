//! Where simulation and recordings part: per DOF (1-step, k-step and
//! free-run fits, whiteness), per time segment, per frequency band (the
//! 1-step residual's PSD against the sensor-noise floor), and per operating
//! condition (forward speed, heading, input amplitude).

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::data::Record;
use super::model::AugmentedModel;
use super::report::Fits;
use super::residual::{BandPower, Whiteness, residual_spectrum, whiteness};
use crate::planning::Dof;
use crate::validation::nrmse_fit;

/// Excess over the noise floor that counts as structure (dB).
pub const BAND_EXCESS_DB: f64 = 10.0;
/// A segment whose free-run error RMS exceeds the median segment by this
/// factor is reported.
pub const SEGMENT_RATIO: f64 = 2.0;
/// An operating condition whose bins' k-step error RMS spread exceeds this
/// factor is reported.
pub const CONDITION_RATIO: f64 = 1.8;

/// Predictions of a model on one run.
pub(crate) struct Predictions {
    pub one: DMatrix<f64>,
    pub k: DMatrix<f64>,
    pub free: DMatrix<f64>,
}

pub(crate) fn predict(model: &AugmentedModel, rec: &Record, k: usize) -> Predictions {
    Predictions {
        one: model.predict_k_step(rec, 1),
        k: model.predict_k_step(rec, k),
        free: model.simulate(rec),
    }
}

/// Residual of column `i`: measured − predicted (NaN where no prediction).
pub(crate) fn residual(rec: &Record, pred: &DMatrix<f64>, i: usize) -> Vec<f64> {
    (0..rec.len())
        .map(|k| rec.nu[(k, i)] - pred[(k, i)])
        .collect()
}

/// The 1-step residual of channel `i` as a force in that DOF alone:
/// e_i / (h·(M⁻¹)_ii) per sample. A force f_i slow against the sampling
/// leaves e ≈ h·M⁻¹·f in the 1-step prediction, whatever the controller
/// does with it (the logged τ carries the controller's answer); the other
/// channels' misfit is kept out. N or N·m; empty when M is singular.
pub(crate) fn force_residual(
    model: &AugmentedModel,
    rec: &Record,
    pred: &DMatrix<f64>,
    i: usize,
) -> Vec<f64> {
    let Some(mi) = model.m.clone().try_inverse() else {
        return Vec::new();
    };
    let gain = mi[(i, i)] * rec.h;
    if !(gain.is_finite() && gain > 0.0) {
        return Vec::new();
    }
    residual(rec, pred, i)
        .into_iter()
        .map(|e| e / gain)
        .collect()
}

/// Mean of the defined fits.
pub(crate) fn mean_fit(v: &[Option<f64>]) -> Option<f64> {
    let d: Vec<f64> = v.iter().flatten().copied().collect();
    (!d.is_empty()).then(|| d.iter().sum::<f64>() / d.len() as f64)
}

/// Fits of channel `i` averaged over runs.
pub(crate) fn channel_fits(runs: &[&Record], preds: &[Predictions], i: usize) -> Fits {
    let f = |sel: &dyn Fn(&Predictions) -> &DMatrix<f64>| {
        let v: Vec<Option<f64>> = runs
            .iter()
            .zip(preds)
            .map(|(r, p)| nrmse_fit(r.nu.column(i).as_slice(), sel(p).column(i).as_slice()))
            .collect();
        mean_fit(&v)
    };
    Fits {
        one_step: f(&|p| &p.one),
        k_step: f(&|p| &p.k),
        free_run: f(&|p| &p.free),
    }
}

/// Diagonal of the 1-step transition Φ ≈ e^{−h M⁻¹D̄} (for the noise floor).
pub(crate) fn phi_diag(model: &AugmentedModel, h: f64) -> Vec<f64> {
    let a = match model.m.clone().try_inverse() {
        Some(mi) => mi * &model.d_bar,
        None => return vec![0.0; model.dofs.len()],
    };
    (0..model.dofs.len())
        .map(|i| (-h * a[(i, i)]).exp().clamp(0.0, 1.0))
        .collect()
}

/// One DOF's overall picture.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct DofLocation {
    /// The DOF.
    pub dof: Dof,
    /// Fits averaged over runs.
    pub fits: Fits,
    /// Mean free-run error (measured − simulated), a bias.
    pub free_run_bias: f64,
    /// Whiteness of the 1-step residual.
    pub whiteness: Whiteness,
    /// True when this DOF shows structure the model misses.
    pub parts: bool,
}

/// A time segment where the free run leaves the recording.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct SegmentFinding {
    /// Run.
    pub run: String,
    /// DOF.
    pub dof: Dof,
    /// Start (s).
    pub start_s: f64,
    /// End (s).
    pub end_s: f64,
    /// Free-run error RMS in the segment.
    pub error_rms: f64,
    /// Ratio to the median segment's RMS.
    pub ratio_to_median: f64,
}

/// Residual structure in a frequency band.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct BandFinding {
    /// DOF.
    pub dof: Dof,
    /// The band.
    pub band: BandPower,
    /// Low-frequency PSD slope of the residual.
    pub low_slope: f64,
}

/// The operating condition a residual is binned by.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum Condition {
    /// Forward speed u (m/s).
    ForwardSpeed,
    /// Heading ψ (rad).
    Heading,
    /// |τ_i| of the DOF itself.
    InputAmplitude,
}

/// Residual statistics in one bin.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct ConditionBin {
    /// Lower edge.
    pub lo: f64,
    /// Upper edge.
    pub hi: f64,
    /// Samples.
    pub n: usize,
    /// Mean k-step residual.
    pub mean: f64,
    /// RMS k-step residual.
    pub rms: f64,
}

/// How a DOF's k-step error depends on an operating condition.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct ConditionFinding {
    /// DOF.
    pub dof: Dof,
    /// Condition.
    pub condition: Condition,
    /// Bins.
    pub bins: Vec<ConditionBin>,
    /// Largest / smallest bin RMS.
    pub spread_ratio: f64,
}

/// Where the model and the recordings part.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct LocationReport {
    /// k of the k-step predictions.
    pub k_step: usize,
    /// Per DOF.
    pub per_dof: Vec<DofLocation>,
    /// Segments that stand out.
    pub segments: Vec<SegmentFinding>,
    /// Bands above the noise floor.
    pub bands: Vec<BandFinding>,
    /// Operating-condition dependence.
    pub conditions: Vec<ConditionFinding>,
    /// Short sentences.
    pub sentences: Vec<String>,
}

/// Locates the model's misfit on `runs`.
pub fn locate(
    model: &AugmentedModel,
    runs: &[&Record],
    k: usize,
    segment_s: f64,
) -> LocationReport {
    let preds: Vec<Predictions> = runs.iter().map(|r| predict(model, r, k)).collect();
    let n = model.dofs.len();
    let h = runs.first().map_or(0.1, |r| r.h);
    let phi = phi_diag(model, h);
    let mut rep = LocationReport {
        k_step: k,
        per_dof: vec![],
        segments: vec![],
        bands: vec![],
        conditions: vec![],
        sentences: vec![],
    };
    let iu = model.dofs.iter().position(|&d| d == Dof::Surge);
    for (i, &phi_i) in phi.iter().enumerate().take(n) {
        let dof = model.dofs[i];
        let one: Vec<Vec<f64>> = runs
            .iter()
            .zip(&preds)
            .map(|(r, p)| residual(r, &p.one, i))
            .collect();
        let kst: Vec<Vec<f64>> = runs
            .iter()
            .zip(&preds)
            .map(|(r, p)| residual(r, &p.k, i))
            .collect();
        let free: Vec<Vec<f64>> = runs
            .iter()
            .zip(&preds)
            .map(|(r, p)| residual(r, &p.free, i))
            .collect();
        let fits = channel_fits(runs, &preds, i);
        let w = whiteness(&one, 30);
        let nf: usize = free.iter().map(Vec::len).sum();
        let bias = free.iter().flatten().sum::<f64>() / nf.max(1) as f64;
        let mut parts = false;
        // Frequency bands.
        if let Some(spec) = residual_spectrum(&one, 1.0 / h, phi_i) {
            for b in spec.bands.iter().filter(|b| b.excess_db > BAND_EXCESS_DB) {
                parts = true;
                rep.bands.push(BandFinding {
                    dof,
                    band: b.clone(),
                    low_slope: spec.low_slope,
                });
            }
        }
        // Time segments of the free run.
        let seg = ((segment_s / h).round() as usize).max(10);
        let mut segs: Vec<(usize, usize, f64)> = Vec::new();
        for (ri, e) in free.iter().enumerate() {
            for s in (0..e.len()).step_by(seg) {
                let part = &e[s..(s + seg).min(e.len())];
                if part.len() * 2 < seg {
                    continue;
                }
                let rms = (part.iter().map(|x| x * x).sum::<f64>() / part.len() as f64).sqrt();
                segs.push((ri, s, rms));
            }
        }
        let mut sorted: Vec<f64> = segs.iter().map(|s| s.2).collect();
        sorted.sort_by(|a, b| a.total_cmp(b));
        let median = sorted.get(sorted.len() / 2).copied().unwrap_or(0.0);
        if let Some(worst) = segs.iter().max_by(|a, b| a.2.total_cmp(&b.2))
            && median > 0.0
            && worst.2 > SEGMENT_RATIO * median
        {
            rep.segments.push(SegmentFinding {
                run: runs[worst.0].name.clone(),
                dof,
                start_s: worst.1 as f64 * h,
                end_s: ((worst.1 + seg).min(free[worst.0].len())) as f64 * h,
                error_rms: worst.2,
                ratio_to_median: worst.2 / median,
            });
        }
        // Operating conditions, on the k-step residual.
        let mut conds: Vec<(Condition, Vec<(f64, f64)>)> = Vec::new();
        let pairs = |val: &dyn Fn(&Record, usize) -> f64| -> Vec<(f64, f64)> {
            runs.iter()
                .zip(&kst)
                .flat_map(|(r, e)| {
                    (0..r.len())
                        .filter(|&t| e[t].is_finite())
                        .map(|t| (val(r, t), e[t]))
                        .collect::<Vec<_>>()
                })
                .collect()
        };
        if let Some(iu) = iu {
            conds.push((Condition::ForwardSpeed, pairs(&|r, t| r.nu[(t, iu)])));
        }
        conds.push((
            Condition::Heading,
            pairs(&|r, t| r.eta[(t, 5)].rem_euclid(std::f64::consts::TAU)),
        ));
        conds.push((
            Condition::InputAmplitude,
            pairs(&|r, t| r.tau[(t, i)].abs()),
        ));
        for (c, v) in conds {
            if let Some(f) = bin_condition(dof, c, v)
                && f.spread_ratio > CONDITION_RATIO
            {
                parts = true;
                rep.conditions.push(f);
            }
        }
        // Whiteness alone does not flag a DOF: sensor noise on ν makes the
        // 1-step residual n_{k+1} − Φn_k coloured even for a perfect model.
        if fits.free_run.is_some_and(|f| f < 0.9) {
            parts = true;
        }
        rep.per_dof.push(DofLocation {
            dof,
            fits,
            free_run_bias: bias,
            whiteness: w,
            parts,
        });
    }
    rep.sentences = sentences(&rep);
    rep
}

/// Quartile bins (heading: four quadrants) of (value, residual) pairs.
fn bin_condition(dof: Dof, c: Condition, mut v: Vec<(f64, f64)>) -> Option<ConditionFinding> {
    if v.len() < 80 {
        return None;
    }
    let edges: Vec<f64> = if c == Condition::Heading {
        (0..=4)
            .map(|q| q as f64 * std::f64::consts::FRAC_PI_2)
            .collect()
    } else {
        v.sort_by(|a, b| a.0.total_cmp(&b.0));
        let q = |p: f64| v[((v.len() - 1) as f64 * p) as usize].0;
        let e = vec![q(0.0), q(0.25), q(0.5), q(0.75), q(1.0)];
        if e[4] - e[0] <= 0.0 {
            return None;
        }
        e
    };
    let mut bins = Vec::new();
    for b in 0..4 {
        let (lo, hi) = (edges[b], edges[b + 1]);
        let sel: Vec<f64> = v
            .iter()
            .filter(|(x, _)| *x >= lo && (*x < hi || (b == 3 && *x <= hi)))
            .map(|p| p.1)
            .collect();
        if sel.len() < 20 {
            continue;
        }
        let mean = sel.iter().sum::<f64>() / sel.len() as f64;
        let rms = (sel.iter().map(|x| x * x).sum::<f64>() / sel.len() as f64).sqrt();
        bins.push(ConditionBin {
            lo,
            hi,
            n: sel.len(),
            mean,
            rms,
        });
    }
    if bins.len() < 2 {
        return None;
    }
    let max = bins.iter().map(|b| b.rms).fold(0.0, f64::max);
    let min = bins.iter().map(|b| b.rms).fold(f64::INFINITY, f64::min);
    Some(ConditionFinding {
        dof,
        condition: c,
        bins,
        spread_ratio: if min > 0.0 { max / min } else { 1.0 },
    })
}

/// A fit with two decimals; far below the mean (a run-away simulation) the
/// digits mean nothing: `< −10`.
fn fmt_fit(f: Option<f64>) -> String {
    match f.filter(|x| x.is_finite()) {
        None => "–".into(),
        Some(x) if x < crate::numbers::FIT_FLOOR => "< −10".into(),
        Some(x) => format!("{x:.2}"),
    }
}

fn sentences(rep: &LocationReport) -> Vec<String> {
    let mut out = Vec::new();
    for d in &rep.per_dof {
        let name = capital(d.dof.name());
        let f = &d.fits;
        let mut s = format!(
            "{name}: free-run fit {}, {}-step {}, 1-step {}",
            fmt_fit(f.free_run),
            rep.k_step,
            fmt_fit(f.k_step),
            fmt_fit(f.one_step)
        );
        if d.whiteness.white {
            s.push_str("; residuals white.");
        } else {
            s.push_str(&format!(
                "; residuals not white ({} of {} lags outside ±{:.3}, {} zero crossings).",
                d.whiteness.lags_outside,
                d.whiteness.lags,
                d.whiteness.bound,
                d.whiteness.zero_crossings
            ));
        }
        if d.parts {
            out.push(s);
        }
    }
    for b in &rep.bands {
        out.push(format!(
            "{}: 1-step residual {:.0} dB above the noise floor at {:.3}–{:.3} Hz{}.",
            capital(b.dof.name()),
            b.band.excess_db,
            b.band.f_lo_hz,
            b.band.f_hi_hz,
            signature_words(b.low_slope, &b.band)
        ));
    }
    for c in &rep.conditions {
        let what = match c.condition {
            Condition::ForwardSpeed => "forward speed",
            Condition::Heading => "heading",
            Condition::InputAmplitude => "input amplitude",
        };
        let first = c.bins.first().map_or(0.0, |b| b.rms);
        let last = c.bins.last().map_or(0.0, |b| b.rms);
        let trend = if c.condition == Condition::Heading {
            "varies with".to_string()
        } else if last > first {
            "grows with".to_string()
        } else {
            "shrinks with".to_string()
        };
        out.push(format!(
            "{}: {}-step error {trend} {what} ({:.1}× between bins).",
            capital(c.dof.name()),
            rep.k_step,
            c.spread_ratio
        ));
    }
    for s in &rep.segments {
        out.push(format!(
            "{}: free run leaves run {} at {:.0}–{:.0} s (error {:.1}× the median segment).",
            capital(s.dof.name()),
            s.run,
            s.start_s,
            s.end_s,
            s.ratio_to_median
        ));
    }
    if out.is_empty() {
        out.push(
            "The model follows the recordings in every DOF: residuals are at the noise floor."
                .into(),
        );
    }
    out
}

/// The spectral signature of residual structure, in words.
pub(crate) fn signature_words(low_slope: f64, band: &BandPower) -> String {
    if band.f_hi_hz <= 0.05 && low_slope < -1.0 {
        format!(
            ", drift-like (PSD slope {low_slope:.1}, as a random walk or a slowly varying load)"
        )
    } else if band.f_lo_hz >= 1.0 {
        ", high-frequency (fast actuator or sampling effects)".into()
    } else {
        format!(", peak at {:.3} Hz", band.peak_hz)
    }
}

pub(crate) fn capital(s: &str) -> String {
    let mut c = s.chars();
    match c.next() {
        Some(f) => f.to_uppercase().collect::<String>() + c.as_str(),
        None => String::new(),
    }
}
