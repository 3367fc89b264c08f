//! Two-way fork–join for the heavy stages of the quality report (the
//! service's machines have two cores, and a report is one request), and
//! [`fan_out`] for independent pieces of a job (discovery's grid speeds),
//! [`beside`] for a job's part that can run while the caller works.
//!
//! Callers split their work at points fixed by the input alone (never by
//! timing or by the pool's size), so a result is the same whether the
//! halves ran on one thread or two. The halves run on rayon's persistent
//! pool ([`rayon::join`]): no thread is started per call.

use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};

use crate::estimation::{Cancelled, Progress};

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

/// `task(k, progress)` for every k in `0..n`, as tasks on rayon's pool,
/// while the calling thread reports their combined progress to `progress`
/// (as its share `span`, never backwards; stage `"{stage} (d of n done)"`)
/// and passes a cancellation it returns on to every task.
///
/// The results come in index order, whatever ran where; the first error by
/// index is returned, and a cancellation when `progress` asked to stop.
/// The caller waits without working: it should not be a pool thread (a
/// job's blocking thread is not).
pub(crate) fn fan_out<T, E>(
    n: usize,
    progress: &mut dyn Progress,
    span: (f64, f64),
    stage: &str,
    task: impl Fn(usize, &mut dyn Progress) -> Result<T, E> + Sync,
) -> Result<Vec<T>, E>
where
    T: Send,
    E: Send + From<Cancelled>,
{
    let fractions: Vec<AtomicU64> = (0..n).map(|_| AtomicU64::new(0)).collect();
    let slots: Vec<Mutex<Option<Result<T, E>>>> = (0..n).map(|_| Mutex::new(None)).collect();
    let cancel = AtomicBool::new(false);
    let done = AtomicUsize::new(0);
    let caller = std::thread::current();
    let mut stopped = false;
    rayon::in_place_scope(|s| {
        for k in 0..n {
            let (fractions, slots, cancel, done, task, caller) =
                (&fractions, &slots, &cancel, &done, &task, &caller);
            s.spawn(move |_| {
                let mut relay = |f: f64, _: &str| {
                    let f = if f.is_finite() {
                        f.clamp(0.0, 1.0)
                    } else {
                        0.0
                    };
                    fractions[k].fetch_max(f.to_bits(), Ordering::Relaxed);
                    if cancel.load(Ordering::Relaxed) {
                        Err(Cancelled)
                    } else {
                        Ok(())
                    }
                };
                let r = if cancel.load(Ordering::Relaxed) {
                    Err(E::from(Cancelled))
                } else {
                    task(k, &mut relay)
                };
                fractions[k].store(1.0f64.to_bits(), Ordering::Relaxed);
                *slots[k].lock().unwrap_or_else(|e| e.into_inner()) = Some(r);
                done.fetch_add(1, Ordering::Release);
                caller.unpark();
            });
        }
        let width = span.1 - span.0;
        let mut last = span.0;
        loop {
            let d = done.load(Ordering::Acquire);
            // Non-negative f64 bits order as the values: `fetch_max` above
            // keeps each task's fraction monotone.
            let sum: f64 = fractions
                .iter()
                .map(|f| f64::from_bits(f.load(Ordering::Relaxed)))
                .sum();
            last = last.max((span.0 + width * sum / n.max(1) as f64).min(span.1));
            if !stopped
                && progress
                    .update(last, &format!("{stage} ({d} of {n} done)"))
                    .is_err()
            {
                stopped = true;
                cancel.store(true, Ordering::Relaxed);
            }
            if d == n {
                break;
            }
            std::thread::park_timeout(std::time::Duration::from_millis(100));
        }
    });
    if stopped {
        return Err(E::from(Cancelled));
    }
    slots
        .into_iter()
        .map(|m| {
            m.into_inner()
                .unwrap_or_else(|e| e.into_inner())
                .unwrap_or_else(|| Err(E::from(Cancelled)))
        })
        .collect()
}

