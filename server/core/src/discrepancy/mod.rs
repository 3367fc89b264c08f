//! Missing-physics discovery: locate where a baseline model and the
//! recordings part, name the left-out physics, model it.
//!
//! (work in progress)

pub mod candidates;
pub mod data;
pub mod error;
pub mod fit;
pub mod model;
pub mod residual;
pub mod select;
pub mod svf;

pub use candidates::{Effect, Family, LibrarySettings, RestoringShape};
pub use data::{Baseline, Record, Restoring};
pub use error::DiscoveryError;
pub use model::{AugmentedModel, ModelTerm};

#[cfg(test)]
mod tests;
