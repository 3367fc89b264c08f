//! The process's two async runtimes. Job workers (their data loading, their
//! database writes, their computations' blocking threads) run on a runtime
//! of their own, so HTTP load cannot queue a job's awaits behind thousands
//! of requests; and the HTTP runtime's threads run at a lower CPU priority
//! (Linux nice [`HTTP_NICE`]), so a core-saturating stream of reads slows
//! the reads, not the identification a supervisor is waiting for.

use tokio::runtime::{Builder, Runtime};

/// Nice value of the HTTP threads (jobs and the main thread keep 0).
pub const HTTP_NICE: i32 = 10;

/// The runtime that serves HTTP: one worker per core, threads `seatrial-http`
/// at nice [`HTTP_NICE`] (their blocking threads inherit it).
pub fn http() -> std::io::Result<Runtime> {
    Builder::new_multi_thread()
        .enable_all()
        .thread_name("seatrial-http")
        .on_thread_start(|| set_nice(HTTP_NICE))
        .build()
}

/// Starts rayon's global pool (the numerics' fork–join, see
/// `server/core/src/par.rs`): one thread per core, `seatrial-compute-N` at nice
/// 0. Called first from the main thread, so that no HTTP thread (nice
/// [`HTTP_NICE`]) starts it and hands its priority down.
pub fn compute_pool() -> std::io::Result<()> {
    rayon::ThreadPoolBuilder::new()
        .thread_name(|i| format!("seatrial-compute-{i}"))
        .start_handler(|_| set_nice(0))
        .build_global()
        .map_err(std::io::Error::other)
}

/// The runtime of the job workers: one async thread, threads `seatrial-jobs`
/// at nice 0 (the computations' blocking threads are spawned from it).
pub fn jobs() -> std::io::Result<Runtime> {
    Builder::new_multi_thread()
        .worker_threads(1)
        .enable_all()
        .thread_name("seatrial-jobs")
        .on_thread_start(|| set_nice(0))
        .build()
}

/// Sets the calling thread's nice value (Linux: per thread). Raising it
/// needs no privilege; where it fails or elsewhere, the thread keeps its own.
#[cfg(target_os = "linux")]
fn set_nice(nice: i32) {
    // SAFETY: gettid and setpriority take no pointers; a failure only leaves
    // the thread's priority as it was.
    unsafe {
        let _ = libc::setpriority(libc::PRIO_PROCESS, libc::gettid() as libc::id_t, nice);
    }
}

#[cfg(not(target_os = "linux"))]
fn set_nice(_nice: i32) {}

/// The calling thread's nice value (Linux), for tests.
#[cfg(target_os = "linux")]
pub fn current_nice() -> Option<i32> {
    // SAFETY: as in `set_nice`; errno is cleared first because -1 is a valid
    // nice value.
    unsafe {
        *libc::__errno_location() = 0;
        let n = libc::getpriority(libc::PRIO_PROCESS, libc::gettid() as libc::id_t);
        (*libc::__errno_location() == 0).then_some(n)
    }
}

/// The calling thread's nice value (not known off Linux).
#[cfg(not(target_os = "linux"))]
pub fn current_nice() -> Option<i32> {
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[cfg(target_os = "linux")]
    #[test]
    fn http_threads_yield_to_job_threads() {
        let http = http().unwrap();
        let jobs = jobs().unwrap();
        let on_http =
            http.block_on(async { tokio::spawn(async { current_nice() }).await.unwrap() });
        let on_http_blocking =
            http.block_on(async { tokio::task::spawn_blocking(current_nice).await.unwrap() });
        let on_jobs_blocking = jobs.block_on(async {
            tokio::spawn(async { tokio::task::spawn_blocking(current_nice).await.unwrap() })
                .await
                .unwrap()
        });
        let base = current_nice().expect("Linux");
        assert_eq!(on_http, Some(HTTP_NICE.max(base)));
        assert_eq!(on_http_blocking, Some(HTTP_NICE.max(base)));
        // Jobs ask for nice 0: granted when privileged (root), else they
        // keep the process's own (a test run under `nice` has base > 0).
        assert!(
            on_jobs_blocking == Some(0) || on_jobs_blocking == Some(base),
            "jobs at nice {on_jobs_blocking:?}, process at {base}"
        );
    }
}
