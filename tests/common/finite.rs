//! "Never prints nonsense": every JSON number finite and of a plausible
//! magnitude, no `inf`/`NaN` and no absurd exponent in any text.

#![allow(dead_code)]

use serde_json::Value;

/// Largest magnitude a served number may have.
pub const MAX_ABS: f64 = 1e15;

/// Walks `v`: every number finite with |x| ≤ [`MAX_ABS`], every string clean
/// (see [`assert_clean_text`]); identifiers and hashes are not text.
pub fn assert_finite_json(v: &Value, path: &str) {
    match v {
        Value::Number(n) => {
            let x = n.as_f64().expect("a JSON number");
            assert!(x.is_finite() && x.abs() <= MAX_ABS, "{path} = {x}");
        }
        Value::String(s) if !is_identifier(path) => assert_clean_text(s, path),
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                assert_finite_json(x, &format!("{path}[{i}]"));
            }
        }
        Value::Object(o) => {
            for (k, x) in o {
                assert_finite_json(x, &format!("{path}.{k}"));
            }
        }
        _ => {}
    }
}

/// Ids, hashes and timestamps hold hex and digits that are not numbers.
fn is_identifier(path: &str) -> bool {
    let key = path
        .rsplit('.')
        .next()
        .unwrap_or("")
        .split('[')
        .next()
        .unwrap_or("");
    key == "sha256" || key.ends_with("id") || key.ends_with("_ids") || key.ends_with("_at")
}

/// No `inf`, `NaN` or `infinity` word, and no number written with an
/// exponent of 16 or more (`7.3e35`, `1E+142`).
pub fn assert_clean_text(s: &str, what: &str) {
    for word in s.split(|c: char| !c.is_ascii_alphanumeric()) {
        let w = word.to_ascii_lowercase();
        assert!(
            !["nan", "inf", "infinity"].contains(&w.as_str()),
            "{what}: '{word}' in {s:?}"
        );
    }
    let b = s.as_bytes();
    for i in 1..b.len() {
        if (b[i] == b'e' || b[i] == b'E') && b[i - 1].is_ascii_digit() {
            let rest = &s[i + 1..];
            let digits: String = rest
                .trim_start_matches(['+', '-'])
                .chars()
                .take_while(char::is_ascii_digit)
                .collect();
            let negative = rest.starts_with('-');
            if let Ok(e) = digits.parse::<u32>() {
                assert!(
                    negative || e < 16,
                    "{what}: absurd magnitude (exponent {e}) in {s:?}"
                );
            }
        }
    }
}

/// A CSV body: clean text, and every cell that is a number finite with
/// |x| ≤ [`MAX_ABS`].
pub fn assert_finite_csv(body: &str, what: &str) {
    assert_clean_text(body, what);
    for (i, line) in body.lines().enumerate() {
        for cell in line.split(',') {
            if let Ok(x) = cell.trim().parse::<f64>() {
                assert!(
                    x.is_finite() && x.abs() <= MAX_ABS,
                    "{what} line {}: {cell}",
                    i + 1
                );
            }
        }
    }
}
