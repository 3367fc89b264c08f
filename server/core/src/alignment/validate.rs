//! Input checks shared by [`super::estimate_offset`] and
//! [`super::align_logs`]: lengths, finiteness, increasing time, a varying
//! shared channel, and options in their domain.

use super::AlignError;
use super::offset::OffsetOptions;

/// Fewest samples a log must hold.
pub(crate) const MIN_SAMPLES: usize = 16;

/// How a series is named in error messages: the fields of its time and value
/// vectors, the log in words, and the shared channel's name when known.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SeriesLabels<'a> {
    /// Field of the time vector (`control_t`, `control.t`, ...).
    pub t: &'a str,
    /// Field of the value vector (`control_x`, `shared`, ...).
    pub x: &'a str,
    /// The log in words (`control log`, `navigation log`).
    pub log: &'a str,
    /// Name of the shared channel, when known (`z`).
    pub channel: Option<&'a str>,
}

impl SeriesLabels<'_> {
    fn channel_words(&self) -> String {
        match self.channel {
            Some(name) => format!("the shared channel {name}"),
            None => "the shared channel".to_owned(),
        }
    }
}

/// Checks that `x` is finite, its first non-finite index otherwise.
pub(crate) fn check_finite(field: &str, x: &[f64]) -> Result<(), AlignError> {
    match x.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(index) => Err(AlignError::NonFinite {
            field: field.to_owned(),
            index,
            message: format!(
                "{field}[{index}] = {}: every sample must be a finite number",
                x[index]
            ),
        }),
    }
}

/// Checks that time stamps are finite and strictly increasing.
pub(crate) fn check_time(field: &str, log: &str, t: &[f64]) -> Result<(), AlignError> {
    check_finite(field, t)?;
    if let Some(k) = t.windows(2).position(|w| w[1] <= w[0]) {
        return Err(AlignError::invalid(
            field,
            format!(
                "the {log} time stamps must strictly increase, but t[{}] = {} follows t[{k}] = {}",
                k + 1,
                t[k + 1],
                t[k]
            ),
        ));
    }
    Ok(())
}

/// Checks a (time, shared channel) series: equal lengths, at least
/// [`MIN_SAMPLES`] samples, finite values, increasing time, and a channel
/// that varies.
pub(crate) fn check_series(t: &[f64], x: &[f64], labels: SeriesLabels) -> Result<(), AlignError> {
    if t.len() != x.len() {
        return Err(AlignError::invalid(
            labels.x,
            format!(
                "{} has {} samples but {} has {}; they must have one value per time stamp",
                labels.x,
                x.len(),
                labels.t,
                t.len()
            ),
        ));
    }
    if t.len() < MIN_SAMPLES {
        return Err(AlignError::too_short(
            labels.t,
            format!(
                "the {} has only {} samples; alignment needs at least {MIN_SAMPLES}",
                labels.log,
                t.len()
            ),
        ));
    }
    check_time(labels.t, labels.log, t)?;
    check_finite(labels.x, x)?;
    let n = x.len() as f64;
    let mean = x.iter().sum::<f64>() / n;
    let std = (x.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / n).sqrt();
    if std <= 1e-9 * (1.0 + mean.abs()) {
        return Err(AlignError::flat(
            labels.x,
            format!(
                "{} does not change in the {}; alignment needs a signal both computers saw vary, e.g. a depth change",
                labels.channel_words(),
                labels.log
            ),
        ));
    }
    Ok(())
}

/// Checks that an optional value is finite and strictly positive.
pub(crate) fn check_positive(field: &str, value: Option<f64>) -> Result<(), AlignError> {
    match value {
        Some(v) if !(v.is_finite() && v > 0.0) => Err(AlignError::invalid(
            field,
            format!("must be a finite number greater than zero (got {v})"),
        )),
        _ => Ok(()),
    }
}

/// Checks the options of [`super::estimate_offset`].
pub(crate) fn check_options(opts: &OffsetOptions) -> Result<(), AlignError> {
    check_positive("max_offset_s", opts.max_offset_s)?;
    check_positive("rate_hz", opts.rate_hz)
}

#[cfg(test)]
mod tests {
    use super::*;

    const LABELS: SeriesLabels = SeriesLabels {
        t: "control_t",
        x: "control_x",
        log: "control log",
        channel: Some("z"),
    };

    fn ramp(n: usize) -> (Vec<f64>, Vec<f64>) {
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 0.1).collect();
        let x = t.iter().map(|v| v.sin()).collect();
        (t, x)
    }

    #[test]
    fn accepts_a_good_series() {
        let (t, x) = ramp(20);
        assert_eq!(check_series(&t, &x, LABELS), Ok(()));
    }

    #[test]
    fn rejects_each_defect_naming_the_field() {
        let (t, x) = ramp(20);
        let e = check_series(&t, &x[..19], LABELS).unwrap_err();
        assert!(matches!(e, AlignError::InvalidInput { .. }));
        assert_eq!(e.field(), "control_x");

        let (t15, x15) = ramp(15);
        let e = check_series(&t15, &x15, LABELS).unwrap_err();
        assert!(matches!(e, AlignError::TooShort { .. }));
        assert!(e.message().contains("at least 16"), "{e}");

        let mut tb = t.clone();
        tb[7] = tb[6];
        let e = check_series(&tb, &x, LABELS).unwrap_err();
        assert_eq!(e.field(), "control_t");
        assert!(e.message().contains("strictly increase"), "{e}");

        let mut xb = x.clone();
        xb[3] = f64::NAN;
        let e = check_series(&t, &xb, LABELS).unwrap_err();
        assert!(matches!(e, AlignError::NonFinite { index: 3, .. }), "{e:?}");

        let flat = vec![4.2; 20];
        let e = check_series(&t, &flat, LABELS).unwrap_err();
        assert!(matches!(e, AlignError::FlatSignal { .. }));
        assert_eq!(
            e.message(),
            "the shared channel z does not change in the control log; alignment needs a signal both computers saw vary, e.g. a depth change"
        );
    }

    #[test]
    fn options_must_be_positive() {
        let bad = OffsetOptions {
            max_offset_s: Some(-1.0),
            rate_hz: None,
        };
        assert_eq!(check_options(&bad).unwrap_err().field(), "max_offset_s");
        let bad = OffsetOptions {
            max_offset_s: None,
            rate_hz: Some(f64::NAN),
        };
        assert_eq!(check_options(&bad).unwrap_err().field(), "rate_hz");
        assert_eq!(check_options(&OffsetOptions::default()), Ok(()));
    }
}
