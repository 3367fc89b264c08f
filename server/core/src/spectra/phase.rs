//! Phase unwrapping (numpy.unwrap semantics).

use std::f64::consts::PI;

/// Unwraps a phase sequence in radians exactly as `numpy.unwrap(p)` with its
/// defaults (`discont = π`, `period = 2π`): every jump between consecutive
/// samples larger than π in magnitude is replaced by its 2π-complement, and
/// the corrections are accumulated. A jump of exactly ±π is kept (as +π when
/// the raw difference is positive), as numpy does.
///
/// Non-finite samples propagate as in numpy (the output becomes NaN from
/// there on).
pub fn unwrap_phase(phase: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(phase.len());
    unwrap_into(phase, &mut out);
    out
}

/// [`unwrap_phase`] into `out` (cleared first), for callers that reuse a
/// buffer. Each jump's correction is computed on its own first (the loop
/// vectorises), then the corrections are summed in order. A jump within
/// ±2π (every jump of phases in [−π, π]) is mapped into [−π, π) by
/// selects, without branches: the phase of a noisy cross spectrum crosses
/// ±π at random bins, and a branch on it mispredicted at every other one.
/// Larger jumps and NaN take numpy's floor-modulo, as numpy does; the
/// results are numpy's bit for bit either way.
pub(crate) fn unwrap_into(phase: &[f64], out: &mut Vec<f64>) {
    out.clear();
    let Some(&first) = phase.first() else {
        return;
    };
    // out = [p₀, step₁, …, stepₙ₋₁], then the running sum in place.
    out.reserve(phase.len());
    out.push(first);
    out.extend(phase.windows(2).map(|w| near_step(w[1] - w[0])));
    for (s, w) in out[1..].iter_mut().zip(phase.windows(2)) {
        let dd = w[1] - w[0];
        if dd.is_nan() || dd.abs() > 2.0 * PI {
            *s = far_step(dd);
        }
    }
    let mut correction = 0.0;
    for (o, p) in out[1..].iter_mut().zip(&phase[1..]) {
        correction += *o;
        *o = p + correction;
    }
}

/// numpy's correction of a jump `dd` with |dd| ≤ 2π: `py_mod(dd + π, 2π)`
/// for `dd + π` in [−π, 3π] (fmod is `a − 2π` above 2π, exact, and `a`
/// below; a negative remainder gains 2π), ±π kept as +π for a positive
/// jump, and no correction below π.
#[inline(always)]
fn near_step(dd: f64) -> f64 {
    let (period, high, low) = (2.0 * PI, PI, -PI);
    let a = dd - low;
    let m = if a >= period { a - period } else { a };
    let m = if m < 0.0 { m + period } else { m };
    let ddmod = m + low;
    let ddmod = if ddmod == low && dd > 0.0 {
        high
    } else {
        ddmod
    };
    if dd.abs() >= high { ddmod - dd } else { 0.0 }
}

/// numpy's correction of any jump `dd` (NaN included).
fn far_step(dd: f64) -> f64 {
    let (period, high, low) = (2.0 * PI, PI, -PI);
    let mut ddmod = py_mod(dd - low, period) + low;
    if ddmod == low && dd > 0.0 {
        ddmod = high;
    }
    ddmod - dd
}

/// `a % b` (C's `fmod`, exact), without the software division loop when
/// `|a| < 2|b|`: the remainder is then `a` (|a| < |b|) or `a ∓ |b|`, which
/// is exact because `|b| ≤ |a| < 2|b|` (Sterbenz). Phase differences of
/// an unwrap are always such (|a| < 3π against 2π).
fn fmod(a: f64, b: f64) -> f64 {
    let (x, y) = (a.abs(), b.abs());
    if x < y {
        a
    } else if x < 2.0 * y {
        (x - y).copysign(a)
    } else {
        a % b
    }
}

