//! Campaign identification: from stored runs (records plus what the plan says
//! they were) to a validated model document. Pure orchestration over the
//! estimators of [`crate::estimation`] and [`crate::validation`].
//!
//! - [`dataset`]: runs → segments (one per valid block, never concatenated).
//! - [`document`]: the stored/served model: matrices, parameters with std.
//! - [`discrete`]: ZOH matrices at a chosen h.
//! - [`export`]: parameter CSV and the Fossen-form parameter set.

pub mod dataset;
pub mod discrete;
pub mod document;
pub mod export;

pub use dataset::{DatasetError, RunInput, Segment, segments};
pub use document::{Method, ModelDocument, ModelKind, ParameterRow};
