//! `seatrial`: start the service.

use std::net::SocketAddr;
use std::path::PathBuf;

use clap::Parser;
use tracing_subscriber::EnvFilter;

/// Sea-trial system identification service.
#[derive(Debug, Parser)]
#[command(version, about)]
struct Args {
    /// SQLite database file (created on first start).
    #[arg(long, env = "SEATRIAL_DB", default_value = "data/seatrial.db")]
    db: PathBuf,
    /// Address to listen on.
    #[arg(long, env = "SEATRIAL_LISTEN", default_value = "127.0.0.1:8080")]
    listen: SocketAddr,
    /// Folder of the web UI.
    #[arg(long, env = "SEATRIAL_WEB_DIR", default_value = "web")]
    web_dir: PathBuf,
    /// Largest upload per run, all files together (MB); larger answers 413.
    #[arg(long, env = "SEATRIAL_MAX_UPLOAD_MB", default_value_t = 1024)]
    max_upload_mb: u64,
    /// Folder of uploaded files (default: `blobs/` beside the database).
    #[arg(long, env = "SEATRIAL_BLOB_DIR")]
    blob_dir: Option<PathBuf>,
    /// Seed the demo vessels, campaigns and plans into an empty database.
    #[arg(long, env = "SEATRIAL_DEMO")]
    demo: bool,
}

#[tokio::main]
async fn main() -> anyhow::Result<()> {
    tracing_subscriber::fmt()
        .with_env_filter(
            EnvFilter::try_from_default_env().unwrap_or_else(|_| EnvFilter::new("info")),
        )
        .init();
    let args = Args::parse();
    if !args.web_dir.join("index.html").exists() {
        tracing::warn!(dir = %args.web_dir.display(), "web UI not found; the API still works");
    } else if !args.web_dir.join("node_modules/uplot").exists() {
        tracing::warn!(
            "web/node_modules is missing: run `npm ci --prefix web` (make run does) for the plots"
        );
    }
    let db = seatrial::storage::open(&args.db).await?;
    if args.demo && seatrial::demo::seed_if_empty(&db).await? {
        tracing::info!("seeded the demo campaigns");
    }
    let blob_dir = args.blob_dir.clone().unwrap_or_else(|| {
        args.db
            .parent()
            .map_or_else(|| PathBuf::from("blobs"), |d| d.join("blobs"))
    });
    let state = seatrial::http::AppState::new(db, &blob_dir, args.max_upload_mb * 1024 * 1024)?;
    let app = seatrial::http::app(state, args.web_dir);
    let listener = tokio::net::TcpListener::bind(args.listen).await?;
    let addr = listener.local_addr()?;
    tracing::info!("seatrial listening on http://{addr}");
    println!("seatrial listening on http://{addr}");
    axum::serve(listener, app)
        .with_graceful_shutdown(shutdown())
        .await?;
    Ok(())
}

/// Ctrl-C or SIGTERM.
async fn shutdown() {
    let ctrl_c = async {
        let _ = tokio::signal::ctrl_c().await;
    };
    #[cfg(unix)]
    let term = async {
        if let Ok(mut s) = tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate())
        {
            s.recv().await;
        }
    };
    #[cfg(not(unix))]
    let term = std::future::pending::<()>();
    tokio::select! {
        _ = ctrl_c => {},
        _ = term => {},
    }
}
