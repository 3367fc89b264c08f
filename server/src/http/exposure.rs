//! What makes the service safe to put on a network before it has accounts:
//! a Host allow-list (a DNS-rebinding page reaches the port under its own
//! name and is refused), an Origin rule on writes (a cross-site page can
//! send a form or a `fetch` but not under our origin), security headers on
//! every response, and only the web UI's own files served.

use std::net::{IpAddr, SocketAddr};
use std::path::PathBuf;
use std::sync::Arc;

use axum::extract::{Request, State};
use axum::http::header::{self, HeaderName, HeaderValue};
use axum::http::{Method, Uri};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};
use tower::ServiceExt;
use tower_http::services::ServeDir;

use crate::error::ApiError;

/// Content-Security-Policy of every response: the UI is ES modules and one
/// stylesheet from this origin, no inline script or style, no framing.
pub const CONTENT_SECURITY_POLICY: &str = "default-src 'self'; script-src 'self'; \
     style-src 'self'; img-src 'self' data: blob:; connect-src 'self'; font-src 'self'; \
     object-src 'none'; base-uri 'none'; form-action 'self'; frame-ancestors 'none'";

/// Who may reach the service: the host names it answers to and the
/// origins (besides its own) allowed to write.
#[derive(Debug, Clone)]
pub struct Exposure {
    /// Host names (lower case, IPv6 in brackets, no port); `*` allows any.
    hosts: Vec<String>,
    /// Origins (`scheme://host[:port]`, lower case) allowed to write besides the service's own.
    origins: Vec<String>,
}

impl Default for Exposure {
    fn default() -> Self {
        Exposure::local(None)
    }
}

impl Exposure {
    /// `localhost`, `127.0.0.1`, `[::1]` and the address listened on (when
    /// it is not the unspecified 0.0.0.0 or `::`).
    pub fn local(listen: Option<SocketAddr>) -> Self {
        let hosts: Vec<String> = ["localhost", "127.0.0.1", "[::1]"]
            .map(String::from)
            .to_vec();
        let local = Exposure {
            hosts,
            origins: Vec::new(),
        };
        match listen.filter(|a| !a.ip().is_unspecified()) {
            Some(a) => local.allow_hosts(&[host_of_ip(a.ip())]),
            None => local,
        }
    }

    /// Also answers to these host names (`*`: any host; ports are ignored).
    pub fn allow_hosts<S: AsRef<str>>(mut self, hosts: &[S]) -> Self {
        for h in hosts {
            let h = normalise_host(h.as_ref().trim());
            if !h.is_empty() && !self.hosts.contains(&h) {
                self.hosts.push(h);
            }
        }
        self
    }

    /// Also accepts writes from pages of these origins (`https://ops.example:8443`).
    pub fn allow_origins<S: AsRef<str>>(mut self, origins: &[S]) -> Self {
        for o in origins {
            let o = o.as_ref().trim().trim_end_matches('/').to_ascii_lowercase();
            if !o.is_empty() && !self.origins.contains(&o) {
                self.origins.push(o);
            }
        }
        self
    }

    /// Whether any host is allowed (`*`), which gives up the rebinding guard.
    pub fn any_host(&self) -> bool {
        self.hosts.iter().any(|h| h == "*")
    }

    /// The host names answered to.
    pub fn hosts(&self) -> &[String] {
        &self.hosts
    }

    fn host_allowed(&self, host: &str) -> bool {
        self.any_host() || self.hosts.iter().any(|h| h == host)
    }

    /// A write from `origin` to a request addressed to `authority` (its
    /// Host header): same host and port, or a configured origin.
    fn origin_allowed(&self, origin: &str, authority: Option<&str>) -> bool {
        let origin = origin.to_ascii_lowercase();
        if self.origins.contains(&origin) {
            return true;
        }
        let Some(authority) = authority else {
            return false;
        };
        let authority = authority.to_ascii_lowercase();
        ["http://", "https://"]
            .iter()
            .any(|scheme| origin.strip_prefix(scheme) == Some(authority.as_str()))
    }
}

fn host_of_ip(ip: IpAddr) -> String {
    match ip {
        IpAddr::V4(v4) => v4.to_string(),
        IpAddr::V6(v6) => format!("[{v6}]"),
    }
}

