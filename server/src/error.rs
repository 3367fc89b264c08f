//! The service's one error type and its mapping to HTTP status codes
//! (the pattern of launchbadge's realworld-axum-sqlx). Every error body is
//! JSON: `{ "status", "message", "field"?, "limit"? }`.

use axum::Json;
use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};
use seatrial_core::planning::PlanError;
use serde::Serialize;

/// JSON body of every error response.
#[derive(Debug, Serialize, utoipa::ToSchema)]
pub struct ErrorBody {
    /// HTTP status code.
    pub status: u16,
    /// What went wrong, in plain words.
    pub message: String,
    /// The offending field (JSON path into the request, or the parameter name).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub field: Option<String>,
    /// The limit that was broken, in SI units.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub limit: Option<f64>,
    /// Line (1-based, header = 1) of an uploaded file.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub line: Option<u64>,
    /// Column name of an uploaded file.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub column: Option<String>,
    /// The run an invalid upload was stored as (nothing is lost).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub run_id: Option<String>,
}

/// Errors of the HTTP layer.
#[derive(Debug, thiserror::Error)]
pub enum ApiError {
    /// Malformed request: unparsable JSON, wrong types (400).
    #[error("{message}")]
    BadRequest {
        /// Message.
        message: String,
        /// Offending field.
        field: Option<String>,
    },
    /// Nothing with that id (404).
    #[error("{0}")]
    NotFound(String),
    /// A request field names something that does not exist (404).
    #[error("{message}")]
    Missing {
        /// Message.
        message: String,
        /// The field holding the unknown id.
        field: String,
    },
    /// A request field is understood but unusable (422).
    #[error("{message}")]
    Invalid {
        /// Message.
        message: String,
        /// The offending field.
        field: String,
    },
    /// The resource is not in a state that allows this (409).
    #[error("{0}")]
    Conflict(String),
    /// Understood but impossible or unsafe (422).
    #[error("{0}")]
    Unprocessable(#[from] PlanError),
    /// An upload that was stored but fails validation (422).
    #[error("{message}")]
    InvalidUpload {
        /// Message.
        message: String,
        /// The file: `file`, `control` or `nav`.
        field: String,
        /// Line in that file.
        line: Option<u64>,
        /// Column name.
        column: Option<String>,
        /// The stored run.
        run_id: String,
    },
    /// No valid credentials where they are required (401).
    #[error("{0}")]
    Unauthorized(String),
    /// A write from a page of another origin, a role too low, a cookie
    /// write without the CSRF header (403).
    #[error("{message}")]
    Forbidden {
        /// Message.
        message: String,
        /// What decided it (`Origin`, `role`, `X-Seatrial-CSRF`).
        field: String,
    },
    /// A Host the service does not answer to: a DNS-rebinding guard (421).
    #[error("{0}")]
    Misdirected(String),
    /// Too many attempts: try again after `retry_after_s` (429 with
    /// `Retry-After`).
    #[error("{message}")]
    TooManyRequests {
        /// Message.
        message: String,
        /// Seconds to wait.
        retry_after_s: u64,
    },
    /// Route exists, method does not (405).
    #[error("{0}")]
    MethodNotAllowed(String),
    /// Request body over the size limit (413); the body's `limit` is in bytes.
    #[error("{message}")]
    TooLarge {
        /// Message, naming the limit.
        message: String,
        /// The limit (bytes).
        limit_bytes: u64,
    },
    /// Wrong content type (415).
    #[error("{0}")]
    UnsupportedMediaType(String),
    /// Database failure (500, logged).
    #[error("database error: {0}")]
    Database(#[from] sqlx::Error),
    /// Anything else unexpected (500, logged).
    #[error("internal error: {0}")]
    Internal(#[from] anyhow::Error),
}

impl ApiError {
    /// A 400 naming a field.
    pub fn bad_field(field: impl Into<String>, message: impl Into<String>) -> Self {
        ApiError::BadRequest {
            message: message.into(),
            field: Some(field.into()),
        }
    }

    /// A 404 for an unknown id given in a request field.
    pub fn missing(field: impl Into<String>, message: impl Into<String>) -> Self {
        ApiError::Missing {
            message: message.into(),
            field: field.into(),
        }
    }

    /// A 422 naming a field.
    pub fn invalid(field: impl Into<String>, message: impl Into<String>) -> Self {
        ApiError::Invalid {
            message: message.into(),
            field: field.into(),
        }
    }

    /// A 403 naming the header that decided it.
    pub fn forbidden(field: impl Into<String>, message: impl Into<String>) -> Self {
        ApiError::Forbidden {
            message: message.into(),
            field: field.into(),
        }
    }

    /// A 413 naming the limit in bytes (and MB when that reads better).
    pub fn too_large(what: &str, limit_bytes: u64, hint: &str) -> Self {
        let mb = limit_bytes as f64 / (1024.0 * 1024.0);
        let shown = if limit_bytes >= 1024 * 1024 {
            format!(
                "{limit_bytes} bytes ({} MB)",
                seatrial_core::numbers::echoed(mb)
            )
        } else {
            format!("{limit_bytes} bytes")
        };
        ApiError::TooLarge {
            message: format!("{what} exceeds the limit of {shown}{hint}"),
            limit_bytes,
        }
    }

    /// A 421 for a Host header not on the allow-list.
    pub fn misdirected(message: impl Into<String>) -> Self {
        ApiError::Misdirected(message.into())
    }

    fn status(&self) -> StatusCode {
        match self {
            ApiError::BadRequest { .. } => StatusCode::BAD_REQUEST,
            ApiError::NotFound(_) | ApiError::Missing { .. } => StatusCode::NOT_FOUND,
            ApiError::Unprocessable(_)
            | ApiError::InvalidUpload { .. }
            | ApiError::Invalid { .. } => StatusCode::UNPROCESSABLE_ENTITY,
            ApiError::Conflict(_) => StatusCode::CONFLICT,
            ApiError::Unauthorized(_) => StatusCode::UNAUTHORIZED,
            ApiError::Forbidden { .. } => StatusCode::FORBIDDEN,
            ApiError::Misdirected(_) => StatusCode::MISDIRECTED_REQUEST,
            ApiError::TooManyRequests { .. } => StatusCode::TOO_MANY_REQUESTS,
            ApiError::MethodNotAllowed(_) => StatusCode::METHOD_NOT_ALLOWED,
            ApiError::TooLarge { .. } => StatusCode::PAYLOAD_TOO_LARGE,
            ApiError::UnsupportedMediaType(_) => StatusCode::UNSUPPORTED_MEDIA_TYPE,
            ApiError::Database(_) | ApiError::Internal(_) => StatusCode::INTERNAL_SERVER_ERROR,
        }
    }
}

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        let status = self.status();
        let mut body = ErrorBody {
            status: status.as_u16(),
            message: String::new(),
            field: None,
            limit: None,
            line: None,
            column: None,
            run_id: None,
        };
        let retry_after = match &self {
            ApiError::TooManyRequests { retry_after_s, .. } => Some(*retry_after_s),
            _ => None,
        };
        let (message, field, limit) = match self {
            ApiError::BadRequest { message, field } => (message, field, None),
            ApiError::Missing { message, field }
            | ApiError::Invalid { message, field }
            | ApiError::Forbidden { message, field } => (message, Some(field), None),
            ApiError::Unprocessable(e) => (e.message, Some(e.field), e.limit),
            ApiError::InvalidUpload {
                message,
                field,
                line,
                column,
                run_id,
            } => {
                body.line = line;
                body.column = column;
                body.run_id = Some(run_id);
                (message, Some(field), None)
            }
            ApiError::Database(e) => {
                tracing::error!(error = %e, "database error");
                (
                    "internal database error; see the server log".to_string(),
                    None,
                    None,
                )
            }
            ApiError::Internal(e) => {
                tracing::error!(error = %e, "internal error");
                ("internal error; see the server log".to_string(), None, None)
            }
            ApiError::Misdirected(message) => (message, Some("Host".to_string()), None),
            ApiError::TooLarge {
                message,
                limit_bytes,
            } => (message, None, Some(limit_bytes as f64)),
            other => (other.to_string(), None, None),
        };
        // Messages and fields may quote what a client sent: never raw
        // control characters (newlines, terminal escapes).
        body.message = seatrial_core::numbers::escape_controls(&message);
        body.field = field.map(|f| seatrial_core::numbers::escape_controls(&f));
        body.limit = limit;
        let mut r = (status, Json(body)).into_response();
        if let Some(secs) = retry_after {
            r.headers_mut()
                .insert(axum::http::header::RETRY_AFTER, secs.into());
        }
        r
    }
}

/// Result of a handler.
pub type ApiResult<T> = Result<T, ApiError>;
