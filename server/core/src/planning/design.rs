//! Excitation design for one channel: amplitude, clock and shape from the
//! DOF's limits and expected time constant T, then the checks that make an
//! impossible request an error naming its field and limit.
//!
//! Rules (documented for the pilots in the run sheet):
//! - Square wave: each level held 5·T (≈ 99.3 % of a first-order step), so
//!   the period is 10·T; the fundamental 1/(10T) lies below the corner
//!   1/(2πT) and the 3rd harmonic above it.
//! - PRBS / random binary: clock T_c = T by default, so the −3 dB edge
//!   0.44/T_c sits at ≈ 2.8× the corner, and the longest run n·T_c lets the
//!   response settle. The register order is the smallest n ≥ 3 with
//!   (2ⁿ−1)·T_c ≥ the required duration, and the run lasts whole periods,
//!   where the m-sequence's balance and two-valued autocorrelation hold.
//! - Slewing 2·amplitude at the rate limit must take at most half a chip
//!   (or a quarter of a square-wave level), otherwise the rate-limited
//!   signal is no longer binary and the request is refused.

use super::campaign::SignalKind;
use super::error::PlanError;
use super::waveform::Waveform;

/// Hold time per square-wave level, in time constants.
pub const SQUARE_HOLD_TIME_CONSTANTS: f64 = 5.0;
/// Smallest PRBS order the planner uses.
pub const MIN_PRBS_ORDER: u32 = 3;
/// Largest PRBS order accepted in a request.
pub const MAX_PRBS_ORDER: u32 = 24;
/// A chip must last at least this many logger samples to be seen.
pub const MIN_LOGGER_SAMPLES_PER_CHIP: f64 = 2.0;

/// Largest seed: 2⁵³ − 1, so seeds survive JSON in JavaScript clients exactly.
pub const MAX_SEED: u64 = (1 << 53) - 1;

/// What the designer needs to know about the channel.
#[derive(Debug, Clone)]
pub struct ChannelRequest<'a> {
    /// JSON path prefix for errors, e.g. `excitation.per_dof.sway`.
    pub field: &'a str,
    /// Shape.
    pub signal: SignalKind,
    /// Expected time constant T (s).
    pub time_constant_s: f64,
    /// Amplitude already checked against the limit.
    pub amplitude: f64,
    /// Slew-rate limit of the channel (unit/s), if any.
    pub rate_limit: Option<f64>,
    /// Field path of the rate limit, for messages.
    pub rate_field: &'a str,
    /// User override of the clock (s).
    pub clock_period_s: Option<f64>,
    /// User override of the PRBS order.
    pub prbs_order: Option<u32>,
    /// Required run length (s).
    pub min_duration_s: f64,
    /// Logger rate (Hz).
    pub logger_rate_hz: f64,
    /// Seed for this channel's sequence.
    pub seed: u64,
    /// Channel index within its run and number of channels (for PRBS shifts
    /// and distinct square/multisine periods).
    pub channel: (usize, usize),
}

/// A designed channel: its waveform and the run length it asks for.
#[derive(Debug, Clone)]
pub struct ChannelDesign {
    /// Waveform.
    pub waveform: Waveform,
    /// Run length this channel needs (s).
    pub duration_s: f64,
}

/// Period multipliers that keep square waves / multisines of one run from
/// sharing a fundamental (distinct, non-harmonic ratios).
const PERIOD_SPREAD: [f64; 6] = [1.0, 1.3, 1.7, 2.1, 2.6, 3.1];

