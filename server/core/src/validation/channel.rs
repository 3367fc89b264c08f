//! The four predictions of one channel through the plausibility check of
//! [`super::divergence`]: each is cut at its divergence, and its fit
//! (eq. 1.13) is taken only over what stayed plausible — a whole-record free
//! run or a k-step prediction that diverged has no fit, restarted free runs
//! are fitted over the windows that did not diverge.

use super::divergence::{Channel, Divergence};
use super::error::ValidationError;
use super::metrics::nrmse_fit;
use super::predictor::restart_windows;
use super::report::RestartedWindows;

/// One channel's prediction after the check.
pub(crate) struct Checked {
    /// The prediction, NaN where none exists and from the divergence on.
    pub series: Vec<f64>,
    /// NRMSE fit, `None` when it diverged (or the measure is undefined).
    pub fit: Option<f64>,
    /// Where it left the plausible range.
    pub divergence: Option<Divergence>,
}

/// A k-step prediction ŷ(t|t−k): rows before its first finite value have no
/// prediction; from there on, every sample must be plausible. `field` names
/// the model method in the error when no prediction exists at all.
pub(crate) fn check_k_step(
    ch: &Channel<'_>,
    yhat: &[f64],
    k: usize,
    field: &str,
) -> Result<Checked, ValidationError> {
    let Some(start) = yhat.iter().position(|v| v.is_finite()) else {
        return Err(ValidationError::model_output(
            field,
            "returned no finite prediction",
        ));
    };
    let what = if k == 1 {
        "1-step prediction".to_owned()
    } else {
        format!("{k}-step prediction")
    };
    Ok(cut_at_divergence(ch, yhat, start, |t| {
        ch.divergence(&what, yhat[t], t, Some(t.saturating_sub(k)))
    }))
}

/// The whole-record free run, from row 0.
pub(crate) fn check_free_run(ch: &Channel<'_>, yhat: &[f64]) -> Checked {
    cut_at_divergence(ch, yhat, 0, |t| {
        ch.divergence("free-run simulation", yhat[t], t, None)
    })
}

/// `yhat` checked from row `start`: whole with its fit, or cut at its first
/// implausible row (the divergence `at` that row) without a fit.
fn cut_at_divergence(
    ch: &Channel<'_>,
    yhat: &[f64],
    start: usize,
    at: impl FnOnce(usize) -> Divergence,
) -> Checked {
    match ch.first_outside(yhat, start..yhat.len()) {
        None => Checked {
            series: yhat.to_vec(),
            fit: nrmse_fit(ch.y, yhat),
            divergence: None,
        },
        Some(t) => {
            let mut series = yhat.to_vec();
            series[t..].fill(f64::NAN);
            Checked {
                series,
                fit: None,
                divergence: Some(at(t)),
            }
        }
    }
}

/// Free runs restarted every `every` samples: a window that diverged is cut
/// from its divergence to its end and left out of the fit; the first such
/// window is the reported divergence.
pub(crate) fn check_restarted(
    ch: &Channel<'_>,
    yhat: &[f64],
    every: usize,
) -> (Checked, RestartedWindows) {
    let windows = restart_windows(yhat.len(), every);
    let mut series = yhat.to_vec();
    let mut kept = yhat.to_vec();
    let mut first = None;
    let mut diverged = 0;
    for &(s, e) in &windows {
        if let Some(t) = ch.first_outside(yhat, s..e) {
            diverged += 1;
            series[t..e].fill(f64::NAN);
            kept[s..e].fill(f64::NAN);
            if first.is_none() {
                first = Some(ch.divergence("restarted free run", yhat[t], t, Some(s)));
            }
        }
    }
    let checked = Checked {
        series,
        fit: nrmse_fit(ch.y, &kept),
        divergence: first,
    };
    let counts = RestartedWindows {
        windows: windows.len(),
        diverged,
    };
    (checked, counts)
}

/// Residual y − ŷ of a plausible prediction, from its first row to the end,
/// and that row; `None` when it diverged.
pub(crate) fn residual(y: &[f64], p: &Checked) -> Option<(usize, Vec<f64>)> {
    if p.divergence.is_some() {
        return None;
    }
    let start = p.series.iter().position(|v| v.is_finite())?;
    Some((
        start,
        y[start..]
            .iter()
            .zip(&p.series[start..])
            .map(|(a, b)| a - b)
            .collect(),
    ))
}

#[cfg(test)]
mod tests {
    use super::super::divergence::PlausibleBand;
    use super::*;

    fn channel(y: &[f64]) -> Channel<'_> {
        Channel {
            output: "w",
            y,
            h: 0.5,
            band: PlausibleBand::of(y),
        }
    }

    #[test]
    fn a_diverged_free_run_is_cut_and_has_no_fit() {
        // y alternates 0, 1: mean 0.5, range 1, band −99.5 … 100.5.
        let y: Vec<f64> = (0..20).map(|t| (t % 2) as f64).collect();
        let ch = channel(&y);
        let mut yhat = y.clone();
        yhat[12] = 100.6;
        let c = check_free_run(&ch, &yhat);
        assert_eq!(c.fit, None);
        let d = c.divergence.unwrap();
        assert_eq!((d.t_s, d.after_s), (6.0, 6.0));
        assert!(c.series[11].is_finite() && c.series[12..].iter().all(|v| v.is_nan()));
        yhat[12] = 100.4;
        let ok = check_free_run(&ch, &yhat);
        assert!(ok.divergence.is_none() && ok.fit.unwrap() < 0.0);
    }

    #[test]
    fn restarted_windows_that_diverge_are_counted_and_left_out_of_the_fit() {
        let y: Vec<f64> = (0..20).map(|t| (t % 2) as f64).collect();
        let ch = channel(&y);
        // Perfect except window [5, 10), which overflows at row 7.
        let mut yhat = y.clone();
        yhat[7] = f64::INFINITY;
        yhat[8] = 3.0;
        let (c, w) = check_restarted(&ch, &yhat, 5);
        assert_eq!((w.windows, w.diverged), (4, 1));
        assert_eq!(c.fit, Some(1.0), "the other windows are exact");
        let d = c.divergence.unwrap();
        assert_eq!((d.t_s, d.after_s), (3.5, 1.0));
        assert!(c.series[6] == 0.0 && c.series[7..10].iter().all(|v| v.is_nan()));
        assert_eq!(c.series[10], 0.0);
    }

    #[test]
    fn k_step_rows_without_prediction_are_not_divergence() {
        let y: Vec<f64> = (0..20).map(|t| (t % 2) as f64).collect();
        let ch = channel(&y);
        let mut yhat = y.clone();
        yhat[..3].fill(f64::NAN);
        let c = check_k_step(&ch, &yhat, 3, "predict_k_step(k)").unwrap();
        assert!(c.divergence.is_none() && c.fit == Some(1.0));
        assert_eq!(residual(&y, &c).unwrap().0, 3);
        yhat[15] = -1e40;
        let c = check_k_step(&ch, &yhat, 3, "predict_k_step(k)").unwrap();
        let d = c.divergence.as_ref().unwrap();
        assert_eq!((d.t_s, d.after_s), (7.5, 1.5));
        assert!(residual(&y, &c).is_none());
        let none = vec![f64::NAN; 20];
        let e = check_k_step(&ch, &none, 1, "predict_k_step(1)")
            .err()
            .unwrap();
        assert_eq!(e.field(), "predict_k_step(1)");
    }
}
