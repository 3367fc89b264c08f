//! A JSON body extractor whose errors name the offending field, with line
//! and column, instead of axum's plain-text rejections.

use axum::body::Bytes;
use axum::extract::{FromRequest, Request};
use axum::http::header::CONTENT_TYPE;
use serde::de::DeserializeOwned;
use serde_json::Value;

use crate::error::ApiError;

/// Largest JSON request body (bytes).
pub const MAX_JSON_BODY: usize = 1 << 20;

/// `Json<T>` with field-naming 400s, 415 on a wrong content type and 413 on
/// an oversized body.
pub struct ApiJson<T>(pub T);

impl<T: DeserializeOwned, S: Send + Sync> FromRequest<S> for ApiJson<T> {
    type Rejection = ApiError;

    async fn from_request(req: Request, state: &S) -> Result<Self, Self::Rejection> {
        let ct = req
            .headers()
            .get(CONTENT_TYPE)
            .and_then(|v| v.to_str().ok())
            .unwrap_or("");
        if !ct.starts_with("application/json") {
            return Err(ApiError::UnsupportedMediaType(format!(
                "expected a JSON body with Content-Type: application/json (got '{ct}')"
            )));
        }
        let bytes = Bytes::from_request(req, state).await.map_err(|e| {
            if e.status() == axum::http::StatusCode::PAYLOAD_TOO_LARGE {
                ApiError::too_large("the JSON body", MAX_JSON_BODY as u64, "")
            } else {
                ApiError::BadRequest {
                    message: format!("could not read the request body: {e}"),
                    field: None,
                }
            }
        })?;
        parse_json(&bytes).map(ApiJson)
    }
}

/// [`ApiJson`] for an optional body: an empty body is `None` (whatever its
/// content type); a non-empty one must be JSON.
pub struct OptionalApiJson<T>(pub Option<T>);

impl<T: DeserializeOwned, S: Send + Sync> FromRequest<S> for OptionalApiJson<T> {
    type Rejection = ApiError;

    async fn from_request(req: Request, state: &S) -> Result<Self, Self::Rejection> {
        let (parts, body) = req.into_parts();
        let bytes = axum::body::to_bytes(body, MAX_JSON_BODY)
            .await
            .map_err(|_| ApiError::too_large("the JSON body", MAX_JSON_BODY as u64, ""))?;
        if bytes.iter().all(u8::is_ascii_whitespace) {
            return Ok(OptionalApiJson(None));
        }
        let req = Request::from_parts(parts, axum::body::Body::from(bytes));
        ApiJson::from_request(req, state)
            .await
            .map(|ApiJson(v)| OptionalApiJson(Some(v)))
    }
}

/// Largest magnitude below which every integer is exactly a double (2⁵³).
const EXACT_INTEGER: f64 = 9_007_199_254_740_992.0;

/// Rewrites every number with an integral value written as a float
/// (`7489.0`, `2e3`) as that integer, in place: JSON has one number type, so
/// a field documented as `integer` accepts it (JSON Schema's `integer` is
/// any number with a zero fractional part). Fields that are floats accept
/// integers anyway.
pub fn integral_floats_as_integers(v: &mut Value) {
    match v {
        Value::Number(n) => {
            if let Some(f) = n.as_f64().filter(|_| n.is_f64())
                && f.fract() == 0.0
                && f.abs() <= EXACT_INTEGER
            {
                *n = serde_json::Number::from(f as i64);
            }
        }
        Value::Array(a) => a.iter_mut().for_each(integral_floats_as_integers),
        Value::Object(o) => o.values_mut().for_each(integral_floats_as_integers),
        _ => {}
    }
}

/// Parses JSON, naming the field (JSON path) of an error, and the line and
/// column of a syntax error. Integral floats are read as integers
/// ([`integral_floats_as_integers`]).
pub fn parse_json<T: DeserializeOwned>(bytes: &[u8]) -> Result<T, ApiError> {
    if bytes.iter().all(u8::is_ascii_whitespace) {
        return Err(ApiError::BadRequest {
            message: "the request body is empty; a JSON object is expected".into(),
            field: None,
        });
    }
    let mut value: Value = serde_json::from_slice(bytes).map_err(|e| ApiError::BadRequest {
        message: format!("invalid JSON body: {e}"),
        field: None,
    })?;
    integral_floats_as_integers(&mut value);
    serde_path_to_error::deserialize(value).map_err(|e| {
        let path = e.path().to_string();
        let inner = e.inner();
        let mut field = if path == "." { None } else { Some(path) };
        let msg = inner.to_string();
        // serde reports a missing field at its parent; name the field itself.
        if let Some(rest) = msg.strip_prefix("missing field `")
            && let Some(name) = rest.split('`').next()
        {
            field = Some(match field {
                Some(p) => format!("{p}.{name}"),
                None => name.to_string(),
            });
        }
        ApiError::BadRequest {
            message: format!("invalid JSON body: {msg}"),
            field,
        }
    })
}
