//! Numbers in plain words: the formatting shared by every message of the
//! report.

/// `x` with three significant digits, trailing zeros removed: `0.31`,
/// `12.3`, `410`, `5`; scientific notation outside `1e-4 ..= 1e6`.
pub(crate) fn num(x: f64) -> String {
    if x == 0.0 {
        return "0".into();
    }
    if !x.is_finite() {
        return format!("{x}");
    }
    let mag = x.abs().log10().floor();
    if !(-4.0..6.0).contains(&mag) {
        return format!("{x:.2e}");
    }
    let decimals = (2.0 - mag).max(0.0) as usize;
    let s = format!("{x:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_owned()
    } else {
        s
    }
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
        assert_eq!(num(-0.0123456), "-0.0123");
        assert_eq!(num(2.5e7), "2.50e7");
        assert_eq!(num(f64::INFINITY), "inf");
        assert_eq!(pct(0.234), "23 %");
        assert_eq!(band([0.02, 0.6]), "0.02–0.6 Hz");
    }
}
