//! Welch configuration, its validation against the input signals, and the
//! default segment length.

use serde::{Deserialize, Serialize};

use super::{SpectraError, Window};

/// Trend removed from each segment before windowing (scipy's `detrend`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Detrend {
    /// No detrending (scipy `detrend=False`).
    None,
    /// Subtract the segment mean (scipy `'constant'`, its default).
    #[default]
    Constant,
    /// Subtract the least-squares straight line (scipy `'linear'`).
    Linear,
}

/// Parameters of a Welch estimate (one-sided, `scaling='density'`,
/// `average='mean'`, `nfft = nperseg`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WelchConfig {
    /// Sampling frequency in Hz; finite and `> 0`.
    pub fs: f64,
    /// Segment length in samples; `1 ..= signal length`.
    pub nperseg: usize,
    /// Samples shared by consecutive segments; `< nperseg`.
    pub noverlap: usize,
    /// Taper applied to each segment.
    pub window: Window,
    /// Trend removed from each segment before windowing.
    pub detrend: Detrend,
}

impl WelchConfig {
    /// scipy's defaults for a given segment length: periodic Hann window,
    /// 50 % overlap (`noverlap = nperseg / 2`, rounded down) and constant
    /// detrend.
    pub fn hann(fs: f64, nperseg: usize) -> Self {
        WelchConfig {
            fs,
            nperseg,
            noverlap: nperseg / 2,
            window: Window::Hann,
            detrend: Detrend::Constant,
        }
    }

    /// [`WelchConfig::hann`] with `nperseg = default_nperseg(n_samples)`, for
    /// callers that have no preferred segment length.
    pub fn for_length(fs: f64, n_samples: usize) -> Self {
        Self::hann(fs, default_nperseg(n_samples))
    }

    /// The same configuration with another overlap.
    pub fn with_noverlap(mut self, noverlap: usize) -> Self {
        self.noverlap = noverlap;
        self
    }

    /// The same configuration with another detrend.
    pub fn with_detrend(mut self, detrend: Detrend) -> Self {
        self.detrend = detrend;
        self
    }

    /// Hop between segment starts, `nperseg − noverlap` (0 if invalid).
    pub fn step(&self) -> usize {
        self.nperseg.saturating_sub(self.noverlap)
    }

    /// Number of one-sided frequency bins, `nperseg / 2 + 1`.
    pub fn n_freqs(&self) -> usize {
        self.nperseg / 2 + 1
    }

    /// Number of whole segments that fit in `n_samples` samples,
    /// `(n_samples − noverlap) / (nperseg − noverlap)`, as scipy; 0 when the
    /// configuration is invalid or the signal is shorter than one segment.
    pub fn n_segments(&self, n_samples: usize) -> usize {
        let step = self.step();
        if self.nperseg == 0 || step == 0 || n_samples < self.nperseg {
            return 0;
        }
        (n_samples - self.noverlap) / step
    }

    /// Frequency resolution `fs / nperseg` in Hz.
    pub fn df(&self) -> f64 {
        self.fs / self.nperseg as f64
    }

    /// The one-sided frequency grid in Hz, computed exactly as numpy's
    /// `rfftfreq(nperseg, 1/fs)`.
    pub fn frequencies(&self) -> Vec<f64> {
        if self.nperseg == 0 {
            return Vec::new();
        }
        let val = 1.0 / (self.nperseg as f64 * (1.0 / self.fs));
        (0..self.n_freqs()).map(|k| k as f64 * val).collect()
    }

    /// Checks the parameters against a signal of `n_samples` samples.
    ///
    /// Errors (in this order): `fs` not finite or `<= 0`; `nperseg == 0`;
    /// `noverlap >= nperseg`; `nperseg > n_samples` (scipy would warn and
    /// shrink `nperseg`; here it is an error naming `nperseg`).
    pub fn validate(&self, n_samples: usize) -> Result<(), SpectraError> {
        self.validate_parameters()?;
        self.validate_length(n_samples)
    }

    fn validate_parameters(&self) -> Result<(), SpectraError> {
        if !self.fs.is_finite() || self.fs <= 0.0 {
            return Err(SpectraError::parameter(
                "fs",
                format!("sampling frequency must be finite and > 0, got {}", self.fs),
            ));
        }
        if self.nperseg == 0 {
            return Err(SpectraError::parameter(
                "nperseg",
                "segment length must be at least 1",
            ));
        }
        if self.noverlap >= self.nperseg {
            return Err(SpectraError::parameter(
                "noverlap",
                format!(
                    "overlap {} must be less than nperseg = {}",
                    self.noverlap, self.nperseg
                ),
            ));
        }
        Ok(())
    }

