//! Progress reporting and cancellation for long estimations.
//!
//! The numerics stay free of threads and I/O: a job runner passes a
//! [`Progress`] sink, and the estimator calls it between units of work (a
//! filter pass, a grid point, a stage). Returning [`Cancelled`] unwinds the
//! estimation cleanly with `?`.

/// The user (or the server shutting down) asked the estimation to stop.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Cancelled;

impl std::fmt::Display for Cancelled {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("cancelled")
    }
}

impl std::error::Error for Cancelled {}

/// Receives progress (fraction 0–1 of the whole estimation, current stage)
/// and says whether to go on.
pub trait Progress {
    /// Reports progress; `Err(Cancelled)` asks the caller to stop.
    fn update(&mut self, fraction: f64, stage: &str) -> Result<(), Cancelled>;
}

/// Ignores progress and never cancels (tests, benches).
#[derive(Debug, Default, Clone, Copy)]
pub struct NoProgress;

impl Progress for NoProgress {
    fn update(&mut self, _fraction: f64, _stage: &str) -> Result<(), Cancelled> {
        Ok(())
    }
}

impl<F: FnMut(f64, &str) -> Result<(), Cancelled>> Progress for F {
    fn update(&mut self, fraction: f64, stage: &str) -> Result<(), Cancelled> {
        self(fraction, stage)
    }
}

/// The part `[start, start + width)` of a parent's progress: a sub-task
/// reports 0–1 and the parent sees its share.
pub struct SubProgress<'a> {
    parent: &'a mut dyn Progress,
    start: f64,
    width: f64,
}

impl<'a> SubProgress<'a> {
    /// The sub-range `[start, start + width]` of `parent` (a width, not
    /// an end).
    pub fn new(parent: &'a mut dyn Progress, start: f64, width: f64) -> Self {
        SubProgress {
            parent,
            start,
            width,
        }
    }
}

impl Progress for SubProgress<'_> {
    fn update(&mut self, fraction: f64, stage: &str) -> Result<(), Cancelled> {
        let f = fraction.clamp(0.0, 1.0);
        self.parent.update(self.start + self.width * f, stage)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sub_progress_maps_into_the_parents_range_and_cancels() {
        let mut seen = Vec::new();
        let mut parent = |f: f64, s: &str| {
            seen.push((f, s.to_string()));
            if f > 0.7 { Err(Cancelled) } else { Ok(()) }
        };
        let mut sub = SubProgress::new(&mut parent, 0.5, 0.25);
        assert!(sub.update(0.0, "a").is_ok());
        assert!(sub.update(1.0, "b").is_err());
        assert_eq!(seen, vec![(0.5, "a".to_string()), (0.75, "b".to_string())]);
    }
}
