//! Proof tests of the λ-filter identification against known truths.
