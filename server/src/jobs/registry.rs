//! The job kinds this server can run, built once at start-up.

use std::collections::BTreeMap;
use std::sync::Arc;

use super::handler::JobHandler;

/// Handlers by kind.
#[derive(Clone, Default)]
pub struct JobRegistry {
    handlers: BTreeMap<String, Arc<dyn JobHandler>>,
}

impl JobRegistry {
    /// No kinds.
    pub fn new() -> Self {
        Self::default()
    }

    /// The production kinds: `identify` (campaign runs → a validated,
    /// versioned model) and `discover` (a model and its runs → the missing
    /// physics, and the augmented model as its next version) and
    /// `precision` (a plan and a prior → each parameter's predicted std) and
    /// `design` (a campaign, a prior and a budget → the plan that buys the
    /// most precision in those hours) and `next_dive` (the flown runs and
    /// a dive's hours → the planned runs to fly next).
    pub fn production() -> Self {
        Self::new()
            .with("identify", super::identify::Identify)
            .with("discover", super::discover::Discover)
            .with("precision", super::precision::Precision)
            .with("design", super::design::Design)
            .with("next_dive", super::next_dive::NextDiveJob)
    }

    /// Adds (or replaces) the handler of `kind`.
    pub fn register(&mut self, kind: impl Into<String>, handler: impl JobHandler) -> &mut Self {
        self.handlers.insert(kind.into(), Arc::new(handler));
        self
    }

    /// Builder form of [`register`](Self::register).
    pub fn with(mut self, kind: impl Into<String>, handler: impl JobHandler) -> Self {
        self.register(kind, handler);
        self
    }

    /// The handler of `kind`.
    pub fn get(&self, kind: &str) -> Option<Arc<dyn JobHandler>> {
        self.handlers.get(kind).cloned()
    }

    /// Registered kinds, sorted.
    pub fn kinds(&self) -> Vec<&str> {
        self.handlers.keys().map(String::as_str).collect()
    }
}

impl std::fmt::Debug for JobRegistry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("JobRegistry")
            .field("kinds", &self.kinds())
            .finish()
    }
}
