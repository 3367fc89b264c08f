//! Liveness and database reachability.

use axum::Json;
use axum::extract::State;
use serde::Serialize;

use super::AppState;
use crate::error::ApiResult;

/// Service health.
#[derive(Debug, Serialize, utoipa::ToSchema)]
pub struct Health {
    /// "ok" when the service and its database answer.
    pub status: String,
    /// Software version.
    pub version: String,
    /// Applied schema migrations.
    pub migrations: i64,
    /// Largest upload per run (bytes): clients can refuse bigger files before sending.
    pub max_upload_bytes: u64,
}

/// Is the service up, and its database reachable?
#[utoipa::path(get, path = "/api/health", tag = "service",
    responses((status = 200, description = "Healthy", body = Health),
              (status = 500, description = "Database unreachable", body = crate::error::ErrorBody)))]
pub async fn health(State(s): State<AppState>) -> ApiResult<Json<Health>> {
    let migrations: i64 = sqlx::query_scalar("SELECT COUNT(*) FROM _sqlx_migrations")
        .fetch_one(&s.db)
        .await?;
    Ok(Json(Health {
        status: "ok".into(),
        version: env!("CARGO_PKG_VERSION").into(),
        migrations,
        max_upload_bytes: s.max_upload_bytes,
    }))
}
