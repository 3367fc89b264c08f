//! Excitation signals for sea-trial identification, and the checks that they
//! excite enough.
//!
//! An identification experiment is only as good as its input: the input must
//! be *persistently exciting* of an order at least as high as the number of
//! parameters to be estimated (Ljung, *System Identification*, §13.2), must
//! put its power in the frequency band where the model has to be accurate, and
//! must respect what the thrusters can physically do (amplitude and slew-rate
//! limits). This module provides:
//!
//! - [`prbs`](mod@prbs): maximum-length pseudo-random binary sequences (m-sequences)
//!   from a linear-feedback shift register, with a flat periodic spectrum and
//!   an ideal two-valued autocorrelation;
//! - [`square`](mod@square): square waves for step-response experiments, with the
//!   5·T hold rule;
//! - [`multisine`](mod@multisine): Schroeder-phased multisines (low crest factor)
//!   and i.i.d. random binary signals;
//! - [`shaping`]: slew-rate limiting and clipping to actuator limits;
//! - [`persistence`]: the numerical order of persistence of excitation.
//!
//! Every function is pure and deterministic (seeded), and reports invalid
//! input as a [`SignalError`] rather than panicking.

pub mod multisine;
pub mod persistence;
pub mod prbs;
pub mod shaping;
pub mod square;

pub use multisine::{crest_factor, multisine, random_binary};
pub use persistence::{DEFAULT_PE_TOL, pe_order};
pub use prbs::{PrbsSpec, mls, prbs};
pub use shaping::{clip, min_slew_time, rate_limit};
pub use square::{SquareSpec, square, square_period_for_time_constant};

use std::fmt;

/// Why a signal could not be generated or analysed.
///
/// Every variant names the offending input (`field`, spelled as the Rust
/// parameter or struct field so an API layer can point at it) and carries a
/// human-readable `message` explaining what was wrong.
#[derive(Debug, Clone, PartialEq)]
pub enum SignalError {
    /// A parameter is out of its valid range or not finite.
    InvalidParameter {
        /// Name of the offending parameter or struct field.
        field: String,
        /// What was wrong with it.
        message: String,
    },
    /// The data are too short (or otherwise insufficient) for the analysis.
    InsufficientData {
        /// Name of the offending input.
        field: String,
        /// What was wrong with it.
        message: String,
    },
    /// The requested output is too large to allocate.
    TooLarge {
        /// Name of the parameter that made the output too large.
        field: String,
        /// What was wrong with it.
        message: String,
    },
}

impl SignalError {
    /// The name of the offending parameter or field.
    pub fn field(&self) -> &str {
        match self {
            SignalError::InvalidParameter { field, .. }
            | SignalError::InsufficientData { field, .. }
            | SignalError::TooLarge { field, .. } => field,
        }
    }

    /// The human-readable explanation.
    pub fn message(&self) -> &str {
        match self {
            SignalError::InvalidParameter { message, .. }
            | SignalError::InsufficientData { message, .. }
            | SignalError::TooLarge { message, .. } => message,
        }
    }

    pub(crate) fn invalid(field: &str, message: impl Into<String>) -> Self {
        SignalError::InvalidParameter {
            field: field.to_owned(),
            message: message.into(),
        }
    }

    pub(crate) fn insufficient(field: &str, message: impl Into<String>) -> Self {
        SignalError::InsufficientData {
            field: field.to_owned(),
            message: message.into(),
        }
    }

    pub(crate) fn too_large(field: &str, message: impl Into<String>) -> Self {
        SignalError::TooLarge {
            field: field.to_owned(),
            message: message.into(),
        }
    }
}

impl fmt::Display for SignalError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SignalError::InvalidParameter { field, message } => {
                write!(f, "invalid parameter `{field}`: {message}")
            }
            SignalError::InsufficientData { field, message } => {
                write!(f, "insufficient data in `{field}`: {message}")
            }
            SignalError::TooLarge { field, message } => {
                write!(f, "output too large because of `{field}`: {message}")
            }
        }
    }
}

impl std::error::Error for SignalError {}

// ---------------------------------------------------------------------------
// Shared validation and sampling helpers (crate-private).
// ---------------------------------------------------------------------------

/// Slack added before flooring a sample-time ratio, so that a boundary that
/// falls exactly on a sample instant (e.g. `k·h/Tc = 3` computed as
/// `2.9999999999999996`) is assigned to the later interval, as exact
/// arithmetic would.
pub(crate) const GRID_EPS: f64 = 1e-9;

/// Require `value` to be finite.
pub(crate) fn require_finite(field: &str, value: f64) -> Result<(), SignalError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(SignalError::invalid(
            field,
            format!("must be a finite number, got {value}"),
        ))
    }
}

/// Require `value` to be finite and strictly positive.
pub(crate) fn require_positive(field: &str, value: f64) -> Result<(), SignalError> {
    require_finite(field, value)?;
    if value > 0.0 {
        Ok(())
    } else {
        Err(SignalError::invalid(
            field,
            format!("must be strictly positive, got {value}"),
        ))
    }
}

