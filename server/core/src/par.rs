//! Two-way fork–join for the heavy stages of the quality report: the
//! service's machines have two cores, and a report is one request.
//!
//! Callers split their work at points fixed by the input alone (never by
//! timing), so a result does not depend on whether the second thread ran:
//! [`join`] falls back to running both halves on the calling thread when
//! the machine has one core or a thread cannot be started.

use std::sync::{Mutex, OnceLock};

/// Cores available to this process (1 when unknown), read once.
fn cores() -> usize {
    static CORES: OnceLock<usize> = OnceLock::new();
    *CORES.get_or_init(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
}

/// `(a(), b())`, with `b` on a scoped second thread when `parallel` and
/// the machine has more than one core. A panic in either is resumed on
/// the caller's thread.
pub(crate) fn join<RA, RB>(
    parallel: bool,
    a: impl FnOnce() -> RA + Send,
    b: impl FnOnce() -> RB + Send,
) -> (RA, RB)
where
    RA: Send,
    RB: Send,
{
    if !parallel || cores() < 2 {
        return (a(), b());
    }
    // `b` waits in a slot: the thread takes it when it starts; the caller
    // takes it back when it is done with `a` first (on a busy machine the
    // thread may not have been scheduled yet) or no thread could start.
    let slot = Mutex::new(Some(b));
    let take = || slot.lock().ok().and_then(|mut s| s.take());
    std::thread::scope(|s| {
        let handle = std::thread::Builder::new().spawn_scoped(s, || take().map(|b| b()));
        let ra = a();
        let here = take().map(|b| b());
        let there = match handle {
            Ok(h) => match h.join() {
                Ok(rb) => rb,
                Err(panic) => std::panic::resume_unwind(panic),
            },
            Err(_) => None,
        };
        let rb = here.or(there);
        (ra, rb.expect("the second half runs exactly once"))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_halves_run_once_in_either_mode() {
        for parallel in [false, true] {
            let v: Vec<u64> = (0..1000).collect();
            let (lo, hi) = join(
                parallel,
                || v[..500].iter().sum::<u64>(),
                || v[500..].iter().sum::<u64>(),
            );
            assert_eq!(lo + hi, 499_500);
        }
    }

    #[test]
    fn a_panic_in_the_second_half_reaches_the_caller() {
        let r = std::panic::catch_unwind(|| join(true, || 1, || -> i32 { panic!("boom") }));
        assert!(r.is_err());
    }
}
