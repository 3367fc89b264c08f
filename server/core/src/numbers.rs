//! Numbers in sentences: what a finding, verdict or note shows a person.
//!
//! One rule everywhere: three significant digits, trailing zeros dropped, the
//! unit after a space (`0.0123 m/s`, `9860 N·m`), a true minus sign (−). Magnitudes outside 10⁻⁴ … 10⁶ switch to `2.5e7`. A non-finite
//! value prints as `—`: it means a guard upstream is missing, never a number
//! to read. Fits (eq. 1.13) are percentages with one decimal (below −1000 %
//! only `< −1000 %`), times of a record seconds with one decimal, p-values
//! stop at `p < 0.001`.

const MINUS: char = '\u{2212}';

/// `x` with three significant digits: `0.0123`, `12.3`, `410`, `5`,
/// `−2.5e7`; `—` when not finite.
pub fn sig3(x: f64) -> String {
    if !x.is_finite() {
        return "—".into();
    }
    if x == 0.0 {
        return "0".into();
    }
    let mag = x.abs().log10().floor();
    let s = if !(-4.0..6.0).contains(&mag) {
        let e = format!("{x:.2e}");
        // 2.50e7 → 2.5e7, 1.00e-5 → 1e-5.
        match e.split_once('e') {
            Some((m, exp)) => {
                let m = m.trim_end_matches('0').trim_end_matches('.');
                format!("{m}e{exp}")
            }
            None => e,
        }
    } else {
        let decimals = (2.0 - mag).max(0.0) as usize;
        let s = format!("{x:.decimals$}");
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_owned()
        } else {
            s
        }
    };
    minus(&s)
}

/// `x` with its unit: `0.0123 m/s`; the bare number when `unit` is empty.
pub fn quantity(x: f64, unit: &str) -> String {
    if unit.is_empty() {
        sig3(x)
    } else {
        format!("{} {unit}", sig3(x))
    }
}

/// Fits below this (−1000 %) read as `< −1000 %`: far worse than the mean,
/// and the digits say nothing more.
pub const FIT_FLOOR: f64 = -10.0;

/// An NRMSE fit (1 = perfect, 0 the mean) as a percentage with one decimal:
/// `87.3 %`, `−41.0 %`; `< −1000 %` below [`FIT_FLOOR`]; `—` for no fit.
pub fn percent(fit: Option<f64>) -> String {
    match fit.filter(|f| f.is_finite()) {
        None => "—".into(),
        Some(f) if f < FIT_FLOOR => format!("< {MINUS}1000 %"),
        Some(f) => format!("{} %", minus(&format!("{:.1}", 100.0 * f))),
    }
}

/// A time within a record, to a tenth of a second: `123.4 s`.
pub fn seconds(t: f64) -> String {
    if !t.is_finite() {
        return "—".into();
    }
    format!("{} s", minus(&format!("{t:.1}")))
}

/// A p-value: `p = 0.034`, `p < 0.001`.
pub fn p_value(p: f64) -> String {
    if !p.is_finite() {
        "p = —".into()
    } else if p < 0.001 {
        "p < 0.001".into()
    } else {
        format!("p = {}", sig3(p))
    }
}

/// A number someone sent, echoed in a message (`got 1e-308`): at most six
/// significant digits, ASCII minus (it may be pasted back), `2.5e-7` or
/// `1.23457e9` outside 10⁻⁴ … 10⁶; `NaN`, `inf` as such.
pub fn echoed(x: f64) -> String {
    if !x.is_finite() {
        return format!("{x}");
    }
    if x == 0.0 {
        return "0".into();
    }
    let trim = |m: &str| {
        if m.contains('.') {
            m.trim_end_matches('0').trim_end_matches('.').to_owned()
        } else {
            m.to_owned()
        }
    };
    // The exponent after rounding to six digits (999999.7 → 1.00000e6).
    let sci = format!("{x:.5e}");
    let Some((mantissa, exp)) = sci.split_once('e') else {
        return sci;
    };
    let exp: i32 = exp.parse().unwrap_or(0);
    if (-4..6).contains(&exp) {
        let decimals = (5 - exp).max(0) as usize;
        trim(&format!("{x:.decimals$}"))
    } else {
        format!("{}e{exp}", trim(mantissa))
    }
}

