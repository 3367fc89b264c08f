//! The shape of one reference channel and its sampling. A waveform is a
//! normalized signal w(t) (mostly in [−1, 1]); the channel's reference is
//! offset + amplitude·w(t), then slew-limited and clipped to the limits.

use serde::{Deserialize, Serialize};

use crate::signals;

/// A reference waveform with every parameter needed to regenerate it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(tag = "shape", rename_all = "snake_case")]
pub enum Waveform {
    /// Held at the operating point.
    Constant,
    /// Slew to offset + sign·amplitude and hold (static experiments).
    Step {
        /// +1 or −1.
        sign: f64,
    },
    /// Maximum-length PRBS: register order n, clock period T_c, the m-sequence
    /// of `seed` rotated by `shift_chips` (channels of one run use shifts M/k
    /// apart, so they are uncorrelated at every lag below M/k chips).
    Prbs {
        /// Register order n (period 2ⁿ−1 chips).
        order: u32,
        /// Chip length T_c (s).
        clock_period_s: f64,
        /// Seed of the register state.
        seed: u64,
        /// Cyclic shift in chips.
        shift_chips: usize,
    },
    /// Square wave ±1 starting high; period 10·T by default.
    Square {
        /// Period (s).
        period_s: f64,
    },
    /// Schroeder multisine over the harmonics of 1/period in [f_lo, f_hi].
    Multisine {
        /// Lowest frequency (Hz).
        f_lo_hz: f64,
        /// Highest frequency (Hz).
        f_hi_hz: f64,
        /// Period (s).
        period_s: f64,
    },
    /// i.i.d. ±1 levels held for a clock period.
    RandomBinary {
        /// Clock period (s).
        clock_period_s: f64,
        /// Seed.
        seed: u64,
    },
    /// Validation pattern: per segment, a constant part then a random-binary
    /// part ("constant as well as changing speeds", thesis sec. 3.5).
    ConstantThenRandom {
        /// Segment length (s).
        segment_s: f64,
        /// Fraction of each segment held constant.
        constant_fraction: f64,
        /// Clock of the random part (s).
        clock_period_s: f64,
        /// Seed.
        seed: u64,
    },
    /// Steps through absolute levels (used for surge: the grid speeds), one
    /// segment each; `amplitude` is ignored and offset is not added.
    Staircase {
        /// Levels, in the channel's unit.
        levels: Vec<f64>,
        /// Segment length (s).
        segment_s: f64,
    },
}

impl Waveform {
    /// Samples `offset + amplitude·w(t)` at `fs` for `n` samples, before shaping.
    pub fn sample(
        &self,
        offset: f64,
        amplitude: f64,
        fs: f64,
        n: usize,
    ) -> Result<Vec<f64>, signals::SignalError> {
        let duration = n as f64 / fs;
        let h = 1.0 / fs;
        let mut x = match self {
            Waveform::Constant => vec![offset; n],
            Waveform::Step { sign } => vec![offset + sign * amplitude; n],
            Waveform::Prbs {
                order,
                clock_period_s,
                seed,
                shift_chips,
            } => {
                let seq = signals::mls(*order, *seed)?;
                let m = seq.len();
                (0..n)
                    .map(|k| {
                        // 1e-9 guards against k·h/T_c landing a hair below an integer.
                        let chip = ((k as f64 * h) / clock_period_s + 1e-9).floor() as usize;
                        offset + amplitude * f64::from(seq[(chip + shift_chips) % m])
                    })
                    .collect()
            }
            Waveform::Square { period_s } => signals::square(
                &signals::SquareSpec {
                    period_s: *period_s,
                    amplitude,
                    offset,
                    phase_s: 0.0,
                },
                fs,
                duration,
            )?,
            Waveform::Multisine {
                f_lo_hz,
                f_hi_hz,
                period_s,
            } => signals::multisine(
                *f_lo_hz, *f_hi_hz, *period_s, amplitude, offset, fs, duration,
            )?,
            Waveform::RandomBinary {
                clock_period_s,
                seed,
            } => signals::random_binary(*clock_period_s, amplitude, offset, *seed, fs, duration)?,
            Waveform::ConstantThenRandom {
                segment_s,
                constant_fraction,
                clock_period_s,
                seed,
            } => {
                let rb = signals::random_binary(
                    *clock_period_s,
                    amplitude,
                    offset,
                    *seed,
                    fs,
                    duration,
                )?;
                (0..n)
                    .map(|k| {
                        let t = k as f64 * h;
                        let within = (t % segment_s) / segment_s;
                        if within < *constant_fraction {
                            offset
                        } else {
                            rb[k]
                        }
                    })
                    .collect()
            }
            Waveform::Staircase { levels, segment_s } => (0..n)
                .map(|k| {
                    let seg = ((k as f64 * h) / segment_s + 1e-9).floor() as usize;
                    levels[seg.min(levels.len().saturating_sub(1))]
                })
                .collect(),
        };
        x.truncate(n);
        x.resize(n, offset);
        Ok(x)
    }

    /// True for waveforms meant to change over the run (dynamic content).
    pub fn is_dynamic(&self) -> bool {
        !matches!(self, Waveform::Constant | Waveform::Step { .. })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prbs_channels_are_shifted_copies() {
        let fs = 1.0;
        let a = Waveform::Prbs {
            order: 5,
            clock_period_s: 1.0,
            seed: 7,
            shift_chips: 0,
        }
        .sample(0.0, 1.0, fs, 31)
        .unwrap();
        let b = Waveform::Prbs {
            order: 5,
            clock_period_s: 1.0,
            seed: 7,
            shift_chips: 10,
        }
        .sample(0.0, 1.0, fs, 31)
        .unwrap();
        for k in 0..31 {
            assert_eq!(b[k], a[(k + 10) % 31]);
        }
        // Held chips: 4 samples per chip at fs = 4.
        let c = Waveform::Prbs {
            order: 5,
            clock_period_s: 1.0,
            seed: 7,
            shift_chips: 0,
        }
        .sample(2.0, 0.5, 4.0, 124)
        .unwrap();
        for k in 0..124 {
            assert_eq!(c[k], 2.0 + 0.5 * a[k / 4]);
        }
    }

    #[test]
    fn staircase_and_constant_then_random() {
        let s = Waveform::Staircase {
            levels: vec![1.0, 2.0, 3.0],
            segment_s: 2.0,
        }
        .sample(0.0, 0.0, 2.0, 12)
        .unwrap();
        assert_eq!(s, vec![1., 1., 1., 1., 2., 2., 2., 2., 3., 3., 3., 3.]);
        let v = Waveform::ConstantThenRandom {
            segment_s: 10.0,
            constant_fraction: 0.4,
            clock_period_s: 1.0,
            seed: 3,
        }
        .sample(0.5, 0.2, 1.0, 30)
        .unwrap();
        for (k, x) in v.iter().enumerate() {
            if k % 10 < 4 {
                assert_eq!(*x, 0.5);
            } else {
                assert!((x - 0.7).abs() < 1e-12 || (x - 0.3).abs() < 1e-12);
            }
        }
    }
}
