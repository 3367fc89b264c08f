//! The verdict on each DOF — `Good`, `Weak` or `Insufficient` — and its
//! reason in words a supervisor acts on.
//!
//! Rules, checked in this order (all that apply are reported, the worst
//! decides):
//!
//! **Insufficient**
//! 1. the DOF's input is not excited: PE order < [`MIN_PE_ORDER`], or its
//!    RMS about the mean is ≤ [`FLAT_INPUT_RELATIVE_RMS`] × |mean| (0 for a
//!    zero-mean input), or its PSD has no usable band — action: repeat the
//!    run following the planned schedule (a run matched to no planned
//!    experiment: fly one that excites the DOF, if it is to be identified);
//! 2. the record gives fewer than [`MIN_SEGMENTS`] Welch segments
//!    (coherence of one segment is 1 whatever the data) — action: log
//!    longer continuous data;
//! 3. the median coherence input→output over the input's usable band is
//!    < [`MIN_MEDIAN_COHERENCE`] — action: more amplitude or a slower PRBS
//!    clock (more power where it matters).
//!
//! **Weak**
//! 4. coherence ≥ [`GOOD_COHERENCE`] covers less than
//!    [`MIN_COHERENT_FRACTION`] of the usable band's bins. (With the
//!    threshold 0.5 of rule 3 this rule would say the same as rule 3 — a
//!    median ≥ 0.5 *is* coherence ≥ 0.5 over half the band — so it uses the
//!    "good" level 0.8: Good needs coherence ≥ 0.8 over half the band.);
//! 5. the input's Nyquist warning fires;
//! 6. a planned column of the DOF (its input or output) was not followed
//!    (only for a run matched to a planned experiment: a run flown without
//!    a plan has no adherence to fail);
//! 7. the full regressor has fewer identifiable parameters than columns
//!    *because of the inputs*: one of its deficient directions lies mostly
//!    (≥ [`MIN_INPUT_SHARE`] of its energy) on input columns and involves
//!    the DOF's input — a dead input, or inputs excited by one and the same
//!    signal (e.g. sway and yaw) — action: independent excitation per
//!    input. Directions mostly on output lags are not held against the
//!    log: a first-order DOF measured with little noise makes
//!    `y(t−1), y(t−2), x(t−1)` dependent whatever the experiment, which the
//!    model order (`lags`) must answer.
//!
//! Rules 2–4 and 7 are skipped for an input that is not excited (nothing
//! to add; the Nyquist and plan findings still explain why it is not), and
//! 3–4 without at least 2 segments.
//!
//! **Good** otherwise.

use super::excitation::describe;
use super::words::{band, num, pct};
use super::{
    Adherence, DofChannels, DofEvidence, DofVerdict, InputQuality, RegressorReport, Verdict,
    WelchSummary,
};

/// Smallest PE order of an excited input: a constant (order ≤ 1 about its
/// mean) carries no dynamic information, a single sinusoid (order 2) the
/// least that identifies a first-order DOF.
pub const MIN_PE_ORDER: usize = 2;

/// Fewest Welch segments for coherence to mean anything.
pub const MIN_SEGMENTS: usize = 2;

/// Smallest median coherence over the usable band: below it, noise and
/// disturbances explain more of the output than the input does.
pub const MIN_MEDIAN_COHERENCE: f64 = 0.5;

/// Smallest share of the usable band's bins with coherence ≥
/// [`GOOD_COHERENCE`] (rule 4).
pub const MIN_COHERENT_FRACTION: f64 = 0.5;

/// Coherence counted as good: the output is ≥ 80 % explained by the input
/// (signal-to-noise ratio ≥ 4), the level of the reason of a Good DOF.
pub const GOOD_COHERENCE: f64 = 0.8;

/// Share of a deficient direction's energy on input columns from which the
/// inputs are held responsible (rule 7).
pub const MIN_INPUT_SHARE: f64 = 0.5;

/// An input whose RMS about its mean is at most this fraction of |mean| is
/// flat (e.g. a thrust held constant, logged with rounding noise).
pub const FLAT_INPUT_RELATIVE_RMS: f64 = 1e-6;