/// Text someone sent, safe to quote in a message: control characters
/// (newlines, escapes, NUL, …) shown as escapes (`\n`, `\u{1b}`), the rest
/// as is.
pub fn escape_controls(s: &str) -> String {
    if !s.chars().any(char::is_control) {
        return s.to_owned();
    }
    s.chars()
        .map(|c| {
            if c.is_control() {
                c.escape_default().to_string()
            } else {
                c.to_string()
            }
        })
        .collect()
}

fn minus(s: &str) -> String {
    match s.strip_prefix('-') {
        // −0.0 prints as "-0.0": no sign on a zero.
        Some(rest) if rest.chars().all(|c| c == '0' || c == '.') => rest.to_owned(),
        Some(rest) => format!("{MINUS}{rest}"),
        None => s.to_owned(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn three_significant_digits_with_units_and_a_true_minus() {
        assert_eq!(sig3(0.0), "0");
        assert_eq!(sig3(0.012345), "0.0123");
        assert_eq!(sig3(12.345), "12.3");
        assert_eq!(sig3(409.6), "410");
        assert_eq!(sig3(1999.5), "2000");
        assert_eq!(sig3(5.0), "5");
        assert_eq!(sig3(-0.5), "−0.5");
        assert_eq!(sig3(2.5e7), "2.5e7");
        assert_eq!(sig3(-1.0e-5), "−1e-5");
        assert_eq!(sig3(f64::NAN), "—");
        assert_eq!(sig3(f64::NEG_INFINITY), "—");
        assert_eq!(quantity(9860.4, "N·m"), "9860 N·m");
        assert_eq!(quantity(0.5, ""), "0.5");
    }

    #[test]
    fn echoed_numbers_have_at_most_six_significant_digits() {
        assert_eq!(echoed(1e-308), "1e-308");
        assert_eq!(echoed(1.7976931348623157e308), "1.79769e308");
        assert_eq!(echoed(-35496.16), "-35496.2");
        assert_eq!(echoed(0.1), "0.1");
        assert_eq!(echoed(100.0), "100");
        assert_eq!(echoed(123456.7), "123457");
        assert_eq!(echoed(0.000123456789), "0.000123457");
        assert_eq!(echoed(f64::NAN), "NaN");
        assert_eq!(echoed(999_999.7), "1e6");
        assert_eq!(echoed(-0.000099999996), "-0.0001");
        for x in [1e-308, 3.0e9, -2.0 / 3.0, 999_999.7, 1e300, 5e-5] {
            let s = echoed(x);
            let digits = s
                .split('e')
                .next()
                .unwrap()
                .chars()
                .filter(char::is_ascii_digit)
                .collect::<String>();
            assert!(digits.trim_start_matches('0').len() <= 6, "{x}: {s}");
        }
    }

    #[test]
    fn control_characters_are_escaped() {
        assert_eq!(escape_controls("Surveyor ROV"), "Surveyor ROV");
        assert_eq!(escape_controls("a\nb\u{1b}[31m"), "a\\nb\\u{1b}[31m");
        assert_eq!(escape_controls("ø\0"), "ø\\u{0}");
    }

    #[test]
    fn fits_times_and_p_values() {
        assert_eq!(percent(Some(0.8731)), "87.3 %");
        assert_eq!(percent(Some(-0.41)), "−41.0 %");
        assert_eq!(percent(Some(-9.99)), "−999.0 %");
        assert_eq!(percent(Some(-23.456)), "< −1000 %");
        assert_eq!(percent(Some(-0.0001)), "0.0 %");
        assert_eq!(percent(None), "—");
        assert_eq!(percent(Some(f64::NAN)), "—");
        assert_eq!(seconds(123.44), "123.4 s");
        assert_eq!(p_value(0.0342), "p = 0.0342");
        assert_eq!(p_value(1e-17), "p < 0.001");
    }
}
