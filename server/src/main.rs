//! `seatrial`: start the service.

use std::net::SocketAddr;
use std::path::PathBuf;

use std::time::Duration;

use clap::Parser;
use seatrial::jobs::{JobRegistry, Jobs, JobsConfig};
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
    /// Jobs computed at once (default: one per core but one, at least one).
    #[arg(long, env = "SEATRIAL_JOB_WORKERS")]
    job_workers: Option<usize>,
    /// Attempts of a job whose server stopped mid-run, before it is `interrupted`.
    #[arg(long, env = "SEATRIAL_JOB_MAX_ATTEMPTS", default_value_t = 3,
          value_parser = clap::value_parser!(i64).range(1..))]
    job_max_attempts: i64,
    /// Lease of a running job (s): after a crash, its job is queued again this long after the last heartbeat.
    #[arg(long, env = "SEATRIAL_JOB_LEASE_SECS", default_value_t = 30,
          value_parser = clap::value_parser!(u64).range(2..))]
    job_lease_secs: u64,
    /// Host names the service answers to besides localhost, 127.0.0.1, [::1]
    /// and the listen address (comma-separated; ports ignored; `*` = any,
    /// which gives up the DNS-rebinding guard). Other Host headers get 421.
    #[arg(long, env = "SEATRIAL_ALLOWED_HOSTS", value_delimiter = ',')]
    allowed_hosts: Vec<String>,
    /// Origins (`https://ops.example:8443`) whose pages may write (POST, PUT,
    /// PATCH, DELETE) besides the service's own; other origins get 403.
    #[arg(long, env = "SEATRIAL_ALLOWED_ORIGINS", value_delimiter = ',')]
    allowed_origins: Vec<String>,
    /// `required`: every request but health and sign-in needs credentials.
    /// `auto` (default): required unless listening on a loopback address,
    /// where requests without credentials act as the local admin.
    #[arg(long, env = "SEATRIAL_AUTH", value_enum, default_value_t = AuthMode::Auto)]
    auth: AuthMode,
    /// File holding the password of the first admin (`admin`), made when
    /// credentials are required and there is no account yet; without it a
    /// one-time password is printed once.
    #[arg(long, env = "SEATRIAL_ADMIN_PASSWORD_FILE")]
    admin_password_file: Option<PathBuf>,
    /// Mark the session cookie `Secure` (serve behind https).
    #[arg(long, env = "SEATRIAL_COOKIE_SECURE")]
    cookie_secure: bool,
}

/// Whether requests need credentials.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum AuthMode {
    /// Required unless listening on loopback (local mode).
    Auto,
    /// Always required.
    Required,
}

/// The service's allocator (see the workspace's Cargo.toml).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// The compute pool and two runtimes (see `seatrial::runtime`): the job workers' own, built first
/// from the main thread at its priority, and the HTTP one that runs `serve`.
fn main() -> anyhow::Result<()> {
    seatrial::runtime::compute_pool()?;
    let jobs = seatrial::runtime::jobs()?;
    let http = seatrial::runtime::http()?;
    http.block_on(serve(jobs.handle().clone()))
}

