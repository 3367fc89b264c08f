//! Proof tests of the λ-filter identification against known truths.

mod analytic;
mod calibration;
mod errors;
mod errors_in_variables;
mod exogenous;
mod multi;
mod rov;
mod truth;
