//! Merging a control log and a navigation log into one uniform record.
//!
//! [`align_logs`] estimates the clock offset from the shared channel
//! ([`super::estimate_offset`]), shifts the navigation time onto the control
//! clock, and resamples both logs onto one grid covering only the overlap.
//!
//! Grid rate: by default the **lower** of the two median rates, so no sample
//! is invented for the slower log; the caller may ask for another rate.
//! Resampling rules (see `resample.rs`): control inputs are commands, held
//! piecewise constant — zero-order hold at or above the control rate, cell
//! averages of the held signal below it; navigation channels and the control
//! log's copy of the shared channel are measurements, interpolated linearly.

use std::collections::HashSet;

use serde::Serialize;

use super::AlignError;
use super::decide::{OffsetPriors, OffsetSource, PooledValue, choose_offset};
use super::drift::check_drift;
use super::grid::grid_len;
use super::offset::{Labels, OffsetEstimate, OffsetOptions, estimate_labeled};
use super::resample::{GAP_FACTOR, cell_average, gaps, valid_blocks, zero_order_hold};
use super::validate::{SeriesLabels, check_finite, check_positive, check_time};
use super::warnings::{
    Context, fmt_num, offset_warnings, overlap_warnings, rate_warnings, source_words,
};
use crate::timeseries::{LogTable, UniformRecord, interp_linear, median_dt};

/// Largest merged record, in values over all channels (256 MB of f64).
const MAX_MERGED_VALUES: usize = 1 << 25;

/// How two logs were aligned and merged, for the analyst.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub struct AlignmentReport {
    /// The run's own estimate of the clock offset (added to navigation
    /// stamps) from the shared channel, and its quality; `null` when the
    /// channel did not vary and another offset was available.
    pub offset: Option<OffsetEstimate>,
    /// The offset the logs were merged with (s): see `offset_source`.
    pub offset_used_s: f64,
    /// Its standard deviation (s); `null` for an offset set by hand.
    pub offset_used_std_s: Option<f64>,
    /// Where `offset_used_s` came from: set by hand for the run or the
    /// campaign, the run's own informative estimate, the campaign's pooled
    /// offset, or the run's own estimate although it is weak.
    pub offset_source: OffsetSource,
    /// The campaign's pooled offset known when the run was merged, if any.
    pub pooled: Option<PooledValue>,
    /// The channel both logs recorded, used to align them.
    pub shared_channel: String,
    /// Rate of the merged record (Hz).
    pub rate_hz: f64,
    /// Median sample rate of the control log (Hz).
    pub control_rate_hz: f64,
    /// Median sample rate of the navigation log (Hz).
    pub nav_rate_hz: f64,
    /// Start of the overlap on the control clock (s): time of merged sample 0.
    pub overlap_start_s: f64,
    /// End of the overlap on the control clock (s).
    pub overlap_end_s: f64,
    /// Plain-language cautions (slow inputs, uncertain offset, mismatch,
    /// clock drift, gaps, renamed columns, dropped data).
    pub warnings: Vec<String>,
}

/// Aligns a navigation log to a control log using a channel both recorded
/// (`shared`, e.g. `"z"`) and merges them into one uniform record.
///
/// The merged record is on the control clock, starts at the beginning of
/// the overlap (`t0 = overlap_start_s`) and holds only the overlap, sampled
/// at `rate_hz` (default: the lower of the two median rates — nothing is
/// invented; a higher rate interpolates). Its channels are every column of
/// the control log, then every column of the navigation log, without `t`:
/// the shared channel appears twice, as `<shared>` (navigation's) and
/// `<shared>_control`; any other name both logs use is kept for the
/// navigation column and suffixed `_control` for the control one (with a
/// warning). Control columns other than the shared one are commands:
/// zero-order hold at or above the control rate (piecewise-constant
/// commands are sampled exactly, no ramp, nothing before it was issued),
/// averages of the held command over each grid cell below it (keeps the
/// impulse and does not alias fast steps). Navigation columns and
/// `<shared>_control` are interpolated linearly (point samples, also when
/// the grid is slower than the log). Merged samples inside a
/// gap of either log (an interval over 4 median intervals) are left out of
/// `valid`.
///
/// # Errors
/// [`AlignError`] naming `shared` when a log lacks the column ("the control
/// log has no column 'z'") or the channel is flat, `control.<column>` /
/// `nav.<column>` for malformed columns (wrong length, NaN), `control.t` /
/// `nav.t` for time stamps that do not increase, `rate_hz` or
/// `opts.<field>` for bad options, and every error of
/// [`super::estimate_offset`].
pub fn align_logs(
    control: &LogTable,
    nav: &LogTable,
    shared: &str,
    rate_hz: Option<f64>,
    opts: &OffsetOptions,
) -> Result<(UniformRecord, AlignmentReport), AlignError> {
    align_logs_with(
        control,
        nav,
        shared,
        rate_hz,
        opts,
        &OffsetPriors::default(),
    )
}