async fn serve(jobs_rt: tokio::runtime::Handle) -> anyhow::Result<()> {
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
    let blob_dir = args.blob_dir.clone().unwrap_or_else(|| {
        args.db
            .parent()
            .map_or_else(|| PathBuf::from("blobs"), |d| d.join("blobs"))
    });
    if args.demo {
        let blobs = seatrial::storage::blobs::BlobStore::open(&blob_dir)?;
        if seatrial::demo::seed_if_empty(&db, &blobs).await? {
            tracing::info!("seeded the demo campaigns (the ROV campaign flown in simulation)");
        }
    }
    let config = JobsConfig {
        workers: args
            .job_workers
            .unwrap_or_else(seatrial::jobs::service::default_workers),
        max_attempts: args.job_max_attempts,
        lease: Duration::from_secs(args.job_lease_secs),
        ..JobsConfig::default()
    };
    let jobs = Jobs::new(JobRegistry::production(), config);
    let mut state = seatrial::http::AppState::with_jobs(
        db.clone(),
        &blob_dir,
        args.max_upload_mb * 1024 * 1024,
        jobs.clone(),
    )?;
    let listener = tokio::net::TcpListener::bind(args.listen).await?;
    let exposure = seatrial::http::exposure::Exposure::local(Some(listener.local_addr()?))
        .allow_hosts(&args.allowed_hosts)
        .allow_origins(&args.allowed_origins);
    if exposure.any_host() {
        tracing::warn!("--allowed-hosts '*': any Host header is answered (no DNS-rebinding guard)");
    } else if args.listen.ip().is_unspecified() && args.allowed_hosts.is_empty() {
        tracing::warn!(
            "listening on every interface, but only localhost names are answered: \
             add the names clients use with --allowed-hosts"
        );
    }
    tracing::info!(hosts = ?exposure.hosts(), "answering to these host names");
    state.exposure = std::sync::Arc::new(exposure);
    let mut auth =
        seatrial::http::auth::AuthConfig::for_listen(args.auth == AuthMode::Required, args.listen);
    auth.secure_cookie = args.cookie_secure;
    if auth.required {
        let password = match &args.admin_password_file {
            Some(f) => Some(
                std::fs::read_to_string(f)
                    .map_err(|e| anyhow::anyhow!("--admin-password-file {}: {e}", f.display()))?
                    .trim_end_matches(['\r', '\n'])
                    .to_string(),
            ),
            None => None,
        };
        let generated = args.admin_password_file.is_none();
        if let Some(pw) = seatrial::http::auth::users::bootstrap_admin(&db, password).await? {
            if generated {
                // Printed once, never logged elsewhere nor stored in clear.
                println!(
                    "created the first account: user 'admin', one-time password {pw} \
                     (change it with POST /api/auth/password)"
                );
            } else {
                tracing::info!("created the first account 'admin' with the password of the file");
            }
        }
        tracing::info!("credentials required (sign in, or Authorization: Bearer <token>)");
    } else {
        tracing::warn!(
            "local mode: requests without credentials act as the local admin \
             (loopback only; --auth required to turn it off)"
        );
    }
    state.auth = std::sync::Arc::new(auth);
    // A stopped server's debris: partial uploads go, runs it left `stored`
    // are processed in the background (listed now, before any new upload).
    let debris = seatrial::intake::sweep(&db, &state.blobs).await?;
    if !debris.stored_runs.is_empty() {
        tracing::info!(
            runs = debris.stored_runs.len(),
            "processing runs a stopped server left stored"
        );
        let (db, blobs) = (db.clone(), state.blobs.clone());
        tokio::spawn(async move { debris.reprocess(&db, &blobs).await });
    }
    // Recovers jobs a previous server left running, then starts the workers.
    // The job workers load, write and compute on their own runtime, over
    // their own connections.
    let mut cx = state.job_context();
    cx.db = {
        let path = args.db.clone();
        jobs_rt
            .spawn(async move { seatrial::storage::open(&path).await })
            .await??
    };
    let runner = jobs_rt
        .spawn(seatrial::jobs::start(jobs.clone(), cx))
        .await??;
    let app = seatrial::http::app(state, args.web_dir);
    let addr = listener.local_addr()?;
    tracing::info!("seatrial listening on http://{addr}");
    println!("seatrial listening on http://{addr}");
    // One signal stops everything: the listener, the event streams (they
    // would hold the graceful shutdown open) and the runner.
    let stop = jobs.shutdown_token().clone();
    tokio::spawn({
        let stop = stop.clone();
        async move {
            shutdown().await;
            tracing::info!("shutting down");
            stop.cancel();
        }
    });
    axum::serve(listener, app)
        .with_graceful_shutdown(stop.cancelled_owned())
        .await?;
    // Running jobs are neither cancelled nor failed: they unwind and are
    // queued again at once, no attempt spent (see seatrial::jobs, "Restarts").
    let _ = jobs_rt
        .spawn(runner.shutdown(Duration::from_secs(10)))
        .await;
    let _ = tokio::time::timeout(Duration::from_secs(5), db.close()).await;
    // A computation that ignored the stop still holds a blocking thread,
    // which the runtime would wait for; its job is safe in the database.
    std::process::exit(0);
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
