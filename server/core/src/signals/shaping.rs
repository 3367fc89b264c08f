//! Shaping excitation to actuator limits.
//!
//! Thrusters and rudders have a maximum thrust/angle and a maximum rate of
//! change (pitch or rpm slew, steering gear speed). A command that violates
//! them is not what the vessel actually receives, so the identified model
//! would be fitted to the wrong input. The excitation is therefore passed
//! through the same saturations the actuator applies: a slew-rate limiter
//! (the actuator follows a too-fast step with a ramp of the maximum rate) and
//! an amplitude clip.
//!
//! These functions return plain vectors and never panic; degenerate
//! parameters have the documented, conservative meaning instead of an error.

/// Slew-rate limit `x`, sampled at `sample_rate_hz`, to `max_rate_per_s`
/// units per second, starting from the actuator position `initial`.
///
/// Each output sample moves from the previous one (from `initial` for the
/// first) toward the target `x[k]` by at most δ = `max_rate_per_s`/fs, and
/// lands exactly on the target when it is within δ. This is the discrete
/// rate limiter y(k) = y(k−1) + sat_δ(x(k) − y(k−1)); a step of size s is
/// therefore followed by a ramp of slope `max_rate_per_s` lasting
/// [`min_slew_time`]`(s, max_rate_per_s)`. Rounding is handled so that
/// |y(k) − y(k−1)| ≤ δ holds in floating point too.
///
/// Degenerate parameters (no panic, no error):
/// - a step δ that is NaN or not positive (rate ≤ 0 or NaN, sample rate ≤ 0,
///   NaN or infinite) means "the actuator cannot move": the output holds
///   `initial`;
/// - an infinite rate (with a finite positive sample rate) means no limit;
/// - a NaN target sample is ignored (the output holds its previous value);
/// - a non-finite `initial` means the starting position is unknown: the
///   limiter starts at the first finite target.
pub fn rate_limit(x: &[f64], max_rate_per_s: f64, sample_rate_hz: f64, initial: f64) -> Vec<f64> {
    let delta = max_rate_per_s / sample_rate_hz;
    let delta = if delta.is_nan()
        || delta <= 0.0
        || !(sample_rate_hz.is_finite() && sample_rate_hz > 0.0)
    {
        0.0
    } else {
        delta
    };
    let mut prev = if initial.is_finite() {
        Some(initial)
    } else {
        None
    };
    x.iter()
        .map(|&target| {
            let y = match prev {
                None => {
                    if target.is_finite() {
                        target
                    } else {
                        return initial;
                    }
                }
                Some(p) => slew_step(p, target, delta),
            };
            prev = Some(y);
            y
        })
        .collect()
}

/// One rate-limited step from `prev` toward `target`, by at most `delta`.
fn slew_step(prev: f64, target: f64, delta: f64) -> f64 {
    if target.is_nan() {
        return prev;
    }
    let diff = target - prev;
    if diff.abs() <= delta {
        return target;
    }
    let mut y = if diff > 0.0 {
        prev + delta
    } else {
        prev - delta
    };
    // prev ± delta is rounded; pull back by ulps until the realised step is
    // within delta, so the limit holds exactly in floating point.
    if diff > 0.0 {
        while y - prev > delta {
            y = y.next_down();
        }
    } else {
        while prev - y > delta {
            y = y.next_up();
        }
    }
    y
}

/// Clip every sample of `x` to the interval [`lo`, `hi`].
///
/// Degenerate bounds (no panic): the bounds are used in order, so `lo > hi`
/// is treated as [`hi`, `lo`]; a NaN bound means "no limit on that side". NaN
/// samples are passed through unchanged (clipping cannot invent a value).
pub fn clip(x: &[f64], lo: f64, hi: f64) -> Vec<f64> {
    let (lo, hi) = if lo > hi { (hi, lo) } else { (lo, hi) };
    x.iter()
        .map(|&v| {
            if v < lo {
                lo
            } else if v > hi {
                hi
            } else {
                v
            }
        })
        .collect()
}

