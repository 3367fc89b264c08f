//! Tests of alignment against known truth (seeded generators in
//! `test_support.rs`).

mod calibration;
mod merge;
mod offset;
mod pool;
