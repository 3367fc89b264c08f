//! A query-string extractor whose errors are JSON 400s naming the parameter,
//! instead of axum's plain-text rejection.

use axum::extract::FromRequestParts;
use axum::http::request::Parts;
use serde::de::DeserializeOwned;

use axum::Json;
use axum::response::{IntoResponse, Response};
use seatrial_core::planning::PlanError;
use serde::Deserialize;

use crate::error::ApiError;
use crate::storage::Page;

/// `Query<T>` with a field-naming 400.
pub struct ApiQuery<T>(pub T);

impl<T: DeserializeOwned, S: Send + Sync> FromRequestParts<S> for ApiQuery<T> {
    type Rejection = ApiError;

    async fn from_request_parts(parts: &mut Parts, _state: &S) -> Result<Self, Self::Rejection> {
        let q = parts.uri.query().unwrap_or("");
        // `k=10.0` is the integer 10, as in JSON bodies.
        let mut rebuilt = form_urlencoded::Serializer::new(String::new());
        for (k, v) in form_urlencoded::parse(q.as_bytes()) {
            rebuilt.append_pair(&k, integral(&v).unwrap_or(&v));
        }
        let rebuilt = rebuilt.finish();
        let de = serde_urlencoded::Deserializer::new(form_urlencoded::parse(rebuilt.as_bytes()));
        serde_path_to_error::deserialize(de)
            .map(ApiQuery)
            .map_err(|e| {
                let path = e.path().to_string();
                let msg = e.inner().to_string();
                // serde_urlencoded names the parameter only in the message for
                // some errors; the path names it for type errors.
                ApiError::BadRequest {
                    message: format!("query parameter: {msg}"),
                    field: (path != ".").then_some(path),
                }
            })
    }
}

/// Largest page of a list.
pub const MAX_LIMIT: u32 = 1000;

/// Paging of a list: `limit` items after skipping `offset`. The number of
/// items that match the filters is in the `X-Total-Count` response header.
#[derive(Debug, Deserialize, utoipa::IntoParams)]
#[into_params(parameter_in = Query)]
pub struct Paging {
    /// Most items to return, 1–1000 (default: all).
    #[param(minimum = 1, maximum = 1000)]
    pub limit: Option<u32>,
    /// Items to skip (default 0).
    #[param(minimum = 0)]
    pub offset: Option<u32>,
}

/// The response header holding the number of items that match a list's filters.
pub const TOTAL_HEADER: &str = "x-total-count";

impl Paging {
    /// The storage page; a `limit` outside 1–1000 is a 422 naming it.
    pub fn page(&self) -> Result<Page, ApiError> {
        if let Some(l) = self.limit
            && !(1..=MAX_LIMIT).contains(&l)
        {
            return Err(ApiError::Unprocessable(PlanError::over_limit(
                "limit",
                format!("limit must be 1–{MAX_LIMIT}, got {l}"),
                f64::from(MAX_LIMIT),
            )));
        }
        Ok(Page {
            limit: self.limit.map(i64::from),
            offset: i64::from(self.offset.unwrap_or(0)),
        })
    }
}

/// One page of a list read whole (a short one: vessels, campaigns, jobs),
/// with the number of items in the `X-Total-Count` header.
pub fn paged<T: serde::Serialize>(items: Vec<T>, page: Page) -> Response {
    let total = items.len() as i64;
    let offset = usize::try_from(page.offset).unwrap_or(usize::MAX);
    let limit = page
        .limit
        .map_or(usize::MAX, |l| usize::try_from(l).unwrap_or(usize::MAX));
    with_total(items.into_iter().skip(offset).take(limit).collect(), total)
}

/// A list with its total in the `X-Total-Count` header.
pub fn with_total<T: serde::Serialize>(items: Vec<T>, total: i64) -> Response {
    ([(TOTAL_HEADER, total.to_string())], Json(items)).into_response()
}

/// The integer part of a decimal written with only zeros after its point
/// (`7489.0`, `-3.00`, `12.`), so that integer parameters accept it.
fn integral(v: &str) -> Option<&str> {
    let (int, frac) = v.split_once('.')?;
    let digits = int.strip_prefix('-').unwrap_or(int);
    (!digits.is_empty()
        && digits.bytes().all(|b| b.is_ascii_digit())
        && frac.bytes().all(|b| b == b'0'))
    .then_some(int)
}

#[cfg(test)]
mod tests {
    #[test]
    fn integral_decimals_lose_their_zeros_only() {
        assert_eq!(super::integral("7489.0"), Some("7489"));
        assert_eq!(super::integral("-3.00"), Some("-3"));
        assert_eq!(super::integral("0.5"), None);
        assert_eq!(super::integral("abc"), None);
        assert_eq!(super::integral(".0"), None);
    }
}
