//! Maximum-length pseudo-random binary sequences (m-sequences).
//!
//! An n-stage linear-feedback shift register (LFSR) whose feedback polynomial
//! is *primitive* over GF(2) walks through all 2ⁿ − 1 nonzero states before
//! repeating (Golomb, *Shift Register Sequences*). Its output bit stream, an
//! m-sequence, is the classical identification input (Ljung §13.3, Godfrey
//! 1993) because, mapped to ±1, one period of length M = 2ⁿ − 1
//!
//! - has 2ⁿ⁻¹ ones and 2ⁿ⁻¹ − 1 zeros (one more +1 than −1), so its mean is
//!   nearly zero;
//! - has the two-valued periodic autocorrelation R(0) = M, R(k) = −1 for
//!   k ≠ 0 (mod M), i.e. it is as close to periodic white noise as a binary
//!   signal can be, with a flat power spectrum out to about 0.44/T_c;
//! - is persistently exciting of order M when played one sample per chip.
//!
//! Feedback taps come from Xilinx XAPP052 (Alfke, 1996), Table 3, which lists
//! a maximal-length tap set for every register length; the table is verified
//! algebraically (primitivity of the polynomial) in the tests for every order
//! 2..=32 and by brute-force period counting for orders 3..=24.

use serde::{Deserialize, Serialize};

use super::{
    SignalError, check_clock_period, chip_index, require_finite, require_non_negative,
    sample_count, try_vec,
};

/// Smallest supported register length.
pub const MIN_ORDER: u32 = 2;
/// Largest supported register length.
pub const MAX_ORDER: u32 = 32;

/// Feedback taps (1-based register positions, XAPP052 numbering) of a
/// maximal-length LFSR for each order `MIN_ORDER..=MAX_ORDER`. The taps
/// `{n, t₂, …}` correspond to the primitive polynomial `1 + Σ x^t`.
const TAPS: [&[u32]; (MAX_ORDER - MIN_ORDER + 1) as usize] = [
    &[2, 1],
    &[3, 2],
    &[4, 3],
    &[5, 3],
    &[6, 5],
    &[7, 6],
    &[8, 6, 5, 4],
    &[9, 5],
    &[10, 7],
    &[11, 9],
    &[12, 6, 4, 1],
    &[13, 4, 3, 1],
    &[14, 5, 3, 1],
    &[15, 14],
    &[16, 15, 13, 4],
    &[17, 14],
    &[18, 11],
    &[19, 6, 2, 1],
    &[20, 17],
    &[21, 19],
    &[22, 21],
    &[23, 18],
    &[24, 23, 22, 17],
    &[25, 22],
    &[26, 6, 2, 1],
    &[27, 5, 2, 1],
    &[28, 25],
    &[29, 27],
    &[30, 6, 4, 1],
    &[31, 28],
    &[32, 22, 2, 1],
];

/// Check that `order` is a supported register length.
fn check_order(order: u32) -> Result<(), SignalError> {
    if (MIN_ORDER..=MAX_ORDER).contains(&order) {
        Ok(())
    } else {
        Err(SignalError::invalid(
            "order",
            format!("register length must be in {MIN_ORDER}..={MAX_ORDER}, got {order}"),
        ))
    }
}

/// Period 2ⁿ − 1 of an m-sequence of order n (n ≤ 32, so it fits in u64).
fn period_of(order: u32) -> u64 {
    (1u64 << order) - 1
}

/// A Fibonacci LFSR of length n.
///
/// Bit i of `state` holds the output i steps ahead, so the output is bit 0
/// and the fed-back bit enters at bit n − 1. Tap t (1-based, XAPP052
/// numbering) reads bit n − t, giving the recurrence
/// a(k+n) = ⊕ₜ a(k+n−t): characteristic polynomial `xⁿ + Σ x^(n−t)`, the
/// reciprocal of `1 + Σ xᵗ`; a polynomial is primitive iff its reciprocal is,
/// so the register is maximal-length exactly when the table entry is.
#[derive(Debug, Clone)]
pub(crate) struct Lfsr {
    state: u64,
    mask: u64,
    top: u32,
}

impl Lfsr {
    /// A register of length `order` started at the nonzero state
    /// `(seed mod (2ⁿ − 1)) + 1`: every seed is valid, and seeds that differ
    /// by a multiple of 2ⁿ − 1 start identically.
    pub(crate) fn new(order: u32, seed: u64) -> Result<Self, SignalError> {
        check_order(order)?;
        let taps = TAPS[(order - MIN_ORDER) as usize];
        let mask = taps.iter().fold(0u64, |m, &t| m | (1u64 << (order - t)));
        Ok(Lfsr {
            state: seed % period_of(order) + 1,
            mask,
            top: order - 1,
        })
    }

