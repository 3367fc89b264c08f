//! Square waves for step-response experiments.
//!
//! A square wave is a train of alternating steps. For a step experiment each
//! level must be held until the response has settled, so that both the
//! transient (time constant, delay) and the steady-state gain are observable.
//! For a first-order lag with time constant T the step response after a hold
//! of t is 1 − e^(−t/T): 5·T gives 1 − e⁻⁵ ≈ 99.3 %, i.e. within 1 % of steady
//! state, which is the usual "settled" criterion; see
//! [`square_period_for_time_constant`].

use serde::{Deserialize, Serialize};

use super::{
    GRID_EPS, SignalError, require_finite, require_non_negative, require_positive, sample_count,
    try_vec,
};

/// Parameters of a sampled square wave.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SquareSpec {
    /// Full period (one high half plus one low half), in seconds.
    pub period_s: f64,
    /// Half the peak-to-peak swing: the signal takes `offset ± amplitude`.
    pub amplitude: f64,
    /// Operating point the signal is centred on.
    pub offset: f64,
    /// Time shift, in seconds: the sample at time t takes the value the
    /// unshifted wave has at t + `phase_s` (0 starts at the high level; half
    /// a period starts low). May be negative.
    pub phase_s: f64,
}

/// Sample a square wave at `sample_rate_hz` for `duration_s` seconds.
///
/// Returns `round(duration·fs)` samples. With `phase_s = 0` the wave starts
/// at `offset + amplitude` for the first half-period, then alternates.
/// Sample k (time t = k·h) is high when `floor((t + phase_s)/(P/2) + 10⁻⁹)`
/// is even; the 10⁻⁹ slack assigns a switching instant that falls on a
/// sample to the new level, as exact arithmetic would.
///
/// # Errors
/// With the offending field named: non-finite values; `sample_rate_hz` or
/// `duration_s` not positive; `period_s` not positive, or with a half-period
/// shorter than one sample (the wave would alias) or not shorter than the run
/// (no level change would be guaranteed); negative `amplitude`.
pub fn square(
    spec: &SquareSpec,
    sample_rate_hz: f64,
    duration_s: f64,
) -> Result<Vec<f64>, SignalError> {
    let n = sample_count(sample_rate_hz, duration_s)?;
    require_positive("period_s", spec.period_s)?;
    let half = spec.period_s / 2.0;
    let samples_per_half = half * sample_rate_hz;
    if samples_per_half < 1.0 - GRID_EPS {
        return Err(SignalError::invalid(
            "period_s",
            format!(
                "half-period {half} s is shorter than one sample ({} s at {sample_rate_hz} Hz)",
                1.0 / sample_rate_hz
            ),
        ));
    }
    if half >= duration_s {
        return Err(SignalError::invalid(
            "period_s",
            format!(
                "half-period {half} s is not shorter than the run ({duration_s} s): no level change"
            ),
        ));
    }
    require_non_negative("amplitude", spec.amplitude)?;
    require_finite("offset", spec.offset)?;
    require_finite("phase_s", spec.phase_s)?;

    let high = spec.offset + spec.amplitude;
    let low = spec.offset - spec.amplitude;
    let phase_halves = spec.phase_s / half;
    let mut out = try_vec::<f64>("duration_s", n)?;
    out.extend((0..n).map(|k| {
        let halves = (k as f64 / samples_per_half + phase_halves + GRID_EPS).floor();
        if halves.rem_euclid(2.0) == 0.0 {
            high
        } else {
            low
        }
    }));
    Ok(out)
}