    fn validate_length(&self, n_samples: usize) -> Result<(), SpectraError> {
        if self.nperseg > n_samples {
            return Err(SpectraError::parameter(
                "nperseg",
                format!(
                    "segment length {} exceeds the signal length {n_samples}",
                    self.nperseg
                ),
            ));
        }
        Ok(())
    }
}

/// Segment length used when the caller has none.
///
/// Rule: for `n < 64`, `n` itself (one segment, the whole record; `0` for an
/// empty signal, which the estimators then reject). Otherwise the largest
/// power of two `≤ n / 4`, clamped to `[64, 4096]`. The result is always
/// `≤ n`. With the 50 % overlap of [`WelchConfig::hann`] this gives at least
/// 7 averaged segments once `n ≥ 256` (variance reduction), at most 4096
/// samples per segment (cost, and resolution `fs/4096` is ample for vessel
/// dynamics), and never fewer than 64 samples (33 bins) when the record
/// allows.
pub fn default_nperseg(n: usize) -> usize {
    const MIN: usize = 64;
    const MAX: usize = 4096;
    if n < MIN {
        return n;
    }
    let quarter = n / 4;
    let pow2 = if quarter == 0 {
        1
    } else {
        1usize << (usize::BITS - 1 - quarter.leading_zeros())
    };
    pow2.clamp(MIN, MAX)
}

/// Validates a configuration and the signals it will be applied to:
/// parameters, `x` non-empty, `y` (if any) of the same length, `nperseg`
/// within the length, then finiteness of `x` and `y`.
pub(crate) fn validate_inputs(
    cfg: &WelchConfig,
    x: &[f64],
    y: Option<&[f64]>,
) -> Result<(), SpectraError> {
    cfg.validate_parameters()?;
    if x.is_empty() {
        return Err(SpectraError::input("x", "signal is empty"));
    }
    if let Some(y) = y
        && y.len() != x.len()
    {
        return Err(SpectraError::input(
            "y",
            format!(
                "length {} differs from the length {} of x",
                y.len(),
                x.len()
            ),
        ));
    }
    cfg.validate_length(x.len())?;
    require_finite("x", x)?;
    if let Some(y) = y {
        require_finite("y", y)?;
    }
    Ok(())
}

