//! Campaign identification: from stored runs (records plus what the plan says
//! they were) to a validated model document. Pure orchestration over the
//! estimators of [`crate::estimation`] and [`crate::validation`].

pub mod dataset;

pub use dataset::{DatasetError, RunInput, Segment, segments};
