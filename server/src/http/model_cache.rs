//! A model's GET answer serialised once: the JSON and its gzip form are
//! kept per model id, keyed by the model's metadata (a rename or a note
//! makes a new entry), so a repeated GET costs a summary query and a copy
//! instead of decoding, re-encoding and compressing a megabyte document.
//! The document and validation of a stored model never change; its row's
//! metadata is the only mutable part.

use std::collections::{HashMap, VecDeque};
use std::sync::{Arc, Mutex};

use axum::body::{Body, Bytes};
use axum::http::{HeaderMap, HeaderValue, header};
use axum::response::{IntoResponse, Response};

use super::offload::{accepts_gzip, gzip};

/// One model's answer, ready to send.
pub struct CachedModel {
    /// The metadata it was built with (serialised summary).
    key: String,
    /// `application/json` body.
    json: Bytes,
    /// The same, gzip-compressed.
    gzip: Bytes,
}

impl CachedModel {
    /// Serialises and compresses `json` once; `key` identifies the metadata.
    pub fn new(key: String, json: Vec<u8>) -> Self {
        let gzip = gzip(&json);
        CachedModel {
            key,
            json: Bytes::from(json),
            gzip: Bytes::from(gzip),
        }
    }

    fn bytes(&self) -> usize {
        self.json.len() + self.gzip.len()
    }

    /// The answer: gzip when the request accepts it, plain JSON otherwise.
    pub fn respond(&self, request: &HeaderMap) -> Response {
        let gzip = accepts_gzip(request);
        let mut headers = HeaderMap::new();
        headers.insert(
            header::CONTENT_TYPE,
            HeaderValue::from_static("application/json"),
        );
        headers.insert(header::VARY, HeaderValue::from_static("accept-encoding"));
        let body = if gzip {
            headers.insert(header::CONTENT_ENCODING, HeaderValue::from_static("gzip"));
            self.gzip.clone()
        } else {
            self.json.clone()
        };
        (headers, Body::from(body)).into_response()
    }
}

/// The cache: bounded by the bytes it holds, the oldest entry leaves first.
pub struct ModelCache {
    inner: Mutex<Inner>,
    budget_bytes: usize,
}

#[derive(Default)]
struct Inner {
    entries: HashMap<String, Arc<CachedModel>>,
    order: VecDeque<String>,
    bytes: usize,
}

impl ModelCache {
    /// A cache holding at most `budget_bytes` of bodies.
    pub fn new(budget_bytes: usize) -> Self {
        ModelCache {
            inner: Mutex::new(Inner::default()),
            budget_bytes,
        }
    }

    /// Model `id`'s answer if it was built with metadata `key`.
    pub fn get(&self, id: &str, key: &str) -> Option<Arc<CachedModel>> {
        let inner = self.inner.lock().unwrap_or_else(|e| e.into_inner());
        inner.entries.get(id).filter(|c| c.key == key).cloned()
    }

    /// Keeps model `id`'s answer (replacing an older one), evicting the
    /// oldest entries beyond the budget. A body larger than the budget is
    /// not kept.
    pub fn put(&self, id: &str, model: Arc<CachedModel>) {
        if model.bytes() > self.budget_bytes {
            return;
        }
        let mut inner = self.inner.lock().unwrap_or_else(|e| e.into_inner());
        inner.remove(id);
        inner.bytes += model.bytes();
        inner.order.push_back(id.to_string());
        inner.entries.insert(id.to_string(), model);
        while inner.bytes > self.budget_bytes {
            let Some(oldest) = inner.order.front().cloned() else {
                break;
            };
            inner.remove(&oldest);
        }
    }

    /// Drops model `id`'s answer (the model was deleted).
    pub fn forget(&self, id: &str) {
        self.inner
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .remove(id);
    }
}

impl Inner {
    fn remove(&mut self, id: &str) {
        if let Some(old) = self.entries.remove(id) {
            self.bytes -= old.bytes();
            self.order.retain(|k| k != id);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Read;

    #[test]
    fn the_gzip_body_decodes_to_the_json_body() {
        let json = br#"{"a":[1,2,3],"b":"x"}"#.repeat(100);
        let c = CachedModel::new("k".into(), json.clone());
        let mut out = Vec::new();
        flate2::read::GzDecoder::new(&c.gzip[..])
            .read_to_end(&mut out)
            .unwrap();
        assert_eq!(out, json);
        assert!(c.gzip.len() < json.len() / 10);
    }

    #[test]
    fn entries_are_keyed_by_metadata_and_bounded_by_bytes() {
        let body = |k: &str, n: usize| Arc::new(CachedModel::new(k.into(), vec![b'x'; n]));
        let one = body("a", 1000).bytes();
        let cache = ModelCache::new(2 * one + one / 2);
        cache.put("m1", body("a", 1000));
        assert!(cache.get("m1", "a").is_some());
        assert!(cache.get("m1", "renamed").is_none());
        cache.put("m2", body("a", 1000));
        cache.put("m3", body("a", 1000));
        assert!(cache.get("m1", "a").is_none(), "the oldest left first");
        assert!(cache.get("m2", "a").is_some() && cache.get("m3", "a").is_some());
        cache.forget("m2");
        assert!(cache.get("m2", "a").is_none());
        cache.put("m3", body("b", 1000));
        assert!(cache.get("m3", "a").is_none() && cache.get("m3", "b").is_some());
    }
}