/// Floor-division remainder with the sign of `b` (numpy's `np.mod` for
/// floats, including its `fmod`-then-adjust rounding).
fn py_mod(a: f64, b: f64) -> f64 {
    let m = fmod(a, b);
    if m != 0.0 {
        if (b < 0.0) != (m < 0.0) { m + b } else { m }
    } else {
        0.0f64.copysign(b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fast remainder is `%` bit for bit, signs of zero included.
    #[test]
    fn fast_remainder_is_fmod() {
        let mut rng = crate::rng::SplitMix64::new(3);
        let b = 2.0 * PI;
        let mut cases = vec![
            0.0,
            -0.0,
            b,
            -b,
            2.0 * b,
            -2.0 * b,
            b.next_up(),
            (2.0 * b).next_down(),
        ];
        cases.extend((0..20_000).map(|_| 4.0 * b * (rng.uniform() - 0.5)));
        cases.extend((0..1000).map(|_| 1e6 * rng.normal()));
        for a in cases {
            for b in [b, -b, 0.7, 3.0] {
                assert_eq!(fmod(a, b).to_bits(), (a % b).to_bits(), "{a} % {b}");
            }
        }
        assert!(fmod(f64::NAN, b).is_nan() && fmod(f64::INFINITY, b).is_nan());
    }

    /// numpy's loop as written: the modulo for every sample, discarded below π.
    fn unwrap_reference(phase: &[f64]) -> Vec<f64> {
        let (period, high, low) = (2.0 * PI, PI, -PI);
        let mut out = Vec::with_capacity(phase.len());
        let Some(&first) = phase.first() else {
            return out;
        };
        out.push(first);
        let mut correction = 0.0;
        for w in phase.windows(2) {
            let dd = w[1] - w[0];
            let mut ddmod = py_mod(dd - low, period) + low;
            if ddmod == low && dd > 0.0 {
                ddmod = high;
            }
            let mut ph_correct = ddmod - dd;
            if dd.abs() < high {
                ph_correct = 0.0;
            }
            correction += ph_correct;
            out.push(w[1] + correction);
        }
        out
    }

    #[test]
    fn fast_path_is_bit_identical_to_the_reference_loop() {
        // Wrapped ramps, exact ±π jumps, large jumps, NaN.
        let mut p: Vec<f64> = (0..5000)
            .map(|i| ((i as f64) * 0.731).sin() * 4.0)
            .collect();
        // Phases of a noisy spectrum: uniform in [−π, π], with its ends.
        let mut rng = crate::rng::SplitMix64::new(11);
        p.extend((0..20_000).map(|_| rng.uniform_in(-PI, PI)));
        p.extend([PI, -PI, PI, PI.next_down(), -PI, (-PI).next_up(), PI]);
        p.extend([PI, 0.0, -PI, 0.0, 7.0, -7.0, f64::NAN, 1.0]);
        let want = unwrap_reference(&p);
        let got = unwrap_phase(&p);
        assert_eq!(got.len(), want.len());
        for (g, w) in got.iter().zip(&want) {
            assert!(
                g.to_bits() == w.to_bits() || (g.is_nan() && w.is_nan()),
                "{g} vs {w}"
            );
        }
    }

    #[test]
    fn unwraps_a_linear_ramp() {
        let truth: Vec<f64> = (0..200).map(|i| -0.3 * i as f64).collect();
        let wrapped: Vec<f64> = truth.iter().map(|p| p.sin().atan2(p.cos())).collect();
        let un = unwrap_phase(&wrapped);
        for (u, t) in un.iter().zip(&truth) {
            assert!((u - t).abs() < 1e-9, "{u} vs {t}");
        }
    }

    #[test]
    fn matches_numpy_on_edge_cases() {
        // np.unwrap([0, 3.5, 7.0, 0.5, -3.0]) = [0, -2.783.., -5.566.., -5.783.., -3.0].
        assert!(unwrap_phase(&[]).is_empty());
        assert_eq!(unwrap_phase(&[1.5]), vec![1.5]);
        let p = [0.0, 3.5, 7.0, 0.5, -3.0];
        let u = unwrap_phase(&p);
        let expected = [
            0.0,
            3.5 - 2.0 * PI,
            7.0 - 4.0 * PI,
            0.5 - 2.0 * PI,
            -3.0 - 2.0 * PI + 2.0 * PI,
        ];
        for (a, e) in u.iter().zip(expected) {
            assert!((a - e).abs() < 1e-12, "{u:?}");
        }
        // A jump of exactly +π is kept; −π likewise.
        assert_eq!(unwrap_phase(&[0.0, PI]), vec![0.0, PI]);
        assert_eq!(unwrap_phase(&[0.0, -PI]), vec![0.0, -PI]);
        // Small steps are untouched.
        assert_eq!(unwrap_phase(&[0.1, 0.2, -0.3]), vec![0.1, 0.2, -0.3]);
    }

    #[test]
    fn py_mod_is_floor_mod() {
        assert_eq!(py_mod(-1.0, 3.0), 2.0);
        assert_eq!(py_mod(4.0, 3.0), 1.0);
        assert_eq!(py_mod(6.0, 3.0), 0.0);
    }
}
