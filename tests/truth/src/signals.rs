//! Excitation signals as a trial team programs them (thesis §3.3: square
//! waves of long enough period, or random binary signals): a square wave, a
//! maximum-length PRBS, and a ramped staircase of forward speeds.

/// What shape an excitation has (for the truth metadata).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SignalKind {
    /// No excitation: a held operating point.
    Constant,
    /// A square wave.
    Square,
    /// A pseudo-random binary sequence.
    Prbs,
    /// Several signals at once (validation runs).
    Mixed,
}

impl SignalKind {
    /// `constant`, `square`, `prbs`, `mixed`.
    pub fn label(self) -> &'static str {
        match self {
            SignalKind::Constant => "constant",
            SignalKind::Square => "square",
            SignalKind::Prbs => "prbs",
            SignalKind::Mixed => "mixed",
        }
    }
}

/// A zero-mean excitation of amplitude `amp` around an operating point.
#[derive(Debug, Clone, PartialEq)]
pub enum Signal {
    /// ±amp, starting at sign `start`, switching every `half_period_s`.
    Square {
        /// Amplitude.
        amp: f64,
        /// Half period (s).
        half_period_s: f64,
        /// +1 or −1: the first level.
        start: f64,
    },
    /// ±amp from a 9-bit maximum-length LFSR (x⁹ + x⁵ + 1, period 511 bits),
    /// one bit every `bit_s` seconds.
    Prbs {
        /// Amplitude.
        amp: f64,
        /// Bit duration (s).
        bit_s: f64,
        /// The bits, precomputed (one full period).
        bits: Vec<bool>,
    },
}

impl Signal {
    /// A PRBS from a nonzero 9-bit register `seed`.
    pub fn prbs(amp: f64, bit_s: f64, seed: u16) -> Signal {
        let mut reg: u16 = (seed & 0x1FF).max(1);
        let bits = (0..511)
            .map(|_| {
                let new = ((reg >> 8) ^ (reg >> 4)) & 1; // taps 9 and 5
                reg = ((reg << 1) | new) & 0x1FF;
                new == 1
            })
            .collect();
        Signal::Prbs { amp, bit_s, bits }
    }

    /// Value at run time `t` (s); 0 before the run starts.
    pub fn at(&self, t: f64) -> f64 {
        if t < 0.0 {
            return 0.0;
        }
        match self {
            Signal::Square {
                amp,
                half_period_s,
                start,
            } => {
                let k = (t / half_period_s).floor() as i64;
                if k % 2 == 0 {
                    start * amp
                } else {
                    -start * amp
                }
            }
            Signal::Prbs { amp, bit_s, bits } => {
                let k = (t / bit_s).floor() as usize % bits.len();
                if bits[k] { *amp } else { -*amp }
            }
        }
    }

    /// The amplitude.
    pub fn amplitude(&self) -> f64 {
        match self {
            Signal::Square { amp, .. } | Signal::Prbs { amp, .. } => *amp,
        }
    }

    /// Half period (square) or bit time (PRBS) (s).
    pub fn switch_time_s(&self) -> f64 {
        match self {
            Signal::Square { half_period_s, .. } => *half_period_s,
            Signal::Prbs { bit_s, .. } => *bit_s,
        }
    }

    /// Square or PRBS.
    pub fn kind(&self) -> SignalKind {
        match self {
            Signal::Square { .. } => SignalKind::Square,
            Signal::Prbs { .. } => SignalKind::Prbs,
        }
    }
}

/// Forward-speed staircase: `levels[k]` from `k · segment_s`, each change
/// ramped at `ramp_rate` (m/s²) so the surge loop does not saturate.
#[derive(Debug, Clone, PartialEq)]
pub struct Staircase {
    /// Speeds in flying order (m/s).
    pub levels: Vec<f64>,
    /// Duration of each level (s).
    pub segment_s: f64,
    /// Ramp rate between levels (m/s²).
    pub ramp_rate: f64,
}

impl Staircase {
    /// Reference speed at run time `t` (s).
    pub fn at(&self, t: f64) -> f64 {
        let n = self.levels.len();
        let k = ((t.max(0.0) / self.segment_s).floor() as usize).min(n - 1);
        if k == 0 {
            return self.levels[0];
        }
        let (from, to) = (self.levels[k - 1], self.levels[k]);
        let since = t - k as f64 * self.segment_s;
        let ramp = (to - from).abs() / self.ramp_rate;
        if since >= ramp {
            to
        } else {
            from + (to - from) * since / ramp
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prbs_is_maximum_length_and_balanced() {
        let Signal::Prbs { bits, .. } = Signal::prbs(1.0, 1.0, 0x1A5) else {
            unreachable!()
        };
        let ones = bits.iter().filter(|b| **b).count();
        assert_eq!(ones, 256, "an m-sequence of 511 bits has 256 ones");
    }

    #[test]
    fn square_alternates_and_staircase_ramps() {
        let s = Signal::Square {
            amp: 2.0,
            half_period_s: 10.0,
            start: -1.0,
        };
        assert_eq!(s.at(5.0), -2.0);
        assert_eq!(s.at(15.0), 2.0);
        let st = Staircase {
            levels: vec![1.0, 2.0],
            segment_s: 100.0,
            ramp_rate: 0.1,
        };
        assert_eq!(st.at(50.0), 1.0);
        assert!((st.at(105.0) - 1.5).abs() < 1e-12);
        assert_eq!(st.at(150.0), 2.0);
    }
}