const ACT_REPEAT: &str = "repeat it following the planned schedule";
/// The action for an input that is not excited in a run matched to no
/// planned experiment: there is no schedule to repeat, and a run flown for
/// other DOFs is no failure of this one.
const ACT_EXCITE: &str = "if this DOF is to be identified, fly a run that excites it (the run is matched to no planned experiment)";
const ACT_SNR: &str = "fly it again with twice the amplitude or a slower PRBS clock";
const ACT_NYQUIST: &str = "log the inputs at the controller rate";
const ACT_INDEPENDENT: &str =
    "excite each input with its own independent signal (another PRBS seed or schedule) and repeat";

/// What the verdict on one DOF looks at.
pub(crate) struct DofContext<'a> {
    pub dof: &'a DofChannels,
    pub input: &'a InputQuality,
    pub freqs: &'a [f64],
    pub coherence: &'a [f64],
    pub welch: &'a WelchSummary,
    pub fs: f64,
    pub adherence: &'a [Adherence],
    pub regressor: &'a RegressorReport,
    /// Identifiable parameters and columns of the DOF's own regressor.
    pub own_rank: (usize, usize),
    /// The run was matched to a planned experiment (a schedule to follow).
    pub planned: bool,
}

/// Coherence over the usable band.
struct BandCoherence {
    median: f64,
    /// Share of bins with coherence ≥ [`GOOD_COHERENCE`].
    good_fraction: f64,
    good_span: Option<[f64; 2]>,
    /// `(frequency, coherence)` of the band's bins (DC excluded).
    bins: Vec<(f64, f64)>,
}

/// The median of `values` (not empty; reordered), the mean of the two
/// middle values for an even count: by selection, not a full sort.
fn median_of(values: &mut [f64]) -> f64 {
    let k = values.len();
    let (below, &mut upper, _) = values.select_nth_unstable_by(k / 2, f64::total_cmp);
    if k % 2 == 1 {
        upper
    } else {
        // The largest of the lower half.
        let lower = below
            .iter()
            .copied()
            .max_by(f64::total_cmp)
            .unwrap_or(upper);
        0.5 * (lower + upper)
    }
}

fn band_coherence(freqs: &[f64], coh: &[f64], b: [f64; 2]) -> Option<BandCoherence> {
    let tol = 1e-9 * b[1].abs().max(1.0);
    let bins: Vec<(f64, f64)> = freqs
        .iter()
        .zip(coh)
        .skip(1)
        .filter(|(f, _)| **f >= b[0] - tol && **f <= b[1] + tol)
        .map(|(f, c)| (*f, *c))
        .collect();
    if bins.is_empty() {
        return None;
    }
    let mut values: Vec<f64> = bins.iter().map(|b| b.1).collect();
    let median = median_of(&mut values);
    let good: Vec<f64> = bins
        .iter()
        .filter(|b| b.1 >= GOOD_COHERENCE)
        .map(|b| b.0)
        .collect();
    let good_span = match (good.first(), good.last()) {
        (Some(a), Some(z)) => Some([*a, *z]),
        _ => None,
    };
    Some(BandCoherence {
        median,
        good_fraction: good.len() as f64 / bins.len() as f64,
        good_span,
        bins,
    })
}

