//! Branch-free `atan2` and `log10` over whole vectors, for the Bode data of
//! the report (36 pairs × 2049 bins: the libm calls cost as much as the
//! Welch accumulation).
//!
//! Both follow fdlibm (Sun Microsystems, the source of most libms):
//! argument reduction, then fdlibm's minimax polynomials, written without
//! branches so the compiler vectorises the loops. Error against the
//! correctly rounded result: ≤ 2 ulp for `atan2`, ≤ 2 ulp + the rounding
//! of the final scaling for `log10` (checked against std in the tests).
//! Special values (zeros, subnormals, infinities, NaN) go through std.
//!
//! On CPUs with AVX2 the loops run in 4-lane registers (no fused
//! multiply–adds: the same roundings, bit-identical results).

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, LOG10_E, PI};

#[cfg(test)]
use crate::spectra::Complex;

/// fdlibm `atan` coefficients for |x| ≤ 7/16.
#[allow(clippy::excessive_precision)] // fdlibm literal, verbatim
const AT: [f64; 11] = [
    3.333_333_333_333_293_180_27e-01,
    -1.999_999_999_987_648_324_76e-01,
    1.428_571_427_250_346_637_11e-01,
    -1.111_111_040_546_235_578_80e-01,
    9.090_887_133_436_506_561_96e-02,
    -7.691_876_205_044_829_994_95e-02,
    6.661_073_137_387_531_206_69e-02,
    -5.833_570_133_790_573_486_45e-02,
    4.976_877_994_615_932_360_17e-02,
    -3.653_157_274_421_691_552_70e-02,
    1.628_582_011_536_578_236_23e-02,
];
/// Low part of π/4 (fdlibm `atanlo[1]`).
#[allow(clippy::excessive_precision)] // fdlibm literal, verbatim
const PI_4_LO: f64 = 3.061_616_997_868_383_017_93e-17;
/// tan(π/8): above it the argument is reduced by π/4.
const TAN_PI_8: f64 = 0.414_213_562_373_095_03;

/// fdlibm `log` coefficients (`Lg1` … `Lg7`).
#[allow(clippy::excessive_precision)] // fdlibm literal, verbatim
const LG: [f64; 7] = [
    6.666_666_666_666_735_13e-01,
    3.999_999_999_940_941_908e-01,
    2.857_142_874_366_239_149e-01,
    2.222_219_843_214_978_396e-01,
    1.818_357_216_161_805_012e-01,
    1.531_383_769_920_937_332e-01,
    1.479_819_860_511_658_591e-01,
];
#[allow(clippy::excessive_precision)] // fdlibm literal, verbatim
const LN2_HI: f64 = 6.931_471_803_691_238_164_90e-01;
#[allow(clippy::excessive_precision)] // fdlibm literal, verbatim
const LN2_LO: f64 = 1.908_214_929_270_587_700_02e-10;

/// `out[k] = arg(c[k]) = atan2(c[k].im, c[k].re)`, through the split
/// planes `re`, `im` (scratch, resized) so the main loop vectorises. (The
/// report's cross spectra come in planes already: a test reference.)
#[cfg(test)]
pub(crate) fn arg_into(c: &[Complex<f64>], re: &mut Vec<f64>, im: &mut Vec<f64>, out: &mut [f64]) {
    re.clear();
    im.clear();
    re.extend(c.iter().map(|v| v.re));
    im.extend(c.iter().map(|v| v.im));
    atan2_into(im, re, out);
}

/// `out[k] = atan2(y[k], x[k])` (same conventions as [`f64::atan2`]).
pub(crate) fn atan2_into(y: &[f64], x: &[f64], out: &mut [f64]) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has the feature the function is compiled for.
        return unsafe { atan2_avx2(y, x, out) };
    }
    atan2_body(y, x, out)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn atan2_avx2(y: &[f64], x: &[f64], out: &mut [f64]) {
    atan2_body(y, x, out)
}