fn require_finite(field: &str, v: &[f64]) -> Result<(), SpectraError> {
    match v.iter().position(|s| !s.is_finite()) {
        None => Ok(()),
        Some(index) => Err(SpectraError::NonFinite {
            field: field.to_owned(),
            index,
            message: format!("{field}[{index}] = {} is not finite", v[index]),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hann_defaults_are_scipys() {
        let c = WelchConfig::hann(10.0, 256);
        assert_eq!(c.noverlap, 128);
        assert_eq!(c.window, Window::Hann);
        assert_eq!(c.detrend, Detrend::Constant);
        assert_eq!(WelchConfig::hann(1.0, 255).noverlap, 127);
        assert_eq!(c.step(), 128);
        assert_eq!(c.n_freqs(), 129);
        assert_eq!(WelchConfig::hann(1.0, 255).n_freqs(), 128);
        assert_eq!(c.df(), 10.0 / 256.0);
        let c2 = c.clone().with_noverlap(0).with_detrend(Detrend::Linear);
        assert_eq!(c2.noverlap, 0);
        assert_eq!(c2.detrend, Detrend::Linear);
    }

    #[test]
    fn segment_count_matches_scipy_formula() {
        // scipy: (n - noverlap) // (nperseg - noverlap)
        let c = WelchConfig::hann(1.0, 256);
        assert_eq!(c.n_segments(2999), (2999 - 128) / 128);
        assert_eq!(c.n_segments(256), 1);
        assert_eq!(c.n_segments(383), 1);
        assert_eq!(c.n_segments(384), 2);
        assert_eq!(c.n_segments(255), 0);
        assert_eq!(c.clone().with_noverlap(256).n_segments(1000), 0);
    }

    #[test]
    fn frequencies_are_rfftfreq() {
        let c = WelchConfig::hann(100.0, 8);
        assert_eq!(c.frequencies(), vec![0.0, 12.5, 25.0, 37.5, 50.0]);
        let c = WelchConfig::hann(3.0, 5);
        let f = c.frequencies();
        assert_eq!(f.len(), 3);
        assert!((f[2] - 1.2).abs() < 1e-15);
    }

    #[test]
    fn default_nperseg_rule() {
        assert_eq!(default_nperseg(0), 0);
        assert_eq!(default_nperseg(1), 1);
        assert_eq!(default_nperseg(63), 63);
        assert_eq!(default_nperseg(64), 64);
        assert_eq!(default_nperseg(255), 64);
        assert_eq!(default_nperseg(512), 128);
        assert_eq!(default_nperseg(1000), 128);
        assert_eq!(default_nperseg(1024), 256);
        assert_eq!(default_nperseg(100_000), 4096);
        assert_eq!(default_nperseg(usize::MAX), 4096);
        for n in 0..5000 {
            let p = default_nperseg(n);
            assert!(p <= n);
            if n >= 64 {
                assert!(p.is_power_of_two() && (64..=4096).contains(&p));
            }
        }
        assert_eq!(WelchConfig::for_length(2.0, 4096).nperseg, 1024);
    }

    #[test]
    fn parameter_errors_name_the_field() {
        let x = vec![0.0; 100];
        let field = |cfg: &WelchConfig| {
            validate_inputs(cfg, &x, None)
                .unwrap_err()
                .field()
                .to_owned()
        };
        assert_eq!(field(&WelchConfig::hann(0.0, 10)), "fs");
        assert_eq!(field(&WelchConfig::hann(-1.0, 10)), "fs");
        assert_eq!(field(&WelchConfig::hann(f64::NAN, 10)), "fs");
        assert_eq!(field(&WelchConfig::hann(f64::INFINITY, 10)), "fs");
        assert_eq!(field(&WelchConfig::hann(1.0, 0)), "nperseg");
        assert_eq!(field(&WelchConfig::hann(1.0, 101)), "nperseg");
        assert_eq!(
            field(&WelchConfig::hann(1.0, 10).with_noverlap(10)),
            "noverlap"
        );
        assert_eq!(
            field(&WelchConfig::hann(1.0, 10).with_noverlap(11)),
            "noverlap"
        );
        assert!(validate_inputs(&WelchConfig::hann(1.0, 100), &x, None).is_ok());
        assert!(WelchConfig::hann(1.0, 100).validate(100).is_ok());
        assert!(WelchConfig::hann(1.0, 100).validate(99).is_err());
    }

    #[test]
    fn input_errors_name_the_signal_and_index() {
        let cfg = WelchConfig::hann(1.0, 4);
        let e = validate_inputs(&cfg, &[], None).unwrap_err();
        assert!(matches!(e, SpectraError::InvalidInput { .. }));
        assert_eq!(e.field(), "x");

        let x = [1.0, 2.0, 3.0, 4.0, 5.0];
        let e = validate_inputs(&cfg, &x, Some(&[1.0; 4])).unwrap_err();
        assert_eq!(e.field(), "y");
        assert!(e.message().contains("differs"));

        let mut bad = x;
        bad[3] = f64::NAN;
        let e = validate_inputs(&cfg, &bad, None).unwrap_err();
        assert_eq!(
            e,
            SpectraError::NonFinite {
                field: "x".into(),
                index: 3,
                message: "x[3] = NaN is not finite".into()
            }
        );
        let mut bad_y = x;
        bad_y[1] = f64::NEG_INFINITY;
        bad_y[4] = f64::NAN;
        match validate_inputs(&cfg, &x, Some(&bad_y)).unwrap_err() {
            SpectraError::NonFinite { field, index, .. } => {
                assert_eq!(field, "y");
                assert_eq!(index, 1);
            }
            other => panic!("unexpected {other:?}"),
        }
    }

    #[test]
    fn detrend_serde_names() {
        assert_eq!(serde_json::to_string(&Detrend::None).unwrap(), "\"none\"");
        assert_eq!(
            serde_json::to_string(&Detrend::Linear).unwrap(),
            "\"linear\""
        );
        let c: WelchConfig = serde_json::from_str(
            r#"{"fs":2.0,"nperseg":8,"noverlap":4,"window":"hann","detrend":"constant"}"#,
        )
        .unwrap();
        assert_eq!(c, WelchConfig::hann(2.0, 8));
    }
}