    /// Current register contents (never zero).
    #[cfg(test)]
    pub(crate) fn state(&self) -> u64 {
        self.state
    }

    /// Return the current output bit and advance the register one step.
    #[inline]
    pub(crate) fn step(&mut self) -> bool {
        let out = self.state & 1 == 1;
        let feedback = (self.state & self.mask).count_ones() as u64 & 1;
        self.state = (self.state >> 1) | (feedback << self.top);
        out
    }
}

/// Map an LFSR output bit to a chip value: 1 → +1, 0 → −1.
#[inline]
fn chip(bit: bool) -> i8 {
    if bit { 1 } else { -1 }
}

/// One full period (length 2ⁿ − 1) of the ±1 m-sequence of register length
/// `order`.
///
/// `seed` selects the initial register state `(seed mod (2ⁿ − 1)) + 1`, so
/// every seed is valid and different seeds give cyclic shifts of the same
/// sequence. Output bit 1 maps to +1 and 0 to −1, so the period contains
/// 2ⁿ⁻¹ values +1 and 2ⁿ⁻¹ − 1 values −1.
///
/// Orders 2..=32 are supported; note that order 32 is a 4 GiB vector.
///
/// # Errors
/// `order` outside 2..=32, or the period cannot be allocated.
pub fn mls(order: u32, seed: u64) -> Result<Vec<i8>, SignalError> {
    let mut reg = Lfsr::new(order, seed)?;
    let m = usize::try_from(period_of(order)).map_err(|_| {
        SignalError::too_large(
            "order",
            format!("a period of order {order} does not fit in memory"),
        )
    })?;
    let mut out = try_vec::<i8>("order", m)?;
    out.extend((0..m).map(|_| chip(reg.step())));
    Ok(out)
}

/// Parameters of a sampled PRBS excitation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PrbsSpec {
    /// LFSR register length n; the sequence repeats every 2ⁿ − 1 chips.
    pub order: u32,
    /// Duration T_c of one chip (the shift-register clock), in seconds. The
    /// power spectrum is flat (within 3 dB) up to about 0.44/T_c.
    pub clock_period_s: f64,
    /// Half the peak-to-peak swing: the signal takes `offset ± amplitude`.
    pub amplitude: f64,
    /// Operating point the signal is centred on.
    pub offset: f64,
    /// Selects the initial register state (see [`mls`]).
    pub seed: u64,
}

/// Sample a PRBS at `sample_rate_hz` for `duration_s` seconds.
///
/// Returns `round(duration·fs)` samples with values `offset ± amplitude`.
/// Sample k (time k·h, h = 1/fs) holds chip `floor(k·h/T_c + 10⁻⁹)` of the
/// m-sequence of [`mls`]`(order, seed)`, wrapping around after 2ⁿ − 1 chips;
/// the 10⁻⁹ slack puts a chip boundary that falls on a sample instant at that
/// sample, as exact arithmetic would.
///
/// # Errors
/// With the offending field named: `order` outside 2..=32; any non-finite
/// value; `sample_rate_hz` or `duration_s` not positive (or shorter than one
/// sample); `clock_period_s` shorter than one sample (chips would be skipped)
/// or longer than `duration_s` (clock slower than the run); negative
/// `amplitude`.
pub fn prbs(
    spec: &PrbsSpec,
    sample_rate_hz: f64,
    duration_s: f64,
) -> Result<Vec<f64>, SignalError> {
    check_order(spec.order)?;
    let n = sample_count(sample_rate_hz, duration_s)?;
    check_clock_period(spec.clock_period_s, sample_rate_hz, duration_s)?;
    require_non_negative("amplitude", spec.amplitude)?;
    require_finite("offset", spec.offset)?;

    let samples_per_chip = spec.clock_period_s * sample_rate_hz;
    let high = spec.offset + spec.amplitude;
    let low = spec.offset - spec.amplitude;

    // Generate chips lazily: the register is periodic, so stepping it past
    // 2ⁿ − 1 chips wraps around the period by itself, and no full period
    // (up to 4 GiB for order 32) is ever materialised.
    let mut reg = Lfsr::new(spec.order, spec.seed)?;
    let mut current_bit = reg.step();
    let mut current_chip: u64 = 0;
    let mut out = try_vec::<f64>("duration_s", n)?;
    for k in 0..n {
        let idx = chip_index(k, samples_per_chip);
        while current_chip < idx {
            current_bit = reg.step();
            current_chip += 1;
        }
        out.push(if current_bit { high } else { low });
    }
    Ok(out)
}

#[cfg(test)]
mod tests;