/// Where coherence is below `threshold` in the band, in words: "coherence
/// below 0.5 above 0.12 Hz", "… below 0.03 Hz", "… over 0.1–0.3 Hz" or
/// "… over 30 % of it, between 0.1–0.9 Hz"; `None` when nowhere.
///
/// The estimate scatters from bin to bin, so the curve is first smoothed
/// by a running mean over 5 % of the band's bins (odd width): a coherence
/// that hovers about the threshold then reads as one crossing, not as
/// hundreds of isolated bins.
fn low_coherence(bins: &[(f64, f64)], threshold: f64) -> Option<String> {
    let k = bins.len();
    let half = k / 40; // window 2·half + 1 ≈ 5 % of the bins
    let mut prefix = Vec::with_capacity(k + 1);
    prefix.push(0.0);
    for b in bins {
        prefix.push(prefix[prefix.len() - 1] + b.1);
    }
    let smooth = |i: usize| {
        let (lo, hi) = (i.saturating_sub(half), (i + half + 1).min(k));
        (prefix[hi] - prefix[lo]) / (hi - lo) as f64
    };
    let low: Vec<usize> = (0..k).filter(|&i| smooth(i) < threshold).collect();
    let (&first, &last) = (low.first()?, low.last()?);
    let t = num(threshold);
    Some(if last - first + 1 == low.len() {
        if last == k - 1 && first > 0 {
            format!("coherence below {t} above {} Hz", num(bins[first].0))
        } else if first == 0 && last < k - 1 {
            format!("coherence below {t} below {} Hz", num(bins[last].0))
        } else {
            format!(
                "coherence below {t} over {}",
                band([bins[first].0, bins[last].0])
            )
        }
    } else {
        format!(
            "coherence below {t} over {} of it, between {}",
            pct(low.len() as f64 / k as f64),
            band([bins[first].0, bins[last].0])
        )
    })
}

/// The input is flat: its RMS about the mean is 0 or negligible (rule 1).
fn flat(q: &InputQuality) -> bool {
    q.rms == 0.0 || q.rms <= FLAT_INPUT_RELATIVE_RMS * q.mean.abs()
}

/// Whether the input excites the DOF at all (rule 1).
fn excited(q: &InputQuality) -> bool {
    q.pe_order >= MIN_PE_ORDER && !flat(q) && q.usable_band_hz.is_some()
}

/// Channel of a regressor column `name(t-k)`.
pub(crate) fn channel_of(column: &str) -> &str {
    column.rfind("(t-").map_or(column, |i| &column[..i])
}

/// `a`, `a and b`, `a, b and c`.
pub(crate) fn and_list(items: &[&str]) -> String {
    match items {
        [] => String::new(),
        [one] => (*one).to_owned(),
        [init @ .., last] => format!("{} and {last}", init.join(", ")),
    }
}

/// The channels of the full regressor's dependency groups that lie mostly
/// on input columns and involve the DOF's input (empty when none), the
/// DOF's input first.
fn deficient_channels<'a>(ctx: &'a DofContext<'_>) -> Vec<&'a str> {
    let input = ctx.dof.input.as_str();
    let mut chans: Vec<&str> = Vec::new();
    for d in &ctx.regressor.deficient_directions {
        if d.input_share >= MIN_INPUT_SHARE
            && d.columns.iter().any(|c| channel_of(&c.column) == input)
        {
            if chans.is_empty() {
                chans.push(input);
            }
            for c in &d.columns {
                let ch = channel_of(&c.column);
                if !chans.contains(&ch) {
                    chans.push(ch);
                }
            }
        }
    }
    chans
}