#[inline(always)]
fn atan2_body(y: &[f64], x: &[f64], out: &mut [f64]) {
    for ((o, &y), &x) in out.iter_mut().zip(y).zip(x) {
        *o = atan2_core(y, x);
    }
    // Rare special values: exact std semantics.
    for ((o, &y), &x) in out.iter_mut().zip(y).zip(x) {
        if !(x.is_finite() && y.is_finite()) || (x == 0.0 && y == 0.0) {
            *o = y.atan2(x);
        }
    }
}

/// Branch-free atan2 for finite arguments not both zero.
#[inline(always)]
fn atan2_core(y: f64, x: f64) -> f64 {
    let (ax, ay) = (x.abs(), y.abs());
    let swap = ay > ax;
    let (num, den) = if swap { (ax, ay) } else { (ay, ax) };
    // t = num/den in [0, 1]; above tan(π/8), atan(t) = π/4 + atan(u) with
    // u = (t − 1)/(t + 1) = (num − den)/(num + den): one division either way.
    let big = num > TAN_PI_8 * den;
    let (n, d) = if big {
        (num - den, num + den)
    } else {
        (num, den)
    };
    let u = n / d; // |u| ≤ tan(π/8) < 7/16
    let z = u * u;
    let w = z * z;
    let s1 = z * (AT[0] + w * (AT[2] + w * (AT[4] + w * (AT[6] + w * (AT[8] + w * AT[10])))));
    let s2 = w * (AT[1] + w * (AT[3] + w * (AT[5] + w * (AT[7] + w * AT[9]))));
    let poly = u * (s1 + s2);
    let a = if big {
        FRAC_PI_4 - ((poly - PI_4_LO) - u)
    } else {
        u - poly
    };
    let a = if swap { FRAC_PI_2 - a } else { a };
    let a = if x.is_sign_negative() { PI - a } else { a };
    if y.is_sign_negative() { -a } else { a }
}

/// `out[k] = log10(v[k])` (same conventions as [`f64::log10`]).
pub(crate) fn log10_into(v: &[f64], out: &mut [f64]) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has the feature the function is compiled for.
        return unsafe { log10_avx2(v, out) };
    }
    log10_body(v, out)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn log10_avx2(v: &[f64], out: &mut [f64]) {
    log10_body(v, out)
}

#[inline(always)]
fn log10_body(v: &[f64], out: &mut [f64]) {
    for (o, &x) in out.iter_mut().zip(v) {
        *o = ln_core(x) * LOG10_E;
    }
    for (o, &x) in out.iter_mut().zip(v) {
        if !(x.is_normal() && x > 0.0) {
            *o = x.log10();
        }
    }
}

