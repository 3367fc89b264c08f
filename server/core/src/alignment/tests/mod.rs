//! Tests of alignment against known truth (seeded generators in
//! `test_support.rs`).

mod merge;
mod offset;