/// Judges one DOF.
pub(crate) fn judge(ctx: &DofContext<'_>) -> DofVerdict {
    let d = ctx.dof;
    let q = ctx.input;
    let mut issues: Vec<(Verdict, String)> = Vec::new();
    let is_excited = excited(q);
    let enough_segments = ctx.welch.n_segments >= MIN_SEGMENTS;
    let bc = q
        .usable_band_hz
        .and_then(|b| band_coherence(ctx.freqs, ctx.coherence, b));

    if !is_excited {
        let what = if flat(q) || q.usable_band_hz.is_none() {
            "barely moved"
        } else {
            "excites too few frequencies"
        };
        issues.push((
            Verdict::Insufficient,
            format!(
                "the input {} {what} ({}); the run holds no dynamic information — {}",
                d.input,
                describe(q),
                if ctx.planned { ACT_REPEAT } else { ACT_EXCITE }
            ),
        ));
    }
    if is_excited && !enough_segments {
        let step = ctx.welch.nperseg - ctx.welch.noverlap;
        let needed_s = (ctx.welch.nperseg + step) as f64 / ctx.fs;
        issues.push((
            Verdict::Insufficient,
            format!(
                "the record gives {} Welch segment(s) of {} s (needs ≥ {MIN_SEGMENTS}), so coherence \
                 cannot be judged — log at least {} s of continuous valid data",
                ctx.welch.n_segments,
                num(ctx.welch.segment_s),
                num(needed_s)
            ),
        ));
    }
    if is_excited
        && enough_segments
        && let (Some(bc), Some(b)) = (&bc, q.usable_band_hz)
    {
        if bc.median < MIN_MEDIAN_COHERENCE {
            let low = low_coherence(&bc.bins, MIN_MEDIAN_COHERENCE)
                .map_or(String::new(), |l| format!(", {l}"));
            issues.push((
                Verdict::Insufficient,
                format!(
                    "median coherence {} from {} to {} over the usable band {} (needs ≥ {MIN_MEDIAN_COHERENCE}){low}: \
                     noise and disturbances dominate the output — {ACT_SNR}",
                    num(bc.median),
                    d.input,
                    d.output,
                    band(b)
                ),
            ));
        } else if bc.good_fraction < MIN_COHERENT_FRACTION {
            let low = low_coherence(&bc.bins, GOOD_COHERENCE)
                .map_or(String::new(), |l| format!(" ({l})"));
            issues.push((
                Verdict::Weak,
                format!(
                    "coherence ≥ {GOOD_COHERENCE} over only {} of the usable band {}{low}; {ACT_SNR}",
                    pct(bc.good_fraction),
                    band(b)
                ),
            ));
        }
    }
    if let Some(w) = &q.nyquist.warning {
        issues.push((Verdict::Weak, format!("{w} — {ACT_NYQUIST}")));
    }
    let planned: Vec<&Adherence> = ctx
        .adherence
        .iter()
        .filter(|a| a.log_column == d.input || a.log_column == d.output)
        .collect();
    let plan_followed = (!planned.is_empty()).then(|| planned.iter().all(|a| a.followed));
    for a in planned.iter().filter(|a| !a.followed) {
        issues.push((Verdict::Weak, format!("{} — {ACT_REPEAT}", a.message)));
    }
    let (own_id, own_cols) = ctx.own_rank;
    let deficient = deficient_channels(ctx);
    if is_excited && !deficient.is_empty() {
        let what = if deficient.len() == 1 {
            format!(
                "the lags of {} are (nearly) dependent: it excites too few frequencies",
                deficient[0]
            )
        } else {
            format!("{} move together (nearly collinear)", and_list(&deficient))
        };
        issues.push((
            Verdict::Weak,
            format!(
                "the regressor is rank-deficient through the inputs: {what} ({} of {} parameters \
                 identifiable) — {ACT_INDEPENDENT}",
                ctx.regressor.identifiable, ctx.regressor.n_columns
            ),
        ));
    }

    let verdict = issues.iter().map(|i| i.0).max().unwrap_or(Verdict::Good);
    issues.sort_by_key(|i| std::cmp::Reverse(i.0));
    let name = d.dof.name();
    let reason = if issues.is_empty() {
        let coherence = match (&bc, q.usable_band_hz) {
            (Some(bc), Some(b)) => match bc.good_span {
                Some(span) => format!(
                    "coherence ≥ {GOOD_COHERENCE} over {} (median {} over the usable band {})",
                    band(span),
                    num(bc.median),
                    band(b)
                ),
                None => format!(
                    "median coherence {} over the usable band {}",
                    num(bc.median),
                    band(b)
                ),
            },
            _ => String::from("coherence not assessed"),
        };
        let pe = if q.pe_order >= q.pe_cap {
            format!("PE order ≥ {}", q.pe_order)
        } else {
            format!("PE order {}", q.pe_order)
        };
        format!(
            "{name}: good — {coherence}, {pe} of {}, {own_id} of {own_cols} regressor parameters identifiable",
            d.input
        )
    } else {
        let texts: Vec<&str> = issues.iter().map(|i| i.1.as_str()).collect();
        format!("{name}: {}", texts.join("; "))
    };
    DofVerdict {
        dof: d.dof,
        input: d.input.clone(),
        output: d.output.clone(),
        verdict,
        reason,
        evidence: DofEvidence {
            pe_order: q.pe_order,
            input_rms: q.rms,
            n_segments: ctx.welch.n_segments,
            usable_band_hz: q.usable_band_hz,
            median_coherence: bc.as_ref().map(|b| b.median),
            coherent_fraction: bc.as_ref().map(|b| b.good_fraction),
            good_coherence_span_hz: bc.as_ref().and_then(|b| b.good_span),
            nyquist_warning: q.nyquist.warning.is_some(),
            plan_followed,
            identifiable: own_id,
            n_columns: own_cols,
            input_deficient: !deficient.is_empty(),
        },
    }
}