/// Require `value` to be finite and non-negative.
pub(crate) fn require_non_negative(field: &str, value: f64) -> Result<(), SignalError> {
    require_finite(field, value)?;
    if value >= 0.0 {
        Ok(())
    } else {
        Err(SignalError::invalid(
            field,
            format!("must not be negative, got {value}"),
        ))
    }
}

/// Validate a sample rate and a duration and return the number of samples,
/// `round(duration·fs)`, which is at least 1.
pub(crate) fn sample_count(sample_rate_hz: f64, duration_s: f64) -> Result<usize, SignalError> {
    require_positive("sample_rate_hz", sample_rate_hz)?;
    require_positive("duration_s", duration_s)?;
    let n = (duration_s * sample_rate_hz).round();
    if !n.is_finite() || n > (isize::MAX as f64) / 8.0 {
        return Err(SignalError::too_large(
            "duration_s",
            format!(
                "{duration_s} s at {sample_rate_hz} Hz is {n} samples, more than can be allocated"
            ),
        ));
    }
    if n < 1.0 {
        return Err(SignalError::invalid(
            "duration_s",
            format!(
                "{duration_s} s at {sample_rate_hz} Hz is shorter than one sample period ({} s)",
                1.0 / sample_rate_hz
            ),
        ));
    }
    // `n` is a finite, positive integer below isize::MAX / 8: the cast is exact.
    Ok(n as usize)
}

/// Allocate an empty vector with room for `n` elements, reporting allocation
/// failure as an error instead of aborting the process.
pub(crate) fn try_vec<T>(field: &str, n: usize) -> Result<Vec<T>, SignalError> {
    let mut v = Vec::new();
    v.try_reserve_exact(n).map_err(|_| {
        SignalError::too_large(
            field,
            format!("cannot allocate {n} samples; shorten the run or lower the rate"),
        )
    })?;
    Ok(v)
}

/// Validate a chip (clock) period against the sample grid and the run length.
///
/// A chip must last at least one sample, or chips are skipped and the
/// sequence's spectrum is destroyed; and it must not last longer than the
/// run, or the run would see a single constant level.
pub(crate) fn check_clock_period(
    clock_period_s: f64,
    sample_rate_hz: f64,
    duration_s: f64,
) -> Result<(), SignalError> {
    require_positive("clock_period_s", clock_period_s)?;
    let samples_per_chip = clock_period_s * sample_rate_hz;
    if samples_per_chip < 1.0 - GRID_EPS {
        return Err(SignalError::invalid(
            "clock_period_s",
            format!(
                "clock period {clock_period_s} s is shorter than one sample ({} s at {sample_rate_hz} Hz)",
                1.0 / sample_rate_hz
            ),
        ));
    }
    if clock_period_s > duration_s {
        return Err(SignalError::invalid(
            "clock_period_s",
            format!(
                "clock slower than the run: clock period {clock_period_s} s exceeds the duration {duration_s} s"
            ),
        ));
    }
    Ok(())
}

/// Index of the chip (interval of length `clock_period_s`) containing sample
/// `k`, i.e. `floor(k·h/Tc + ε)` with `h = 1/fs`. Written as `k/(Tc·fs)` so
/// that one sample per chip gives exactly `k`.
pub(crate) fn chip_index(k: usize, samples_per_chip: f64) -> u64 {
    // Non-negative and finite because samples_per_chip >= 1 - eps; the
    // saturating float-to-int cast can never wrap.
    (k as f64 / samples_per_chip + GRID_EPS).floor() as u64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn error_display_names_field_and_message() {
        let e = SignalError::invalid("order", "must be in 2..=32, got 40");
        assert_eq!(e.field(), "order");
        assert_eq!(e.message(), "must be in 2..=32, got 40");
        let s = e.to_string();
        assert!(s.contains("`order`") && s.contains("2..=32"), "{s}");
        let boxed: Box<dyn std::error::Error> = Box::new(e.clone());
        assert_eq!(boxed.to_string(), s);
    }

    #[test]
    fn sample_count_rounds_and_rejects_bad_input() {
        assert_eq!(sample_count(10.0, 1.04), Ok(10));
        assert_eq!(sample_count(10.0, 1.06), Ok(11));
        assert_eq!(
            sample_count(0.0, 1.0).unwrap_err().field(),
            "sample_rate_hz"
        );
        assert_eq!(
            sample_count(f64::NAN, 1.0).unwrap_err().field(),
            "sample_rate_hz"
        );
        assert_eq!(sample_count(10.0, -1.0).unwrap_err().field(), "duration_s");
        assert_eq!(sample_count(10.0, 0.01).unwrap_err().field(), "duration_s");
        assert!(matches!(
            sample_count(1e300, 1e300),
            Err(SignalError::TooLarge { .. })
        ));
    }
}