/// Branch-free natural log for positive normal `x` (fdlibm `__ieee754_log`).
#[inline(always)]
fn ln_core(x: f64) -> f64 {
    const MANT: u64 = (1 << 52) - 1;
    let bits = x.to_bits();
    // i32: converts to f64 in vector registers (i64 would not, before
    // AVX-512); the exponent fits either way.
    let mut e = ((bits >> 52) & 0x7ff) as i32 - 1023;
    // m in [1, 2); fold to [√2/2, √2).
    let m = f64::from_bits((bits & MANT) | (1023 << 52));
    let high = m > std::f64::consts::SQRT_2;
    let m = if high { 0.5 * m } else { m };
    e += i32::from(high);
    let f = m - 1.0;
    let s = f / (2.0 + f);
    let z = s * s;
    let w = z * z;
    let t1 = w * (LG[1] + w * (LG[3] + w * LG[5]));
    let t2 = z * (LG[0] + w * (LG[2] + w * (LG[4] + w * LG[6])));
    let r = t2 + t1;
    let hfsq = 0.5 * f * f;
    let dk = f64::from(e);
    dk * LN2_HI - ((hfsq - (s * (hfsq + r) + dk * LN2_LO)) - f)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Distance in units in the last place.
    fn ulps(a: f64, b: f64) -> u64 {
        if a == b {
            return 0;
        }
        let key = |v: f64| {
            let i = v.to_bits() as i64;
            if i < 0 { i64::MIN - i } else { i }
        };
        key(a).abs_diff(key(b))
    }

    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    #[test]
    fn atan2_within_two_ulps_of_std() {
        let mut r = Lcg(7);
        let mut y = Vec::new();
        let mut x = Vec::new();
        for _ in 0..200_000 {
            let scale = 10f64.powf(40.0 * r.next() - 20.0);
            y.push((2.0 * r.next() - 1.0) * scale);
            x.push((2.0 * r.next() - 1.0) * 10f64.powf(40.0 * r.next() - 20.0));
        }
        // Edges: axes, diagonals, the reduction boundary, signed zeros,
        // infinities, NaN.
        let edges = [
            (0.0, 1.0),
            (-0.0, 1.0),
            (0.0, -1.0),
            (-0.0, -1.0),
            (1.0, 0.0),
            (-1.0, -0.0),
            (1.0, 1.0),
            (-1.0, -1.0),
            (TAN_PI_8, 1.0),
            (0.0, 0.0),
            (-0.0, -0.0),
            (0.0, -0.0),
            (f64::INFINITY, 1.0),
            (1.0, f64::NEG_INFINITY),
            (f64::NAN, 1.0),
            (1e-310, 1.0),
            (1.0, 1e-310),
        ];
        for (a, b) in edges {
            y.push(a);
            x.push(b);
        }
        let mut out = vec![0.0; y.len()];
        atan2_into(&y, &x, &mut out);
        let c: Vec<Complex<f64>> = x
            .iter()
            .zip(&y)
            .map(|(&re, &im)| Complex::new(re, im))
            .collect();
        let mut arg = vec![0.0; y.len()];
        arg_into(&c, &mut Vec::new(), &mut Vec::new(), &mut arg);
        // The vector path (AVX2, when the CPU has it) is the plain one.
        let mut plain = vec![0.0; y.len()];
        atan2_body(&y, &x, &mut plain);
        assert!(
            out.iter()
                .zip(&plain)
                .all(|(a, b)| a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()))
        );
        assert!(
            out.iter()
                .zip(&arg)
                .all(|(a, b)| a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()))
        );
        let mut worst = 0;
        for k in 0..y.len() {
            let e = y[k].atan2(x[k]);
            if e.is_nan() {
                assert!(out[k].is_nan());
                continue;
            }
            let d = ulps(out[k], e);
            worst = worst.max(d);
            assert!(d <= 2, "atan2({}, {}) = {} vs {e}", y[k], x[k], out[k]);
        }
        assert!(worst <= 2);
    }

    #[test]
    fn log10_within_three_ulps_of_std() {
        let mut r = Lcg(3);
        let mut v: Vec<f64> = (0..200_000)
            .map(|_| 10f64.powf(600.0 * r.next() - 300.0))
            .collect();
        v.extend([
            1.0,
            10.0,
            0.1,
            std::f64::consts::SQRT_2,
            f64::MIN_POSITIVE,
            1e-310,
            0.0,
            -0.0,
            -1.0,
            f64::INFINITY,
            f64::NAN,
            f64::MAX,
        ]);
        let mut out = vec![0.0; v.len()];
        log10_into(&v, &mut out);
        let mut plain = vec![0.0; v.len()];
        log10_body(&v, &mut plain);
        assert!(
            out.iter()
                .zip(&plain)
                .all(|(a, b)| a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()))
        );
        for (x, o) in v.iter().zip(&out) {
            let e = x.log10();
            if e.is_nan() {
                assert!(o.is_nan(), "log10({x})");
                continue;
            }
            assert!(ulps(*o, e) <= 3, "log10({x}) = {o} vs {e}");
        }
        assert_eq!(out[v.len() - 12], 0.0);
        assert!((out[v.len() - 11] - 1.0).abs() <= f64::EPSILON);
    }

    #[test]
    fn ln_core_is_accurate_near_one() {
        for x in [1.0 + 1e-12, 1.0 - 1e-12, 0.999, 1.001, 2.0, 0.5] {
            let d = ulps(ln_core(x), x.ln());
            assert!(d <= 2, "ln({x}): {} vs {}", ln_core(x), x.ln());
        }
        assert!((ln_core(2.0) - std::f64::consts::LN_2).abs() < 1e-16);
    }
}
