//! Excitation for the surface-vessel trials: a PRBS (the 9-bit
//! maximum-length sequence of [`crate::signals::Signal::prbs`] from a random
//! start), random held levels (alternating in sign, or anywhere in a
//! band), and a slew limit. All sampled at the log instants k·h.

use crate::rng::Rng;
use crate::signals::Signal;

/// ±1 from a maximum-length PRBS, one chip every `chip_s` seconds, n
/// samples at step `h`, from a random register state.
pub fn prbs(rng: &mut Rng, n: usize, h: f64, chip_s: f64) -> Vec<f64> {
    let seed = 1 + rng.below(511) as u16;
    let s = Signal::prbs(1.0, chip_s, seed);
    (0..n).map(|k| s.at(k as f64 * h + 1e-9)).collect()
}

/// Levels held for a random number of samples in `hold`, n samples.
/// `alternate`: |level| uniform in `level`, sign alternating from a random
/// first sign; otherwise level uniform in `level`. Zero for the first
/// `quiet` samples.
pub fn held(
    rng: &mut Rng,
    n: usize,
    quiet: usize,
    hold: (f64, f64),
    level: (f64, f64),
    alternate: bool,
) -> Vec<f64> {
    let mut out = vec![0.0; n];
    let mut k = quiet.min(n);
    let mut sign = rng.sign();
    while k < n {
        let len = (rng.range(hold.0, hold.1).round() as usize).max(1);
        let l = if alternate {
            sign = -sign;
            sign * rng.range(level.0, level.1)
        } else {
            rng.range(level.0, level.1)
        };
        for o in out.iter_mut().skip(k).take(len) {
            *o = l;
        }
        k += len;
    }
    out
}

/// `x` slewed from 0 at no more than `step` per sample.
pub fn slewed(x: &[f64], step: f64) -> Vec<f64> {
    let mut y = 0.0_f64;
    x.iter()
        .map(|&g| {
            y += (g - y).clamp(-step, step);
            y
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn held_levels_alternate_and_slew_limits() {
        let mut rng = Rng::new(2);
        let x = held(&mut rng, 500, 10, (20.0, 40.0), (0.4, 1.0), true);
        assert!(x[..10].iter().all(|&v| v == 0.0));
        let levels: Vec<f64> = x[10..]
            .windows(2)
            .filter(|w| w[0] != w[1])
            .map(|w| w[1])
            .collect();
        assert!(levels.windows(2).all(|w| w[0] * w[1] < 0.0));
        assert!(x[10..].iter().all(|v| (0.4..1.0).contains(&v.abs())));
        let y = slewed(&x, 0.05);
        assert!(y.windows(2).all(|w| (w[1] - w[0]).abs() <= 0.05 + 1e-12));
        let p = prbs(&mut rng, 300, 0.1, 1.5);
        assert!(p.iter().all(|v| v.abs() == 1.0));
        // A chip of 1.5 s at 10 Hz holds 15 samples.
        let flips = p.windows(2).filter(|w| w[0] != w[1]).count();
        assert!((3..=20).contains(&flips), "{flips}");
    }
}