/// Designs a dynamic channel.
pub fn design_channel(req: &ChannelRequest<'_>) -> Result<ChannelDesign, PlanError> {
    let t = req.time_constant_s;
    let clock_field = format!("{}.clock_period_s", req.field);
    if let Some(c) = req.clock_period_s {
        if !(c.is_finite() && c > 0.0) {
            return Err(PlanError::invalid(
                clock_field,
                format!("must be a finite number of seconds > 0 (got {c})"),
            ));
        }
        if c > req.min_duration_s {
            return Err(PlanError::over_limit(
                clock_field,
                format!(
                    "a clock period of {c} s is slower than the run ({} s): not one change would be flown",
                    req.min_duration_s
                ),
                req.min_duration_s,
            ));
        }
        let min_chip = MIN_LOGGER_SAMPLES_PER_CHIP / req.logger_rate_hz;
        if c < min_chip {
            return Err(PlanError::over_limit(
                clock_field,
                format!(
                    "a clock period of {c} s is shorter than {MIN_LOGGER_SAMPLES_PER_CHIP} samples of the {} Hz logger ({min_chip} s)",
                    req.logger_rate_hz
                ),
                min_chip,
            ));
        }
    }
    if let Some(n) = req.prbs_order
        && !(MIN_PRBS_ORDER..=MAX_PRBS_ORDER).contains(&n)
    {
        return Err(PlanError::over_limit(
            format!("{}.prbs_order", req.field),
            format!(
                "the PRBS order must be between {MIN_PRBS_ORDER} and {MAX_PRBS_ORDER} (got {n})"
            ),
            MAX_PRBS_ORDER as f64,
        ));
    }
    let (i, k) = req.channel;
    let spread = PERIOD_SPREAD[i % PERIOD_SPREAD.len()];
    // Time to slew across the full swing at the rate limit.
    let slew = req.rate_limit.map_or(0.0, |r| 2.0 * req.amplitude / r);
    let check_slew = |hold: f64, what: &str| -> Result<(), PlanError> {
        if slew > hold {
            return Err(PlanError::over_limit(
                clock_field.clone(),
                format!(
                    "slewing 2×{:.4} at the rate limit {} ({:.4}/s) takes {slew:.2} s, longer than {hold:.2} s ({what}); lengthen the clock or lower the amplitude",
                    req.amplitude,
                    req.rate_field,
                    req.rate_limit.unwrap_or(f64::INFINITY),
                ),
                hold,
            ));
        }
        Ok(())
    };
    let design = match req.signal {
        SignalKind::Prbs => {
            // Default clock T, lengthened so a slew takes at most half a chip.
            let tc = req.clock_period_s.unwrap_or(t.max(2.0 * slew));
            check_slew(tc / 2.0, "half a PRBS chip")?;
            let order = match req.prbs_order {
                Some(n) => n,
                None => {
                    let mut n = MIN_PRBS_ORDER;
                    while ((1u64 << n) - 1) as f64 * tc < req.min_duration_s && n < MAX_PRBS_ORDER {
                        n += 1;
                    }
                    n
                }
            };
            let m = (1usize << order) - 1;
            let period = m as f64 * tc;
            let periods = (req.min_duration_s / period - 1e-9).ceil().max(1.0);
            ChannelDesign {
                waveform: Waveform::Prbs {
                    order,
                    clock_period_s: tc,
                    seed: req.seed,
                    shift_chips: i * m / k.max(1),
                },
                duration_s: periods * period,
            }
        }
        SignalKind::Square => {
            let half = req
                .clock_period_s
                .unwrap_or((SQUARE_HOLD_TIME_CONSTANTS * t * spread).max(4.0 * slew));
            check_slew(half / 4.0, "a quarter of a square-wave level")?;
            let period = 2.0 * half;
            let periods = (req.min_duration_s / period - 1e-9).ceil().max(2.0);
            ChannelDesign {
                waveform: Waveform::Square { period_s: period },
                duration_s: periods * period,
            }
        }
        SignalKind::Multisine => {
            // One period covers the run; lines from 1/period up to 10× the corner
            // (a smooth, narrow-band signal is ill-conditioned as a regressor).
            let corner = 1.0 / (2.0 * std::f64::consts::PI * t);
            // Channels of one run get distinct periods, so their lines interleave.
            let period = req.min_duration_s.max(20.0 * t) / spread;
            let f_lo = 1.0 / period;
            let f_hi = (10.0 * corner)
                .min(req.logger_rate_hz / 4.0)
                .max(10.0 * f_lo);
            ChannelDesign {
                waveform: Waveform::Multisine {
                    f_lo_hz: f_lo,
                    f_hi_hz: f_hi,
                    period_s: period,
                },
                duration_s: (req.min_duration_s / period - 1e-9).ceil().max(1.0) * period,
            }
        }
        SignalKind::RandomBinary => {
            let tc = req.clock_period_s.unwrap_or(t.max(2.0 * slew));
            check_slew(tc / 2.0, "half a random-binary chip")?;
            ChannelDesign {
                waveform: Waveform::RandomBinary {
                    clock_period_s: tc,
                    // Channels of one run draw independent sequences.
                    seed: (req.seed ^ (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)) & MAX_SEED,
                },
                duration_s: (req.min_duration_s / tc).ceil() * tc,
            }
        }
    };
    Ok(design)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn req(signal: SignalKind) -> ChannelRequest<'static> {
        ChannelRequest {
            field: "excitation.per_dof.sway",
            signal,
            time_constant_s: 3.0,
            amplitude: 0.2,
            rate_limit: Some(0.3),
            rate_field: "limits.sway.max_accel",
            clock_period_s: None,
            prbs_order: None,
            min_duration_s: 30.0,
            logger_rate_hz: 10.0,
            seed: 1,
            channel: (0, 1),
        }
    }

    #[test]
    fn prbs_order_covers_the_run_in_whole_periods() {
        let d = design_channel(&req(SignalKind::Prbs)).unwrap();
        // T_c = 3 s, 30 s needed: 2⁴−1 = 15 chips = 45 s ≥ 30 s, 2³−1 = 7 chips = 21 s < 30 s.
        match d.waveform {
            Waveform::Prbs {
                order,
                clock_period_s,
                ..
            } => {
                assert_eq!(order, 4);
                assert_eq!(clock_period_s, 3.0);
            }
            w => panic!("{w:?}"),
        }
        assert_eq!(d.duration_s, 45.0);
    }

    #[test]
    fn default_clock_lengthens_to_respect_the_rate_limit() {
        let mut r = req(SignalKind::Prbs);
        r.amplitude = 0.6; // 2×0.6 at 0.3/s = 4 s of slew: chip ≥ 8 s
        match design_channel(&r).unwrap().waveform {
            Waveform::Prbs { clock_period_s, .. } => assert!((clock_period_s - 8.0).abs() < 1e-12),
            w => panic!("{w:?}"),
        }
    }

    #[test]
    fn square_period_is_ten_time_constants() {
        let d = design_channel(&req(SignalKind::Square)).unwrap();
        assert_eq!(d.waveform, Waveform::Square { period_s: 30.0 });
        assert_eq!(d.duration_s, 60.0); // at least two periods
    }

    #[test]
    fn impossible_clocks_are_refused_with_their_limit() {
        let mut r = req(SignalKind::Prbs);
        r.clock_period_s = Some(31.0);
        let e = design_channel(&r).unwrap_err();
        assert_eq!(e.field, "excitation.per_dof.sway.clock_period_s");
        assert_eq!(e.limit, Some(30.0));

        r.clock_period_s = Some(0.1); // one logger sample
        let e = design_channel(&r).unwrap_err();
        assert_eq!(e.limit, Some(0.2));

        // 2×0.4 at 0.3/s takes 2.67 s > half of a 4 s chip.
        r.amplitude = 0.4;
        r.clock_period_s = Some(4.0);
        let e = design_channel(&r).unwrap_err();
        assert_eq!(e.field, "excitation.per_dof.sway.clock_period_s");
        assert!(e.message.contains("limits.sway.max_accel"), "{}", e.message);
        r.clock_period_s = Some(6.0);
        design_channel(&r).unwrap();

        r.prbs_order = Some(25);
        assert_eq!(
            design_channel(&r).unwrap_err().field,
            "excitation.per_dof.sway.prbs_order"
        );
    }
}