/// [`align_logs`] with offsets known apart from the run's own estimate: set
/// by hand for the run or the campaign, or the campaign's pooled offset.
/// The own estimate is always made and reported; the logs are merged with
/// the offset chosen by [`super::choose_offset`] (precedence: by hand for
/// the run, by hand for the campaign, own if informative, pooled, own
/// although weak). A shared channel that does not vary is no error when a
/// prior offset exists: the run is merged with it.
///
/// # Errors
/// Those of [`align_logs`]; `priors.user_run_s`, `priors.user_campaign_s`
/// or `priors.pooled` for a prior that is not finite, beyond a day (by
/// hand) or leaves the logs without overlap.
pub fn align_logs_with(
    control: &LogTable,
    nav: &LogTable,
    shared: &str,
    rate_hz: Option<f64>,
    opts: &OffsetOptions,
    priors: &OffsetPriors,
) -> Result<(UniformRecord, AlignmentReport), AlignError> {
    check_positive("rate_hz", rate_hz)?;
    check_table(control, "control", "control log")?;
    check_table(nav, "nav", "navigation log")?;
    let missing =
        |log: &str| AlignError::invalid("shared", format!("the {log} has no column '{shared}'"));
    let control_x = control
        .column(shared)
        .ok_or_else(|| missing("control log"))?;
    let nav_x = nav
        .column(shared)
        .ok_or_else(|| missing("navigation log"))?;
    let labels = Labels {
        control: SeriesLabels {
            t: "control.t",
            x: "shared",
            log: "control log",
            channel: Some(shared),
        },
        nav: SeriesLabels {
            t: "nav.t",
            x: "shared",
            log: "navigation log",
            channel: Some(shared),
        },
        max_offset: "opts.max_offset_s",
        rate: "opts.rate_hz",
    };
    let has_prior =
        priors.user_run_s.is_some() || priors.user_campaign_s.is_some() || priors.pooled.is_some();
    let mut no_estimate = None;
    let (own, pairing) = match estimate_labeled(&control.t, control_x, &nav.t, nav_x, opts, &labels)
    {
        Ok((e, p)) => (Some(e), Some(p)),
        Err(e @ AlignError::FlatSignal { .. }) if has_prior => {
            no_estimate = Some(e.message().to_owned());
            (None, None)
        }
        Err(e) => return Err(e),
    };
    let chosen = choose_offset(own.as_ref(), priors)?.ok_or_else(|| {
        AlignError::flat("shared", "no offset: the shared channel gave no estimate")
    })?;
    let d = chosen.offset_s;
    let source_field = match chosen.source {
        OffsetSource::UserRun => "priors.user_run_s",
        OffsetSource::UserCampaign => "priors.user_campaign_s",
        OffsetSource::Pooled => "priors.pooled",
        OffsetSource::Own | OffsetSource::WeakOwn => "shared",
    };

    // Validated above: at least 16 strictly increasing stamps each.
    let dt_c = median_dt(&control.t).unwrap_or(1.0);
    let dt_n = median_dt(&nav.t).unwrap_or(1.0);
    let (control_rate_hz, nav_rate_hz) = (1.0 / dt_c, 1.0 / dt_n);
    let fs = rate_hz.unwrap_or(control_rate_hz.min(nav_rate_hz));
    let h = 1.0 / fs;
    let (tc0, tc1) = (control.t[0], control.t[control.t.len() - 1]);
    let (tn0, tn1) = (nav.t[0] + d, nav.t[nav.t.len() - 1] + d);
    let (start, end) = (tc0.max(tn0), tc1.min(tn1));
    if end <= start {
        return Err(AlignError::overlap(
            source_field,
            format!(
                "with the {} offset {d:.3} s the logs do not overlap (control {tc0:.3}–{tc1:.3} s, navigation {:.3}–{:.3} s + offset)",
                source_words(chosen.source),
                nav.t[0],
                nav.t[nav.t.len() - 1]
            ),
        ));
    }
    let n = grid_len(start, end, h);
    let n_channels = control.names.len() + nav.names.len();
    if n < 2 || n.saturating_mul(n_channels) > MAX_MERGED_VALUES {
        return Err(AlignError::invalid(
            "rate_hz",
            format!(
                "{} Hz over the {:.1} s overlap gives {n} samples per channel; choose a rate giving at least 2 samples and at most {} values in all",
                fmt_num(fs),
                end - start,
                MAX_MERGED_VALUES
            ),
        ));
    }
    let at: Vec<f64> = (0..n).map(|k| start + k as f64 * h).collect();
    let at_nav: Vec<f64> = at.iter().map(|s| s - d).collect();

    let mut warnings = Vec::new();
    let nav_names: HashSet<&str> = nav.names.iter().map(String::as_str).collect();
    let hold = fs >= control_rate_hz * (1.0 - 1e-3);
    let mut names = Vec::with_capacity(n_channels);
    let mut data = Vec::with_capacity(n_channels);
    for (name, col) in control.names.iter().zip(&control.data) {
        if name == shared {
            names.push(format!("{name}_control"));
            data.push(interp_linear(&control.t, col, &at));
            continue;
        }
        if nav_names.contains(name.as_str()) {
            names.push(format!("{name}_control"));
            warnings.push(format!(
                "both logs have a column '{name}'; the control log's copy is named '{name}_control'"
            ));
        } else {
            names.push(name.clone());
        }
        data.push(if hold {
            zero_order_hold(&control.t, col, &at)
        } else {
            cell_average(&control.t, col, &at, h)
        });
    }
    for (name, col) in nav.names.iter().zip(&nav.data) {
        names.push(name.clone());
        data.push(interp_linear(&nav.t, col, &at_nav));
    }
    let mut seen = HashSet::new();
    if let Some(dup) = names.iter().find(|n| !seen.insert(n.as_str())) {
        return Err(AlignError::invalid(
            format!("control.{dup}").as_str(),
            format!("the merged record would have two columns named '{dup}'; rename one of them"),
        ));
    }

    let mut all_gaps = gaps(&control.t);
    let control_gaps = all_gaps.len();
    let nav_gaps: Vec<(f64, f64)> = gaps(&nav.t).iter().map(|&(a, b)| (a + d, b + d)).collect();
    all_gaps.extend(&nav_gaps);
    let valid = valid_blocks(start, h, n, &all_gaps);

    let ctx = Context {
        shared,
        own: own.as_ref(),
        chosen,
        pooled: priors.pooled,
        fs,
        control_rate_hz,
        nav_rate_hz,
        hold,
        overlap: end - start,
        control_span: tc1 - tc0,
        nav_span: tn1 - tn0,
    };
    warnings.splice(0..0, rate_warnings(&ctx));
    if let Some(why) = no_estimate {
        warnings.push(format!("no own estimate of the clock offset: {why}"));
    }
    warnings.extend(offset_warnings(&ctx));
    warnings.extend(overlap_warnings(&ctx));
    for (log, list) in [
        ("control log", &all_gaps[..control_gaps]),
        ("navigation log", &nav_gaps[..]),
    ] {
        if let Some(longest) = list.iter().map(|g| g.1 - g.0).max_by(f64::total_cmp) {
            warnings.push(format!(
                "the {log} has {} gap(s) longer than {GAP_FACTOR} sample intervals (longest {:.2} s); the merged samples inside them are marked invalid",
                list.len(),
                longest
            ));
        }
    }
    // Drift is measured about an offset the run itself determines well.
    if chosen.source == OffsetSource::Own
        && let Some(pairing) = &pairing
        && let Some(drift) = check_drift(pairing, d, dt_c.max(dt_n))
        && drift.significant
    {
        warnings.push(format!(
            "the clocks appear to drift: the offset is {:.3} s in the first third of the overlap and {:.3} s in the last ({:+.0} ppm); one offset cannot align the whole run, consider splitting it",
            drift.early_offset_s, drift.late_offset_s, drift.ppm
        ));
    }

    let record = UniformRecord {
        sample_rate_hz: fs,
        t0: start,
        names,
        data,
        valid,
    };
    let report = AlignmentReport {
        offset: own,
        offset_used_s: d,
        offset_used_std_s: chosen.std_s,
        offset_source: chosen.source,
        pooled: priors.pooled,
        shared_channel: shared.to_owned(),
        rate_hz: fs,
        control_rate_hz,
        nav_rate_hz,
        overlap_start_s: start,
        overlap_end_s: end,
        warnings,
    };
    Ok((record, report))
}

/// Checks a table's shape, time and values; fields are `<prefix>.<column>`.
fn check_table(table: &LogTable, prefix: &str, log: &str) -> Result<(), AlignError> {
    if table.names.len() != table.data.len() {
        return Err(AlignError::invalid(
            &format!("{prefix}.names"),
            format!(
                "the {log} has {} column names but {} columns",
                table.names.len(),
                table.data.len()
            ),
        ));
    }
    check_time(&format!("{prefix}.t"), log, &table.t)?;
    let mut seen = HashSet::new();
    for (name, col) in table.names.iter().zip(&table.data) {
        let field = format!("{prefix}.{name}");
        if !seen.insert(name.as_str()) {
            return Err(AlignError::invalid(
                &field,
                format!("the {log} has two columns named '{name}'"),
            ));
        }
        if col.len() != table.t.len() {
            return Err(AlignError::invalid(
                &field,
                format!(
                    "column '{name}' of the {log} has {} values for {} time stamps",
                    col.len(),
                    table.t.len()
                ),
            ));
        }
        check_finite(&field, col)?;
    }
    Ok(())
}