/// Shortest time, in seconds, an actuator limited to `max_rate_per_s` needs
/// to move by `step` (either sign): |step| / rate.
///
/// Returns 0 for a zero step, +∞ when the rate is zero or negative (the
/// actuator cannot move), and NaN when either input is NaN.
pub fn min_slew_time(step: f64, max_rate_per_s: f64) -> f64 {
    if step.is_nan() || max_rate_per_s.is_nan() {
        return f64::NAN;
    }
    if step == 0.0 {
        return 0.0;
    }
    if max_rate_per_s <= 0.0 {
        return f64::INFINITY;
    }
    step.abs() / max_rate_per_s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn max_rate(y: &[f64], initial: f64, fs: f64) -> f64 {
        let mut prev = initial;
        let mut m = 0.0_f64;
        for &v in y {
            m = m.max((v - prev).abs() * fs);
            prev = v;
        }
        m
    }

    #[test]
    fn rate_limit_respects_the_rate_exactly() {
        // A rough, large-amplitude signal with awkward rates.
        let fs = 10.0;
        let rate = 0.7;
        let mut s = 12345u64;
        let x: Vec<f64> = (0..5000)
            .map(|_| {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((s >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 200.0
            })
            .collect();
        for initial in [0.0, 37.3, -1e3] {
            let y = rate_limit(&x, rate, fs, initial);
            assert_eq!(y.len(), x.len());
            assert!(
                max_rate(&y, initial, fs) <= rate + 1e-12,
                "initial {initial}"
            );
        }
        // Also for values far from zero, where rounding is coarser.
        let x: Vec<f64> = (0..200)
            .map(|k| 1e4 + if k % 20 < 10 { 5.0 } else { -5.0 })
            .collect();
        let y = rate_limit(&x, 0.3, 7.0, 1e4);
        assert!(max_rate(&y, 1e4, 7.0) <= 0.3 + 1e-12);
    }

    #[test]
    fn rate_limit_ramp_is_analytic_and_reaches_the_target() {
        // Dyadic numbers (exact in binary): step 0 → 5 at 2.5/s, fs = 10 Hz,
        // δ = 0.25. y(k) = 0.25·(k+1) until 5, reached after
        // min_slew_time = 2 s = 20 samples, then held exactly.
        let fs = 10.0;
        let y = rate_limit(&[5.0; 30], 2.5, fs, 0.0);
        let n_ramp = (min_slew_time(5.0, 2.5) * fs).round() as usize;
        assert_eq!(n_ramp, 20);
        for (k, &v) in y.iter().enumerate() {
            assert_eq!(v, (0.25 * (k + 1) as f64).min(5.0), "sample {k}");
        }
        assert!(y[n_ramp - 2] < 5.0 && y[n_ramp - 1] == 5.0);

        // Non-dyadic rate: the ramp matches 0.2·(k+1) to rounding and the
        // target is reached within one sample of min_slew_time.
        let y = rate_limit(&[5.0; 40], 2.0, fs, 0.0);
        for (k, &v) in y.iter().enumerate() {
            let expected = (0.2 * (k + 1) as f64).min(5.0);
            assert!(
                (v - expected).abs() < 1e-12,
                "sample {k}: {v} vs {expected}"
            );
        }
        let n_ramp = (min_slew_time(5.0, 2.0) * fs).round() as usize;
        assert!(y[n_ramp..].iter().all(|&v| v == 5.0));

        // Downward step, and a target already within one step is hit exactly.
        let y = rate_limit(&[-1.0; 10], 2.5, fs, 0.0);
        assert_eq!(&y[..5], &[-0.25, -0.5, -0.75, -1.0, -1.0]);
        assert_eq!(rate_limit(&[0.15], 2.0, fs, 0.0), vec![0.15]);
    }

    #[test]
    fn rate_limit_passes_slow_signals_unchanged() {
        let x: Vec<f64> = (0..100).map(|k| (k as f64 * 0.01).sin()).collect();
        assert_eq!(rate_limit(&x, 1.0, 1.0, 0.0), x);
        assert_eq!(rate_limit(&x, f64::INFINITY, 10.0, 0.0), x);
        assert!(rate_limit(&[], 1.0, 10.0, 0.0).is_empty());
    }

    #[test]
    fn rate_limit_degenerate_parameters_are_safe() {
        let x = [1.0, 2.0, 3.0];
        for (rate, fs) in [
            (0.0, 10.0),
            (-1.0, 10.0),
            (f64::NAN, 10.0),
            (1.0, 0.0),
            (1.0, f64::NAN),
            (1.0, f64::INFINITY),
        ] {
            assert_eq!(
                rate_limit(&x, rate, fs, 0.5),
                vec![0.5; 3],
                "rate {rate}, fs {fs}"
            );
        }
        // NaN target holds; non-finite initial starts at the first finite target.
        assert_eq!(
            rate_limit(&[1.0, f64::NAN, 1.0], 1.0, 1.0, 0.0),
            vec![1.0, 1.0, 1.0]
        );
        let y = rate_limit(&[f64::NAN, 4.0, 10.0], 1.0, 1.0, f64::NAN);
        assert!(y[0].is_nan());
        assert_eq!(&y[1..], &[4.0, 5.0]);
    }

    #[test]
    fn clip_limits_amplitude() {
        assert_eq!(
            clip(&[-3.0, -1.0, 0.5, 2.0, 9.0], -1.0, 2.0),
            vec![-1.0, -1.0, 0.5, 2.0, 2.0]
        );
        // Reversed bounds are reordered; NaN bound is open; NaN sample passes.
        assert_eq!(clip(&[-3.0, 9.0], 2.0, -1.0), vec![-1.0, 2.0]);
        assert_eq!(clip(&[-3.0, 9.0], f64::NAN, 2.0), vec![-3.0, 2.0]);
        assert!(clip(&[f64::NAN], 0.0, 1.0)[0].is_nan());
    }

    #[test]
    fn min_slew_time_is_step_over_rate() {
        assert_eq!(min_slew_time(5.0, 2.0), 2.5);
        assert_eq!(min_slew_time(-5.0, 2.0), 2.5);
        assert_eq!(min_slew_time(0.0, 0.0), 0.0);
        assert_eq!(min_slew_time(1.0, 0.0), f64::INFINITY);
        assert_eq!(min_slew_time(1.0, -3.0), f64::INFINITY);
        assert!(min_slew_time(f64::NAN, 1.0).is_nan());
        assert!(min_slew_time(1.0, f64::NAN).is_nan());
    }
}
