//! Numbers in plain words: the formatting shared by every message of the
//! report.

/// `x` with three significant digits, trailing zeros removed: `0.31`,
/// `12.3`, `410`, `5`, `−0.0123`, `2.5e7`; `—` when not finite (the one
/// formatter of [`crate::numbers::sig3`]).
pub(crate) fn num(x: f64) -> String {
    crate::numbers::sig3(x)
}

/// A fraction as a whole percentage: `0.234` → `23 %`.
pub(crate) fn pct(x: f64) -> String {
    format!("{:.0} %", 100.0 * x)
}

/// A frequency band: `0.02–0.6 Hz`.
pub(crate) fn band(b: [f64; 2]) -> String {
    format!("{}–{} Hz", num(b[0]), num(b[1]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn three_significant_digits() {
        assert_eq!(num(0.0), "0");
        assert_eq!(num(0.31), "0.31");
        assert_eq!(num(12.345), "12.3");
        assert_eq!(num(409.6), "410");
        assert_eq!(num(5.0), "5");
        assert_eq!(num(-0.0123456), "−0.0123");
        assert_eq!(num(2.5e7), "2.5e7");
        assert_eq!(num(f64::INFINITY), "—");
        assert_eq!(pct(0.234), "23 %");
        assert_eq!(band([0.02, 0.6]), "0.02–0.6 Hz");
    }
}
