//! Two-way fork–join for the heavy stages of the quality report: the
//! service's machines have two cores, and a report is one request.
//!
//! Callers split their work at points fixed by the input alone (never by
//! timing or by the pool's size), so a result is the same whether the
//! halves ran on one thread or two. The halves run on rayon's persistent
//! pool ([`rayon::join`]): no thread is started per call.

/// `(a(), b())`: both on rayon's pool when `parallel` (worth a hand-off,
/// tens of microseconds), else one after the other on the caller's
/// thread. A panic in either half reaches the caller.
pub(crate) fn join<RA, RB>(
    parallel: bool,
    a: impl FnOnce() -> RA + Send,
    b: impl FnOnce() -> RB + Send,
) -> (RA, RB)
where
    RA: Send,
    RB: Send,
{
    if parallel {
        rayon::join(a, b)
    } else {
        (a(), b())
    }
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