/// `(main(progress), side(relay))`: `main` on the calling thread, `side`
/// meanwhile as a task on rayon's pool. The side reports nothing; its
/// `relay` asks it to stop once `progress` has asked `main` to. Returns
/// when both are done (a panic in either reaches the caller).
pub(crate) fn beside<A, B: Send>(
    progress: &mut dyn Progress,
    main: impl FnOnce(&mut dyn Progress) -> A,
    side: impl FnOnce(&mut dyn Progress) -> B + Send,
) -> (A, B) {
    let cancel = AtomicBool::new(false);
    let mut out = None;
    let a = rayon::in_place_scope(|s| {
        let (cancel, slot) = (&cancel, &mut out);
        s.spawn(move |_| {
            let mut relay = |_: f64, _: &str| {
                if cancel.load(Ordering::Relaxed) {
                    Err(Cancelled)
                } else {
                    Ok(())
                }
            };
            *slot = Some(side(&mut relay));
        });
        let mut watch = |f: f64, stage: &str| {
            let r = progress.update(f, stage);
            if r.is_err() {
                cancel.store(true, Ordering::Relaxed);
            }
            r
        };
        main(&mut watch)
    });
    (a, out.expect("the scope waits for its task"))
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

    /// Results in index order, the first error by index, progress within
    /// its span and never backwards, ending at the span's end.
    #[test]
    fn fan_out_keeps_order_and_reports_monotone_progress() {
        let mut seen: Vec<f64> = Vec::new();
        let mut sink = |f: f64, _: &str| {
            seen.push(f);
            Ok(())
        };
        let out: Result<Vec<usize>, Cancelled> = fan_out(7, &mut sink, (0.2, 0.8), "x", |k, p| {
            for i in 0..=4 {
                p.update(i as f64 / 4.0, "step")?;
                std::thread::sleep(std::time::Duration::from_millis(2 * (7 - k as u64)));
            }
            Ok(k * k)
        });
        assert_eq!(out.unwrap(), [0, 1, 4, 9, 16, 25, 36]);
        assert!(seen.windows(2).all(|w| w[1] >= w[0]), "{seen:?}");
        assert!(seen.iter().all(|f| (0.2..=0.8).contains(f)));
        assert!((seen.last().unwrap() - 0.8).abs() < 1e-12);

        #[derive(Debug, PartialEq)]
        enum E {
            Bad(usize),
            Stop,
        }
        impl From<Cancelled> for E {
            fn from(_: Cancelled) -> Self {
                E::Stop
            }
        }
        let r: Result<Vec<()>, E> = fan_out(
            5,
            &mut crate::estimation::NoProgress,
            (0.0, 1.0),
            "x",
            |k, _| {
                if k % 2 == 1 { Err(E::Bad(k)) } else { Ok(()) }
            },
        );
        assert_eq!(r.unwrap_err(), E::Bad(1));
    }

    /// A cancellation from the caller's progress reaches every task, and
    /// the result is a cancellation.
    #[test]
    fn fan_out_passes_a_cancellation_on() {
        let mut sink = |_: f64, _: &str| Err(Cancelled);
        let r: Result<Vec<()>, Cancelled> = fan_out(4, &mut sink, (0.0, 1.0), "x", |_, p| {
            for _ in 0..2000 {
                p.update(0.5, "step")?;
                std::thread::sleep(std::time::Duration::from_millis(1));
            }
            panic!("not stopped");
        });
        assert_eq!(r.unwrap_err(), Cancelled);
    }

    /// Both results; the side stops when the caller's progress stops the
    /// main part.
    #[test]
    fn beside_runs_both_and_passes_a_cancellation_on() {
        let mut sink = |_: f64, _: &str| Ok(());
        let (a, b) = beside(&mut sink, |p| p.update(0.5, "x").map(|_| 2), |_| 3);
        assert_eq!((a, b), (Ok(2), 3));

        let mut stop = |_: f64, _: &str| Err(Cancelled);
        let (a, b) = beside(
            &mut stop,
            |p| p.update(0.5, "x"),
            |p| {
                for _ in 0..5000 {
                    if p.update(0.0, "side").is_err() {
                        return Err(Cancelled);
                    }
                    std::thread::sleep(std::time::Duration::from_millis(1));
                }
                Ok(())
            },
        );
        assert_eq!((a, b), (Err(Cancelled), Err(Cancelled)));
    }

    #[test]
    fn a_panic_in_the_second_half_reaches_the_caller() {
        let r = std::panic::catch_unwind(|| join(true, || 1, || -> i32 { panic!("boom") }));
        assert!(r.is_err());
    }
}