/// The host name of a Host header value (or an allow-list entry): lower
/// case, without port or trailing dot; an IPv6 literal keeps its brackets.
fn normalise_host(authority: &str) -> String {
    let a = authority.to_ascii_lowercase();
    let host = if a.starts_with('[') {
        match a.find(']') {
            Some(end) => a[..=end].to_string(),
            None => a,
        }
    } else if a.parse::<std::net::Ipv6Addr>().is_ok() {
        format!("[{a}]")
    } else {
        match a.rsplit_once(':') {
            Some((h, port)) if port.bytes().all(|b| b.is_ascii_digit()) => h.to_string(),
            _ => a,
        }
    };
    host.trim_end_matches('.').to_string()
}

/// A header value quoted for a message: printable ASCII kept, anything
/// else escaped, at most 100 characters.
fn quoted(v: &[u8]) -> String {
    let mut s: String = v
        .iter()
        .take(100)
        .flat_map(|b| std::ascii::escape_default(*b))
        .map(char::from)
        .collect();
    if v.len() > 100 {
        s.push('…');
    }
    s
}

fn is_write(m: &Method) -> bool {
    !matches!(
        *m,
        Method::GET | Method::HEAD | Method::OPTIONS | Method::TRACE
    )
}

/// The guard in front of every route: Host allow-list (421), Origin rule
/// on writes (403), then the security headers on whatever is answered.
pub async fn guard(State(exposure): State<Arc<Exposure>>, req: Request, next: Next) -> Response {
    let is_api = req.uri().path().starts_with("/api/") || req.uri().path() == "/api";
    let mut resp = match check(&exposure, &req) {
        Ok(()) => next.run(req).await,
        Err(e) => e.into_response(),
    };
    let h = resp.headers_mut();
    let set = |h: &mut axum::http::HeaderMap, name: HeaderName, value: &'static str| {
        h.entry(name).or_insert(HeaderValue::from_static(value));
    };
    set(h, header::CONTENT_SECURITY_POLICY, CONTENT_SECURITY_POLICY);
    set(h, header::X_CONTENT_TYPE_OPTIONS, "nosniff");
    set(h, header::X_FRAME_OPTIONS, "DENY");
    set(h, header::REFERRER_POLICY, "no-referrer");
    if is_api {
        set(h, header::CACHE_CONTROL, "no-store");
    }
    resp
}