/// Square-wave period for a step experiment on a process whose dominant time
/// constant is `time_constant_s`: **10·T**.
///
/// Rule: hold each level for 5·T. A first-order response then reaches
/// 1 − e⁻⁵ ≈ 99.3 % of its final value before the next step, so every level
/// reaches a measurable steady state (gain is identifiable, not only the
/// transient). In the frequency domain, the fundamental 1/(10T) = 0.1/T lies
/// below the corner frequency 1/(2πT) ≈ 0.159/T, while the 3rd and 5th
/// harmonics (0.3/T, 0.5/T) lie above it, so the strong low-order lines of
/// the wave straddle the corner where the model's dynamics are decided.
///
/// The input is not validated (this returns a plain number): a non-positive
/// or non-finite time constant yields a period that [`square`] rejects.
pub fn square_period_for_time_constant(time_constant_s: f64) -> f64 {
    10.0 * time_constant_s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(period_s: f64) -> SquareSpec {
        SquareSpec {
            period_s,
            amplitude: 3.0,
            offset: 1.0,
            phase_s: 0.0,
        }
    }

    /// Lengths of consecutive runs of equal values.
    fn run_lengths(x: &[f64]) -> Vec<usize> {
        let mut runs = Vec::new();
        let mut len = 1;
        for w in x.windows(2) {
            if w[1] == w[0] {
                len += 1;
            } else {
                runs.push(len);
                len = 1;
            }
        }
        runs.push(len);
        runs
    }

    #[test]
    fn starts_high_and_alternates_with_exact_values() {
        let x = square(&spec(2.0), 10.0, 6.0).unwrap();
        assert_eq!(x.len(), 60);
        for (k, &v) in x.iter().enumerate() {
            let expected = if (k / 10) % 2 == 0 { 4.0 } else { -2.0 };
            assert_eq!(v, expected, "sample {k}");
        }
    }

    #[test]
    fn half_periods_have_the_right_number_of_samples() {
        // Integer: 7 samples per half-period.
        let x = square(&spec(1.4), 10.0, 14.0).unwrap();
        assert_eq!(run_lengths(&x), vec![7; 20]);
        // Non-integer: 7.5 samples per half-period → boundaries at 7.5, 15,
        // 22.5, … so runs alternate 8, 7.
        let x = square(&spec(1.5), 10.0, 6.0).unwrap();
        assert_eq!(run_lengths(&x), vec![8, 7, 8, 7, 8, 7, 8, 7]);
        // Exactly one sample per half-period is allowed: +,−,+,−,…
        let x = square(&spec(0.2), 10.0, 1.0).unwrap();
        assert_eq!(
            x,
            vec![4.0, -2.0, 4.0, -2.0, 4.0, -2.0, 4.0, -2.0, 4.0, -2.0]
        );
    }

    #[test]
    fn phase_shifts_the_wave() {
        let base = square(&spec(2.0), 10.0, 10.0).unwrap();
        // Half a period: starts low, i.e. the negated wave about the offset.
        let half = square(
            &SquareSpec {
                phase_s: 1.0,
                ..spec(2.0)
            },
            10.0,
            10.0,
        )
        .unwrap();
        for (a, b) in base.iter().zip(&half) {
            assert_eq!(a - 1.0, -(b - 1.0));
        }
        // Positive shift of 0.3 s (3 samples) advances the wave; a negative
        // shift of a full period is a no-op.
        let adv = square(
            &SquareSpec {
                phase_s: 0.3,
                ..spec(2.0)
            },
            10.0,
            10.0,
        )
        .unwrap();
        assert_eq!(&adv[..97], &base[3..]);
        let neg = square(
            &SquareSpec {
                phase_s: -2.0,
                ..spec(2.0)
            },
            10.0,
            10.0,
        )
        .unwrap();
        assert_eq!(neg, base);
        let lag = square(
            &SquareSpec {
                phase_s: -0.4,
                ..spec(2.0)
            },
            10.0,
            10.0,
        )
        .unwrap();
        assert_eq!(&lag[4..], &base[..96]);
        assert!(lag[..4].iter().all(|&v| v == -2.0));
    }

    #[test]
    fn period_rule_is_ten_time_constants() {
        assert_eq!(square_period_for_time_constant(2.0), 20.0);
        assert_eq!(square_period_for_time_constant(0.35), 3.5);
        let t = 1.7;
        let p = square_period_for_time_constant(t);
        // Each level is held 5·T: a first-order step reaches ≥ 99.3 %.
        assert!((p / 2.0 - 5.0 * t).abs() < 1e-12);
        assert!(1.0 - (-(p / 2.0) / t).exp() > 0.993);
        // Fundamental below the corner 1/(2πT); 3rd and 5th harmonics above.
        let corner = 1.0 / (2.0 * std::f64::consts::PI * t);
        assert!(1.0 / p < corner && 3.0 / p > corner && 5.0 / p > corner);
    }

    /// Drive an exactly discretised first-order lag with the rule's square
    /// wave: at the end of every half-period (after the first) the output is
    /// within 1 % of the swing from the level it is heading to.
    #[test]
    fn rule_lets_a_first_order_lag_settle_every_half_period() {
        let tau = 3.0;
        let fs = 20.0;
        let s = SquareSpec {
            period_s: square_period_for_time_constant(tau),
            amplitude: 1.0,
            offset: 0.0,
            phase_s: 0.0,
        };
        let u = square(&s, fs, 4.0 * s.period_s).unwrap();
        let a = (-1.0 / (fs * tau)).exp();
        let mut y = 0.0;
        let mut ys = Vec::with_capacity(u.len());
        for &uk in &u {
            // Zero-order hold: the input is constant over each sample.
            y = a * y + (1.0 - a) * uk;
            ys.push(y);
        }
        let half = (s.period_s / 2.0 * fs).round() as usize;
        for end in (2 * half - 1..u.len()).step_by(half) {
            let err = (ys[end] - u[end]).abs() / (2.0 * s.amplitude);
            assert!(err < 0.01, "half-period ending at {end}: residual {err}");
        }
    }

    #[test]
    fn square_reports_each_invalid_field() {
        let ok = spec(2.0);
        let field =
            |s: &SquareSpec, fs: f64, d: f64| square(s, fs, d).unwrap_err().field().to_owned();
        assert_eq!(field(&spec(0.0), 10.0, 10.0), "period_s");
        assert_eq!(field(&spec(-2.0), 10.0, 10.0), "period_s");
        assert_eq!(field(&spec(f64::NAN), 10.0, 10.0), "period_s");
        assert_eq!(field(&spec(0.1), 10.0, 10.0), "period_s"); // half-period < one sample
        assert_eq!(field(&spec(20.0), 10.0, 10.0), "period_s"); // no level change
        assert_eq!(
            field(
                &SquareSpec {
                    amplitude: -1.0,
                    ..ok.clone()
                },
                10.0,
                10.0
            ),
            "amplitude"
        );
        assert_eq!(
            field(
                &SquareSpec {
                    offset: f64::INFINITY,
                    ..ok.clone()
                },
                10.0,
                10.0
            ),
            "offset"
        );
        assert_eq!(
            field(
                &SquareSpec {
                    phase_s: f64::NAN,
                    ..ok.clone()
                },
                10.0,
                10.0
            ),
            "phase_s"
        );
        assert_eq!(field(&ok, 0.0, 10.0), "sample_rate_hz");
        assert_eq!(field(&ok, 10.0, -1.0), "duration_s");
        assert_eq!(field(&ok, 10.0, f64::NAN), "duration_s");
    }

    #[test]
    fn square_spec_round_trips_through_serde() {
        let s = SquareSpec {
            phase_s: -0.25,
            ..spec(4.0)
        };
        let back: SquareSpec = serde_json::from_str(&serde_json::to_string(&s).unwrap()).unwrap();
        assert_eq!(back, s);
    }
}
