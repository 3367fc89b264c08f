//! Trial logs: the CSV contract, parsing with exact error locations,
//! plausibility warnings, gaps, and resampling onto a uniform grid.
//!
//! # The log format (the contract)
//!
//! CSV, comma-separated, one header row, SI units and radians, NED/body
//! frames as in Fossen. Columns by name, in any order:
//!
//! | columns | meaning |
//! |---|---|
//! | `t` | time (s), strictly increasing |
//! | `tau_X tau_Y tau_Z tau_K tau_M tau_N` | generalized forces (N, N·m) |
//! | `thr_1 … thr_n` | thruster commands, instead of τ for thruster-actuated vessels (or shaft speed, pitch or thrust, as the profile's `signal` says: [`thruster_signals`]) |
//! | `u v w p q r` | body velocities (m/s, rad/s) |
//! | `x y z phi theta psi` | pose (m, rad) |
//!
//! A vessel's file carries the columns of its modeled DOFs only (a 3-DOF DP
//! vessel: `tau_X tau_Y tau_N` or `thr_*`; `u v r`; `x y psi`); see
//! [`schema::required_columns`]; a DP vessel needs its pose or its
//! velocities, not necessarily both. The heading may be declared in degrees
//! (`HeadingUnit`). Missing required columns are an error; other
//! columns are kept when fully numeric and ignored otherwise.
//!
//! A run may instead come as two files from unsynchronized computers: a
//! control log ([`LogRole::Control`]: `t`, inputs, a shared channel such as
//! depth `z`) and a navigation log ([`LogRole::Nav`]: `t`, velocities, pose,
//! the same shared channel).
//!
//! # Pipeline
//!
//! [`parse_log`] (a reader the caller opened → [`ParsedLog`] with warnings
//! and gaps, or the first defect as a [`LogError`] with file, line and
//! column), then [`to_uniform`] (→ [`UniformRecord`](crate::timeseries::UniformRecord)).
//! Gaps up to [`MAX_BRIDGE_SAMPLES`] (5) samples are interpolated; longer
//! gaps split the run and their samples are not used
//! (see [`uniform`]). The warning rules are in [`checks`].

pub mod checks;
pub mod error;
pub mod gaps;
pub mod measurements;
pub mod parse;
pub mod schema;
pub mod thruster_signals;
pub mod uniform;

pub use checks::LogWarning;
pub use error::{LogError, LogErrorKind};
pub use gaps::{Gap, MAX_BRIDGE_SAMPLES};
pub use parse::{DEFAULT_MAX_COLUMNS, DEFAULT_MAX_ROWS, ParseOptions, ParsedLog, parse_log};
pub use schema::{
    LogRole, input_columns, measurement_groups, output_columns, pose_columns, required_columns,
    strict_columns,
};
pub use thruster_signals::{
    CommandedInput, ThrusterReading, commanded_columns, commanded_inputs, read_thruster_commands,
};
pub use uniform::{MAX_RATE_HZ, MIN_RATE_HZ, check_rate_hz, to_uniform, zoh};
