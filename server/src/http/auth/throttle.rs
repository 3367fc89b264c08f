//! Bounds on password checks: failed sign-ins per account name back off,
//! and at most one argon2 verification per core runs at a time.
//!
//! Each verification costs 19 MiB and tens of milliseconds of CPU (argon2id
//! defaults, [`super::secrets`]): unbounded, a burst of sign-ins would
//! exhaust memory, and free retries let anyone guess passwords at the rate
//! the CPU allows. After [`FREE_FAILURES`] wrong passwords for a name, each
//! further attempt must wait `2^(n − FREE_FAILURES)` s since the last
//! failure (at most [`MAX_WAIT`]); an attempt during the wait is answered
//! 429 with `Retry-After`, without checking the password. A success clears
//! the name. Counted per name (lower-cased), whether or not the account
//! exists, so the answers do not reveal which names exist.

use std::collections::HashMap;
use std::sync::Mutex;
use std::time::{Duration, Instant};

use tokio::sync::{Semaphore, SemaphorePermit};

use crate::error::ApiError;

/// Wrong passwords allowed for a name before attempts must wait.
pub const FREE_FAILURES: u32 = 5;

/// Longest wait between attempts.
pub const MAX_WAIT: Duration = Duration::from_secs(15 * 60);

/// A name's failures are forgotten this long after the last one.
const FORGET_AFTER: Duration = Duration::from_secs(60 * 60);

/// Names tracked at most (oldest forgotten first when full).
const MAX_NAMES: usize = 10_000;

/// Failed attempts of one name.
#[derive(Debug, Clone, Copy)]
struct Failures {
    count: u32,
    last: Instant,
}

impl Failures {
    /// How long after `last` the next attempt must wait.
    fn wait(&self) -> Duration {
        if self.count < FREE_FAILURES {
            return Duration::ZERO;
        }
        let exp = (self.count - FREE_FAILURES).min(20);
        Duration::from_secs(1u64 << exp).min(MAX_WAIT)
    }
}

/// Sign-in throttle of one service.
#[derive(Debug)]
pub struct LoginThrottle {
    failures: Mutex<HashMap<String, Failures>>,
    hashing: Semaphore,
}

impl Default for LoginThrottle {
    fn default() -> Self {
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        LoginThrottle {
            failures: Mutex::new(HashMap::new()),
            hashing: Semaphore::new(cores),
        }
    }
}

fn key(name: &str) -> String {
    name.chars().take(200).collect::<String>().to_lowercase()
}

impl LoginThrottle {
    /// Refuses an attempt for `name` during its wait (429 naming the
    /// account and the seconds left).
    pub fn check(&self, name: &str, now: Instant) -> Result<(), ApiError> {
        let map = self.failures.lock().unwrap_or_else(|e| e.into_inner());
        let Some(f) = map.get(&key(name)) else {
            return Ok(());
        };
        let ready = f.last + f.wait();
        if now >= ready {
            return Ok(());
        }
        let secs = (ready - now).as_secs_f64().ceil().max(1.0) as u64;
        Err(ApiError::TooManyRequests {
            message: format!(
                "{} failed sign-ins for '{}'; try again in {secs} s",
                f.count,
                seatrial_core::numbers::escape_controls(&key(name))
            ),
            retry_after_s: secs,
        })
    }

    /// Records a wrong password for `name`.
    pub fn failed(&self, name: &str, now: Instant) {
        let mut map = self.failures.lock().unwrap_or_else(|e| e.into_inner());
        if map.len() >= MAX_NAMES {
            map.retain(|_, f| now.saturating_duration_since(f.last) < FORGET_AFTER);
            if map.len() >= MAX_NAMES
                && let Some(oldest) = map
                    .iter()
                    .min_by_key(|(_, f)| f.last)
                    .map(|(k, _)| k.clone())
            {
                map.remove(&oldest);
            }
        }
        let f = map.entry(key(name)).or_insert(Failures {
            count: 0,
            last: now,
        });
        if now.saturating_duration_since(f.last) >= FORGET_AFTER {
            f.count = 0;
        }
        f.count = f.count.saturating_add(1);
        f.last = now;
    }

    /// Clears `name` after a correct password.
    pub fn succeeded(&self, name: &str) {
        let mut map = self.failures.lock().unwrap_or_else(|e| e.into_inner());
        map.remove(&key(name));
    }

    /// A permit to run one password verification (one per core at a time;
    /// waits its turn).
    pub async fn hashing_permit(&self) -> Result<SemaphorePermit<'_>, ApiError> {
        self.hashing
            .acquire()
            .await
            .map_err(|e| ApiError::Internal(anyhow::anyhow!("password check permits: {e}")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn five_failures_are_free_then_the_wait_doubles() {
        let t = LoginThrottle::default();
        let t0 = Instant::now();
        for i in 0..FREE_FAILURES {
            assert!(t.check("Ann", t0).is_ok(), "attempt {i}");
            t.failed("Ann", t0);
        }
        // Sixth attempt: 1 s after the fifth failure.
        let err = t.check("ann", t0).unwrap_err();
        match err {
            ApiError::TooManyRequests {
                retry_after_s,
                ref message,
            } => {
                assert_eq!(retry_after_s, 1);
                assert!(message.contains("5 failed sign-ins for 'ann'"), "{message}");
            }
            e => panic!("{e:?}"),
        }
        assert!(t.check("ann", t0 + Duration::from_secs(1)).is_ok());
        t.failed("ann", t0 + Duration::from_secs(1));
        // Now 2 s.
        assert!(t.check("ann", t0 + Duration::from_millis(2500)).is_err());
        assert!(t.check("ann", t0 + Duration::from_secs(3)).is_ok());
        // Another name is not affected; a success clears the name.
        assert!(t.check("bob", t0).is_ok());
        t.succeeded("ANN");
        assert!(t.check("ann", t0 + Duration::from_secs(1)).is_ok());
    }

    #[test]
    fn the_wait_is_capped_and_old_failures_are_forgotten() {
        let t = LoginThrottle::default();
        let t0 = Instant::now();
        for _ in 0..40 {
            t.failed("x", t0);
        }
        match t.check("x", t0).unwrap_err() {
            ApiError::TooManyRequests { retry_after_s, .. } => {
                assert_eq!(retry_after_s, MAX_WAIT.as_secs())
            }
            e => panic!("{e:?}"),
        }
        let later = t0 + FORGET_AFTER;
        assert!(t.check("x", later).is_ok());
        t.failed("x", later);
        assert!(t.check("x", later).is_ok(), "count restarted at 1");
    }

    #[test]
    fn the_map_stays_bounded() {
        let t = LoginThrottle::default();
        let t0 = Instant::now();
        for i in 0..MAX_NAMES + 50 {
            t.failed(&format!("n{i}"), t0 + Duration::from_millis(i as u64));
        }
        let map = t.failures.lock().unwrap();
        assert_eq!(map.len(), MAX_NAMES);
        assert!(!map.contains_key("n0"), "the oldest went first");
    }
}
