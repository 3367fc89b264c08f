//! One cell of a log: a trimmed decimal number, or the defect that makes it
//! unusable, in words that quote it.

use crate::logs::error::{LogError, LogErrorKind};
use crate::numbers::escape_controls;

/// Why a cell is not a usable number.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum BadCell {
    Empty,
    NotNumber,
    NonFinite,
}

impl BadCell {
    /// The defect in words, quoting the cell.
    pub(super) fn describe(self, cell: &[u8]) -> String {
        let shown = quote(cell);
        match self {
            BadCell::Empty => "the cell is empty; every row needs a value".to_string(),
            BadCell::NotNumber => format!("{shown} is not a number"),
            BadCell::NonFinite => {
                format!("{shown} is not a finite number (NaN and infinity are not allowed)")
            }
        }
    }
}

/// Parses a trimmed decimal number; NaN, infinities and overflow are
/// `NonFinite`.
#[inline]
pub(super) fn parse_cell(cell: &[u8]) -> Result<f64, BadCell> {
    let s = trim(cell);
    if s.is_empty() {
        return Err(BadCell::Empty);
    }
    let v: f64 = match fast_decimal(s) {
        Some(v) => v,
        None => std::str::from_utf8(s)
            .ok()
            .and_then(|s| s.parse().ok())
            .ok_or(BadCell::NotNumber)?,
    };
    if v.is_finite() {
        Ok(v)
    } else {
        Err(BadCell::NonFinite)
    }
}

/// Fast path for plain decimals `[+-]digits[.digits]` (no exponent) whose
/// digits form an integer `m ≤ 2^53` with at most 22 decimals: so `m / 10^k` divides two exactly representable numbers and the
/// one IEEE rounding gives the same `f64` as `str::parse` (Clinger's fast
/// path). Anything else returns `None` and goes to `str::parse`.
#[inline]
pub(super) fn fast_decimal(s: &[u8]) -> Option<f64> {
    const POW10: [f64; 23] = [
        1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
        1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
    ];
    let (negative, body) = match s.split_first() {
        Some((b'-', rest)) => (true, rest),
        Some((b'+', rest)) => (false, rest),
        _ => (false, s),
    };
    let mut m: u64 = 0;
    let mut digits = 0usize;
    let mut dot_at: Option<usize> = None;
    for &b in body {
        match b {
            b'0'..=b'9' => {
                digits += 1;
                if digits > 18 {
                    return None;
                }
                m = m * 10 + u64::from(b - b'0');
            }
            b'.' if dot_at.is_none() => dot_at = Some(digits),
            _ => return None,
        }
    }
    let k = digits - dot_at.unwrap_or(digits);
    if digits == 0 || m > (1u64 << 53) || k >= POW10.len() {
        return None;
    }
    let v = m as f64 / POW10[k];
    Some(if negative { -v } else { v })
}

/// The error of a bad cell in a required column.
pub(super) fn cell_error(
    file: &str,
    line: u64,
    column: &str,
    cell: &[u8],
    bad: BadCell,
) -> LogError {
    let kind = match bad {
        BadCell::Empty | BadCell::NotNumber => LogErrorKind::NotNumeric,
        BadCell::NonFinite => LogErrorKind::NonFinite,
    };
    LogError::new(file, kind, bad.describe(cell))
        .at_line(line)
        .in_column(column)
}

/// A cell in quotes for messages, shortened to 40 characters.
pub(super) fn quote(cell: &[u8]) -> String {
    let s = String::from_utf8_lossy(trim(cell));
    let mut out: String = escape_controls(&s.chars().take(40).collect::<String>());
    if s.chars().count() > 40 {
        out.push('…');
    }
    format!("'{out}'")
}

/// ASCII whitespace (including a `\r` left by `\r\n`) trimmed off both ends.
#[inline]
pub(super) fn trim(b: &[u8]) -> &[u8] {
    b.trim_ascii()
}
