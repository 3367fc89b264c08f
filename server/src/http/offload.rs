//! Reads answered off the async workers. A GET under `/api` (but the health
//! probe, event streams and raw file downloads) runs its handler, the
//! serialisation and the gzip of its body on a blocking thread, at most one
//! per core at a time; the async workers only move bytes. So a burst of
//! heavy reads waits for a permit without occupying the threads that answer
//! `/api/health` and accept connections.

use std::io::Write;
use std::sync::Arc;

use axum::body::{Body, to_bytes};
use axum::extract::{Request, State};
use axum::http::{HeaderMap, HeaderValue, Method, header};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};
use tokio::sync::Semaphore;

use crate::error::ApiError;

/// Bodies smaller than this are sent as they are.
const GZIP_MIN_BYTES: usize = 1024;

/// Whether an `Accept-Encoding` header admits gzip (`gzip`, `x-gzip` or `*`
/// without `q=0`).
pub(crate) fn accepts_gzip(request: &HeaderMap) -> bool {
    request
        .get_all(header::ACCEPT_ENCODING)
        .iter()
        .filter_map(|v| v.to_str().ok())
        .flat_map(|v| v.split(','))
        .any(|item| {
            let mut parts = item.split(';').map(str::trim);
            let coding = parts.next().unwrap_or("").to_ascii_lowercase();
            let refused = parts.any(|p| {
                p.strip_prefix("q=")
                    .and_then(|q| q.trim().parse::<f64>().ok())
                    .is_some_and(|q| q <= 0.0)
            });
            matches!(coding.as_str(), "gzip" | "x-gzip" | "*") && !refused
        })
}

/// `bytes` gzip-compressed (default level).
pub(crate) fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut enc = flate2::write::GzEncoder::new(
        Vec::with_capacity(bytes.len() / 3),
        flate2::Compression::default(),
    );
    enc.write_all(bytes).expect("gzip into memory");
    enc.finish().expect("gzip into memory")
}

/// Permits for the blocking threads that answer reads: one per core.
pub fn permits() -> Arc<Semaphore> {
    let n = std::thread::available_parallelism().map_or(2, |n| n.get());
    Arc::new(Semaphore::new(n))
}

fn offloaded(req: &Request) -> bool {
    let path = req.uri().path();
    matches!(*req.method(), Method::GET | Method::HEAD)
        && path.starts_with("/api/")
        && path != "/api/health"
        && !path.ends_with("/events")
        && !path.ends_with("/raw")
}

/// The middleware (see the module documentation).
pub async fn offload(State(permits): State<Arc<Semaphore>>, req: Request, next: Next) -> Response {
    if !offloaded(&req) {
        return next.run(req).await;
    }
    let gzip_ok = accepts_gzip(req.headers());
    let Ok(permit) = permits.acquire_owned().await else {
        return next.run(req).await;
    };
    let handle = tokio::runtime::Handle::current();
    let answered = tokio::task::spawn_blocking(move || {
        let _permit = permit;
        handle.block_on(async move { finish(next.run(req).await, gzip_ok).await })
    })
    .await;
    answered.unwrap_or_else(|e| {
        ApiError::Internal(anyhow::anyhow!("read worker failed: {e}")).into_response()
    })
}

/// The response with its body collected and, when the client accepts it and
/// the body is large text, gzip-compressed here.
async fn finish(resp: Response, gzip_ok: bool) -> Response {
    let (mut parts, body) = resp.into_parts();
    let Ok(bytes) = to_bytes(body, usize::MAX).await else {
        return ApiError::Internal(anyhow::anyhow!("response body unreadable")).into_response();
    };
    let textual = parts
        .headers
        .get(header::CONTENT_TYPE)
        .and_then(|v| v.to_str().ok())
        .is_some_and(|t| t.starts_with("application/json") || t.starts_with("text/"));
    if gzip_ok
        && textual
        && bytes.len() >= GZIP_MIN_BYTES
        && !parts.headers.contains_key(header::CONTENT_ENCODING)
    {
        let packed = gzip(&bytes);
        parts
            .headers
            .insert(header::CONTENT_ENCODING, HeaderValue::from_static("gzip"));
        parts.headers.remove(header::CONTENT_LENGTH);
        parts
            .headers
            .append(header::VARY, HeaderValue::from_static("accept-encoding"));
        return Response::from_parts(parts, Body::from(packed));
    }
    Response::from_parts(parts, Body::from(bytes))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn headers(v: &str) -> HeaderMap {
        let mut h = HeaderMap::new();
        h.insert(header::ACCEPT_ENCODING, HeaderValue::from_str(v).unwrap());
        h
    }

    #[test]
    fn gzip_is_chosen_only_when_accepted() {
        assert!(accepts_gzip(&headers("gzip, deflate, br")));
        assert!(accepts_gzip(&headers("br;q=1.0, gzip;q=0.8")));
        assert!(accepts_gzip(&headers("*")));
        assert!(!accepts_gzip(&headers("gzip;q=0")));
        assert!(!accepts_gzip(&headers("identity")));
        assert!(!accepts_gzip(&HeaderMap::new()));
    }
}
