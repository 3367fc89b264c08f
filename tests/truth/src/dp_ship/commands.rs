//! Command signals a DP trial flies: maximum-length shift-register
//! sequences held per chip, and random held pitch ratios.

use crate::rng::Rng;

/// Feedback taps (bit positions, 1-based) of a primitive polynomial of
/// each order 3 … 10 (x³+x²+1, x⁴+x³+1, x⁵+x³+1, x⁶+x⁵+1, x⁷+x⁶+1,
/// x⁸+x⁶+x⁵+x⁴+1, x⁹+x⁵+1, x¹⁰+x⁷+1).
fn taps(order: u32) -> &'static [u32] {
    match order {
        3 => &[3, 2],
        4 => &[4, 3],
        5 => &[5, 3],
        6 => &[6, 5],
        7 => &[7, 6],
        8 => &[8, 6, 5, 4],
        9 => &[9, 5],
        10 => &[10, 7],
        _ => panic!("PRBS order {order} is outside 3 … 10"),
    }
}

/// One period (2ⁿ − 1 chips, ±1) of the maximum-length sequence of a
/// Fibonacci shift register of order n from a random nonzero state.
pub(super) fn m_sequence(rng: &mut Rng, order: u32) -> Vec<f64> {
    let m = (1usize << order) - 1;
    let mut reg = 1 + rng.below(m as u64) as u32;
    (0..m)
        .map(|_| {
            let out = reg & 1;
            let fb = taps(order)
                .iter()
                .fold(0, |acc, &t| acc ^ ((reg >> (order - t)) & 1));
            reg = (reg >> 1) | (fb << (order - 1));
            if out == 1 { 1.0 } else { -1.0 }
        })
        .collect()
}

/// Commands u (n samples) holding `chips[c]`·level over chip c, slewed.
pub(super) fn binary(chips: &[f64], chip_s: f64, n: usize, level: f64, slew: f64) -> Vec<f64> {
    let mut u = 0.0_f64;
    (0..n)
        .map(|k| {
            let c = ((k as f64 + 1e-9) / chip_s).floor() as usize % chips.len();
            u += (level * chips[c] - u).clamp(-slew, slew);
            u
        })
        .collect()
}

/// Random held pitch ratios (alternating sign, |p| in `level`), slewed at
/// 5 % per sample, zero for the first 10 samples.
pub(super) fn pitch(rng: &mut Rng, n: usize, hold: (f64, f64), level: (f64, f64)) -> Vec<f64> {
    let mut goal = vec![0.0; n];
    let mut k = n.min(10);
    let mut sign = rng.sign();
    while k < n {
        let len = rng.range(hold.0, hold.1).round() as usize;
        let l = sign * rng.range(level.0, level.1);
        sign = -sign;
        for g in goal.iter_mut().skip(k).take(len.max(1)) {
            *g = l;
        }
        k += len.max(1);
    }
    let mut p = 0.0_f64;
    goal.iter()
        .map(|&g| {
            p += (g - p).clamp(-0.05, 0.05);
            p.abs() * p
        })
        .collect()
}
