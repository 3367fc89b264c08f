//! Missing-physics discovery: locate where a baseline model and the
//! recordings part, name the left-out physics, model it.
//!
//! (work in progress)

pub mod candidates;
pub mod data;
pub mod discover;
pub mod error;
pub mod evidence;
pub mod experiment;
pub mod fit;
pub mod locate;
pub mod model;
pub mod report;
pub mod residual;
pub mod select;
pub mod svf;

pub use candidates::{Effect, Family, LibrarySettings, RestoringShape};
pub use data::{Baseline, Record, Restoring};
pub use discover::{DiscoverySettings, discover};
pub use error::DiscoveryError;
pub use experiment::ExperimentProposal;
pub use model::{AugmentedModel, ModelTerm};
pub use report::DiscoveryReport;

#[cfg(test)]
mod tests;