/// The verdicts of a log whose units look wrong (`doubts`: the plausibility
/// warnings about units, in words): every DOF becomes
/// [`Verdict::CheckUnits`] with a reason that names the doubts, instead of
/// a "fly it again" computed on numbers in the wrong units. The evidence
/// stays as computed. No doubts: the verdicts are left as they are.
pub fn units_first(verdicts: &mut [DofVerdict], doubts: &[&str]) {
    if doubts.is_empty() {
        return;
    }
    let doubts = doubts.join("; ");
    for v in verdicts {
        v.verdict = Verdict::CheckUnits;
        v.reason = format!(
            "{}: check the log's units first — {doubts}; fix them and upload the log again \
             (its excitation is not judged until then)",
            v.dof.name()
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_by_selection_is_the_sorted_median() {
        let mut rng = crate::rng::SplitMix64::new(9);
        for n in [1, 2, 3, 10, 11, 2048, 2049] {
            let v: Vec<f64> = (0..n).map(|_| rng.normal()).collect();
            let mut sorted = v.clone();
            sorted.sort_by(f64::total_cmp);
            let want = if n % 2 == 1 {
                sorted[n / 2]
            } else {
                0.5 * (sorted[n / 2 - 1] + sorted[n / 2])
            };
            assert_eq!(median_of(&mut v.clone()), want, "n = {n}");
        }
    }

    #[test]
    fn band_coherence_describes_where_it_is_low() {
        let freqs: Vec<f64> = (0..11).map(|k| k as f64 * 0.1).collect();
        // Bins 1..=10 in band [0.1, 1.0]: high below 0.5 Hz, low above.
        let coh: Vec<f64> = freqs
            .iter()
            .map(|f| if *f < 0.55 { 0.9 } else { 0.2 })
            .collect();
        let bc = band_coherence(&freqs, &coh, [0.1, 1.0]).unwrap();
        assert_eq!(bc.good_fraction, 0.5);
        assert!((bc.median - 0.55).abs() < 1e-12);
        assert_eq!(bc.good_span, Some([0.1, 0.5]));
        assert_eq!(
            low_coherence(&bc.bins, 0.5).as_deref(),
            Some("coherence below 0.5 above 0.6 Hz")
        );
        let rev: Vec<f64> = coh.iter().rev().copied().collect();
        let bc = band_coherence(&freqs, &rev, [0.1, 1.0]).unwrap();
        assert_eq!(
            low_coherence(&bc.bins, 0.8).as_deref(),
            Some("coherence below 0.8 below 0.4 Hz")
        );
        let mid: Vec<f64> = freqs
            .iter()
            .map(|f| if (0.35..0.65).contains(f) { 0.1 } else { 0.9 })
            .collect();
        let bc = band_coherence(&freqs, &mid, [0.1, 1.0]).unwrap();
        assert_eq!(
            low_coherence(&bc.bins, 0.5).as_deref(),
            Some("coherence below 0.5 over 0.4–0.6 Hz")
        );
        let holes: Vec<f64> = (0..11)
            .map(|k| if k % 3 == 0 { 0.1 } else { 0.9 })
            .collect();
        let bc = band_coherence(&freqs, &holes, [0.1, 1.0]).unwrap();
        assert_eq!(
            low_coherence(&bc.bins, 0.5).as_deref(),
            Some("coherence below 0.5 over 30 % of it, between 0.3–0.9 Hz")
        );
        assert!(band_coherence(&freqs, &coh, [2.0, 3.0]).is_none());
        let all_good = vec![0.95; 11];
        let bc = band_coherence(&freqs, &all_good, [0.1, 1.0]).unwrap();
        assert!(low_coherence(&bc.bins, 0.8).is_none());
    }
}
