//! "Never prints nonsense": every JSON number finite and of a plausible
//! magnitude, no `inf`/`NaN` and no absurd exponent in any text.

#![allow(dead_code)]

use serde_json::Value;

use super::TestApp;

/// Largest magnitude a served number may have.
pub const MAX_ABS: f64 = 1e15;

/// GET `template` with `args`: 200 and every number finite; the JSON.
pub async fn get_finite(app: &TestApp, template: &str, args: &[&str]) -> Value {
    let r = app.call("GET", template, args, None).await;
    assert_eq!(r.status, 200, "GET {template} {args:?}: {}", r.text);
    assert_finite_json(&r.json, template);
    r.json
}

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

/// Ids, hashes, worker names (`pid123-f36e72ac/0`) and timestamps hold hex
/// and digits that are not numbers.
fn is_identifier(path: &str) -> bool {
    let key = path
        .rsplit('.')
        .next()
        .unwrap_or("")
        .split('[')
        .next()
        .unwrap_or("");
    key == "sha256"
        || key == "worker"
        || key.ends_with("id")
        || key.ends_with("_ids")
        || key.ends_with("_at")
}

/// No `inf`, `NaN` or `infinity` word, and no number written with an
/// exponent of 16 or more (`7.3e35`, `1E+142`). A number is a token (of
/// letters, digits, '.', '+' and '-') that parses as one: the hex groups of
/// an id or hash (`…-9e87-…`, `f36e72ac`) are not numbers.
pub fn assert_clean_text(s: &str, what: &str) {
    for word in s.split(|c: char| !c.is_ascii_alphanumeric()) {
        let w = word.to_ascii_lowercase();
        assert!(
            !["nan", "inf", "infinity"].contains(&w.as_str()),
            "{what}: '{word}' in {s:?}"
        );
    }
    let tokens = s.split(|c: char| !(c.is_ascii_alphanumeric() || matches!(c, '.' | '+' | '-')));
    for token in tokens.map(|t| t.trim_end_matches('.')) {
        let Some(at) = token.find(['e', 'E']) else {
            continue;
        };
        if token.parse::<f64>().is_err() {
            continue;
        }
        let exponent = &token[at + 1..];
        let e: u32 = exponent
            .trim_start_matches(['+', '-'])
            .parse()
            .unwrap_or(u32::MAX);
        assert!(
            exponent.starts_with('-') || e < 16,
            "{what}: absurd magnitude (exponent {e}) in {s:?}"
        );
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
