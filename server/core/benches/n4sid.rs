//! Benchmark placeholder (work in progress).
fn main() {}
