//! Clock alignment of two logs written by unsynchronized computers.
//!
//! A sea-trial run often comes as two files: the controller log (time, the
//! commanded inputs `tau_*` / `thr_*`, and a channel it also measures, e.g.
//! depth `z`) and the navigation (INS/DVL) log (time, velocities, pose and
//! the same channel). Their clocks differ by an unknown offset and their
//! sample rates differ. This module finds the offset from the channel both
//! computers recorded and merges the two logs onto one uniform grid.
//!
//! Clock convention, used everywhere here: **`offset_s` is added to
//! navigation time stamps to put them on the control clock** — the nav sample
//! stamped `t_nav` was taken at control time `t_nav + offset_s`. The merged
//! record lives on the control clock.
//!
//! - [`estimate_offset`] (file `offset.rs`): FFT normalized cross-correlation
//!   for the integer lag, then a sub-sample refinement that minimizes the
//!   mismatch over a continuous offset; a calibrated standard deviation
//!   (the local error widened to cover every offset the data cannot tell
//!   from the best), whether the estimate is `informative` and why, and a
//!   confidence grade.
//! - [`align_logs`] / [`align_logs_with`] (file `merge.rs`): estimate, choose
//!   the offset ([`choose_offset`]: hand-set for the run, for the campaign,
//!   pooled when the pool holds the run's own estimate, own if informative,
//!   pooled, weak own), shift, resample both logs onto one grid over the
//!   overlap, and report in plain words.
//! - [`pool_offsets`] (file `pool.rs`): one campaign offset from its runs'
//!   informative estimates, outliers left out and named.
//!
//! Measured on seeded synthetic runs (10 min, 30 dB SNR, ±1 % stamp jitter,
//! control 10 Hz vs nav 10/20/25 Hz): worst offset error 0.058 samples of
//! the slower log over 27 cases. Calibration over 240 runs of six kinds,
//! excitation runs to static holds and periodic heave, offsets within
//! ±60 s: 238 within ±2σ, the informative ones 89/91 (rms error/σ 0.91,
//! worst 0.036 s); pooled over 8 campaigns of 13 runs: within 1.5 ms of the
//! truth, and so every run that shares the campaign's clocks
//! (`tests/calibration.rs`, `tests/pool.rs`). On 75 campaigns of the
//! independent truth (`seatrial-truth`): the own ±2σ of 17 of 599
//! informative runs and the pooled ±2σ of 3 campaigns missed the truth.
//! One hour of 50 Hz navigation vs 10 Hz control (`cargo bench --bench
//! alignment`): 0.32 s for the estimate, 0.33 s for the whole merge,
//! measured on a machine shared with other builds (0.09 s and 0.11 s were
//! measured before the ambiguity test, on an idle one).
//!
//! Internals, one responsibility per file: `validate` (input checks),
//! `grid` (uniform resampling and detrending for the correlation), `xcorr`
//! (FFT normalized cross-correlation and peak analysis), `bandwidth` (the
//! band both logs share, from their coherence), `kernel` (the Gaussian
//! prefilter of the refinement), `hermite` (cubic interpolation), `brent`
//! (1-D minimization), `refine` (sub-sample refinement and its standard
//! error), `ambiguity` (offsets that fit as well as the best),
//! `calibrate` (σ, informative, reason), `decide` (which offset a run is
//! merged with), `pool` (the campaign's offset), `resample` (merging rules:
//! zero-order hold, cell averages, linear; gaps), `drift` (clock-drift
//! check), `warnings` (the report's words), `error` ([`AlignError`]).

mod ambiguity;
mod bandwidth;
mod brent;
mod calibrate;
mod decide;
mod drift;
mod error;
mod grid;
mod hermite;
mod kernel;
mod merge;
mod offset;
mod pool;
mod refine;
mod resample;
mod validate;
mod warnings;
mod xcorr;

#[cfg(test)]
mod test_support;
#[cfg(test)]
mod tests;

pub use decide::{
    Chosen, MAX_USER_OFFSET_S, OffsetPriors, OffsetSource, PooledValue, check_user_offset,
    choose_offset,
};
pub use error::AlignError;
pub use merge::{AlignmentReport, align_logs, align_logs_with};
pub use offset::{Confidence, OffsetEstimate, OffsetOptions, estimate_offset};
pub use pool::{OUTLIER_Z, PooledOffset, RejectedRun, RunOffset, pool_offsets};
pub use warnings::offset_words;