fn check(exposure: &Exposure, req: &Request) -> Result<(), ApiError> {
    // A browser always sends Host (HTTP/2: the authority); a request with
    // neither cannot come from a rebinding page.
    let authority = match req.headers().get(header::HOST) {
        Some(v) => Some(v.to_str().map_err(|_| {
            ApiError::misdirected(format!(
                "the Host header '{}' is not a host name",
                quoted(v.as_bytes())
            ))
        })?),
        None => req.uri().authority().map(|a| a.as_str()),
    };
    if let Some(a) = authority
        && !exposure.host_allowed(&normalise_host(a))
    {
        return Err(ApiError::misdirected(format!(
            "this service does not answer to the host '{}' (a guard against DNS rebinding); \
             its operator can add the name with --allowed-hosts or SEATRIAL_ALLOWED_HOSTS",
            quoted(a.as_bytes())
        )));
    }
    if !is_write(req.method()) {
        return Ok(());
    }
    match req.headers().get(header::ORIGIN) {
        Some(o) => {
            let allowed = o
                .to_str()
                .is_ok_and(|o| exposure.origin_allowed(o, authority));
            if !allowed {
                return Err(ApiError::forbidden(
                    "Origin",
                    format!(
                        "{} from a page of another origin ('{}') is refused: writes come from this \
                         service's own pages or from origins its operator lists with \
                         --allowed-origins or SEATRIAL_ALLOWED_ORIGINS",
                        req.method(),
                        quoted(o.as_bytes())
                    ),
                ));
            }
        }
        None => {
            // Browsers that send Fetch metadata say so even without Origin.
            if req
                .headers()
                .get("sec-fetch-site")
                .is_some_and(|v| v.as_bytes() == b"cross-site")
            {
                return Err(ApiError::forbidden(
                    "Origin",
                    format!(
                        "{} from a cross-site page is refused (Sec-Fetch-Site: cross-site)",
                        req.method()
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Whether `path` is one of the files the web UI loads: `/`, `index.html`,
/// the `*.js` and `*.css` at the top of the web folder, and uPlot's module
/// and stylesheet. Nothing else there (`package.json`, `node_modules/…`,
/// `tests/…`) is served.
pub fn is_web_asset(path: &str) -> bool {
    const VENDORED: [&str; 2] = [
        "/node_modules/uplot/dist/uPlot.esm.js",
        "/node_modules/uplot/dist/uPlot.min.css",
    ];
    if path == "/" || path == "/index.html" || VENDORED.contains(&path) {
        return true;
    }
    let Some(name) = path.strip_prefix('/') else {
        return false;
    };
    !name.starts_with('.')
        && name
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || matches!(b, b'-' | b'_' | b'.'))
        && (name.ends_with(".js") || name.ends_with(".css"))
}

/// The web UI's files from `web_dir`, and a 404 for anything else.
pub async fn web_asset(web_dir: PathBuf, uri: Uri, req: Request) -> Response {
    if !is_web_asset(uri.path()) {
        return ApiError::NotFound(format!(
            "no web page or asset {}",
            quoted(uri.path().as_bytes())
        ))
        .into_response();
    }
    match ServeDir::new(web_dir).oneshot(req).await {
        Ok(r) => r.into_response(),
        Err(never) => match never {},
    }
}

/// `Content-Disposition: attachment` for a download named after something
/// people named (a vessel, an uploaded file): an ASCII `filename=` with
/// anything unsafe replaced by `_`, and the exact name as RFC 5987
/// `filename*=UTF-8''…`. Visible ASCII only: always a valid header value.
pub fn attachment(filename: &str) -> String {
    let ascii: String = filename
        .chars()
        .map(|c| {
            if c == ' ' || (c.is_ascii_graphic() && !matches!(c, '"' | '\\' | '/' | '%' | ';')) {
                c
            } else {
                '_'
            }
        })
        .collect();
    let mut encoded = String::new();
    for b in filename.bytes() {
        if b.is_ascii_alphanumeric() || b"!#$&+-.^_`|~".contains(&b) {
            encoded.push(char::from(b));
        } else {
            encoded.push_str(&format!("%{b:02X}"));
        }
    }
    format!("attachment; filename=\"{ascii}\"; filename*=UTF-8''{encoded}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn attachment_names_are_valid_headers() {
        assert_eq!(
            attachment("Surveyor ROV.json"),
            "attachment; filename=\"Surveyor ROV.json\"; filename*=UTF-8''Surveyor%20ROV.json"
        );
        assert_eq!(
            attachment("a\u{7}\"b\nø.csv"),
            "attachment; filename=\"a__b__.csv\"; filename*=UTF-8''a%07%22b%0A%C3%B8.csv"
        );
    }

    #[test]
    fn host_names_lose_port_case_and_trailing_dot() {
        assert_eq!(normalise_host("LocalHost:8080"), "localhost");
        assert_eq!(normalise_host("localhost."), "localhost");
        assert_eq!(normalise_host("[::1]:8080"), "[::1]");
        assert_eq!(normalise_host("::1"), "[::1]");
        assert_eq!(normalise_host("10.0.0.5"), "10.0.0.5");
    }

    #[test]
    fn the_bind_address_is_allowed_unless_unspecified() {
        let e = Exposure::local(Some("10.1.2.3:8080".parse().unwrap()));
        assert!(e.host_allowed("10.1.2.3"));
        let e = Exposure::local(Some("127.0.0.1:8080".parse().unwrap()));
        assert_eq!(e.hosts(), ["localhost", "127.0.0.1", "[::1]"]);
        let e = Exposure::local(Some("[::1]:8080".parse().unwrap()));
        assert_eq!(e.hosts(), ["localhost", "127.0.0.1", "[::1]"]);
        let e = Exposure::local(Some("0.0.0.0:8080".parse().unwrap()));
        assert!(!e.host_allowed("0.0.0.0"));
        assert_eq!(e.hosts(), ["localhost", "127.0.0.1", "[::1]"]);
        let e = e.allow_hosts(&["Ops.Example:443"]);
        assert!(e.host_allowed("ops.example"));
    }

    #[test]
    fn only_the_ui_files_are_web_assets() {
        for ok in [
            "/",
            "/index.html",
            "/app.js",
            "/style.css",
            "/node_modules/uplot/dist/uPlot.esm.js",
        ] {
            assert!(is_web_asset(ok), "{ok}");
        }
        for no in [
            "/package.json",
            "/package-lock.json",
            "/node_modules/uplot/package.json",
            "/node_modules/playwright-core/index.js",
            "/tests/harness.mjs",
            "/tests/sim.js",
            "/.eslintrc.js",
            "/%2e%2e/secret.js",
            "/README.md",
        ] {
            assert!(!is_web_asset(no), "{no}");
        }
    }
}
