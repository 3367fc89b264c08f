//! Normalized cross-correlation of two uniformly sampled records by FFT, and
//! the analysis of its peak (integer lag, ambiguity).
//!
//! Lag `m` pairs `a[k]` with `b[k − m]`. For every lag the correlation is
//! Pearson's coefficient over the samples that overlap at that lag, after
//! removing from each side its own mean *and linear trend over that
//! overlap* (a partial correlation given time). Detrending per overlap,
//! rather than once per record, keeps the two sides consistent: records
//! covering different spans of a dive would otherwise lose different lines.
//! The raw products `Σ a[k]·b[k−m]` for all lags come from one zero-padded
//! real FFT pair (O(n log n)); the overlap sums `Σa`, `Σk·a`, `Σa²` (and the
//! same for `b`) come from prefix sums, O(1) per lag.
//!
//! The peak is chosen on the *evidence* `z(m) = ρ(m)·√(n_m / n_full)`, with
//! `n_m` the overlap at lag `m` and `n_full` the largest possible overlap
//! (the shorter record): for unrelated signals `ρ·√n` is of order one, so a
//! high correlation over a short overlap — easy to get by chance from slow
//! signals — does not beat a slightly lower one over the whole record.

use realfft::RealFftPlanner;
use realfft::num_complex::Complex;

/// Correlation and overlap for each lag of a range.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Correlation {
    /// First lag (`rho[i]` is lag `lo + i`).
    pub lo: i64,
    /// Pearson correlation of the locally detrended overlaps (0 when an
    /// overlap is shorter than 4 samples or constant).
    pub rho: Vec<f64>,
    /// Evidence `ρ·√(n_m / n_full)`.
    pub z: Vec<f64>,
}

pub(crate) struct Prefix {
    s0: Vec<f64>,
    s1: Vec<f64>,
    sq: Vec<f64>,
}

impl Prefix {
    pub(crate) fn new(x: &[f64]) -> Self {
        let n = x.len() + 1;
        let (mut s0, mut s1, mut sq) = (
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
        );
        let (mut a0, mut a1, mut aq) = (0.0, 0.0, 0.0);
        s0.push(0.0);
        s1.push(0.0);
        sq.push(0.0);
        for (k, v) in x.iter().enumerate() {
            a0 += v;
            a1 += k as f64 * v;
            aq += v * v;
            s0.push(a0);
            s1.push(a1);
            sq.push(aq);
        }
        Prefix { s0, s1, sq }
    }

    /// (Σx, Σ(i − (n−1)/2)·x, Σx²) over `x[start..start + n]`, `i` the
    /// index within the slice.
    pub(crate) fn window(&self, start: usize, n: usize) -> (f64, f64, f64) {
        let end = start + n;
        let s0 = self.s0[end] - self.s0[start];
        let s1 = self.s1[end] - self.s1[start] - start as f64 * s0;
        let centred = s1 - 0.5 * (n as f64 - 1.0) * s0;
        (s0, centred, self.sq[end] - self.sq[start])
    }
}

/// Correlation for the lags `lo..=hi` (`hi ≥ lo`).
pub(crate) fn normalized_xcorr(a: &[f64], b: &[f64], lo: i64, hi: i64) -> Correlation {
    let (na, nb) = (a.len(), b.len());
    if na == 0 || nb == 0 || hi < lo {
        return Correlation {
            lo,
            rho: Vec::new(),
            z: Vec::new(),
        };
    }
    let raw = raw_xcorr(a, b);
    let n_fft = raw.len() as i64;
    let (pa, pb) = (Prefix::new(a), Prefix::new(b));
    let n_full = na.min(nb) as f64;
    let (rho, z) = (lo..=hi)
        .map(|m| {
            let k_lo = m.max(0);
            let k_hi = (na as i64).min(nb as i64 + m);
            let n = k_hi - k_lo;
            if n < 4 {
                return (0.0, 0.0);
            }
            let (a0, a1, aa) = pa.window(k_lo as usize, n as usize);
            let (b0, b1, bb) = pb.window((k_lo - m) as usize, n as usize);
            let nf = n as f64;
            // Σ(i − ī)² over i = 0..n−1.
            let sc = nf * (nf * nf - 1.0) / 12.0;
            let quad = |u0: f64, u1: f64, v0: f64, v1: f64| u0 * v0 / nf + u1 * v1 / sc;
            let cross = raw[m.rem_euclid(n_fft) as usize] - quad(a0, a1, b0, b1);
            let var_a = aa - quad(a0, a1, a0, a1);
            let var_b = bb - quad(b0, b1, b0, b1);
            let denom = (var_a * var_b).sqrt();
            let r = if denom > 0.0 && denom.is_finite() {
                (cross / denom).clamp(-1.0, 1.0)
            } else {
                0.0
            };
            (r, r * (nf / n_full).sqrt())
        })
        .unzip();
    Correlation { lo, rho, z }
}

/// `r[m mod N] = Σ_k a[k]·b[k − m]` for every lag, by one zero-padded real
/// FFT pair (`N` a power of two ≥ `na + nb − 1`, so nothing wraps).
pub(crate) fn raw_xcorr(a: &[f64], b: &[f64]) -> Vec<f64> {
    let n_fft = (a.len() + b.len() - 1).next_power_of_two().max(2);
    let mut planner = RealFftPlanner::<f64>::new();
    let fwd = planner.plan_fft_forward(n_fft);
    let inv = planner.plan_fft_inverse(n_fft);
    let mut scratch = vec![Complex::default(); fwd.get_scratch_len().max(inv.get_scratch_len())];
    let mut buf = vec![0.0; n_fft];
    let mut spectrum = |x: &[f64], scratch: &mut [Complex<f64>]| {
        buf.fill(0.0);
        buf[..x.len()].copy_from_slice(x);
        let mut out = fwd.make_output_vec();
        // Lengths come from the plan itself, so this cannot fail.
        let _ = fwd.process_with_scratch(&mut buf, &mut out, scratch);
        out
    };
    let mut fa = spectrum(a, &mut scratch);
    let fb = spectrum(b, &mut scratch);
    fa.iter_mut().zip(&fb).for_each(|(x, y)| *x *= y.conj());
    // The DC and Nyquist bins of a real signal's spectrum are real.
    let last = fa.len() - 1;
    fa[0].im = 0.0;
    fa[last].im = 0.0;
    let mut out = inv.make_output_vec();
    let _ = inv.process_with_scratch(&mut fa, &mut out, &mut scratch);
    let scale = 1.0 / n_fft as f64;
    out.iter_mut().for_each(|v| *v *= scale);
    out
}

/// Ambiguity ratio when nothing outside the main lobe correlates positively.
pub(crate) const MAX_PEAK_RATIO: f64 = 1000.0;

/// The integer peak of a correlation over a lag range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Peak {
    /// Lag of the highest correlation within the main lobe of the highest
    /// evidence.
    pub lag: i64,
    /// Correlation there.
    pub rho: f64,
    /// Correlation at the lag of lowest evidence (sign-convention check).
    pub min_rho: f64,
    /// Lowest evidence.
    pub min_z: f64,
    /// Highest evidence.
    pub z: f64,
    /// `z / max(z₂, z / MAX_PEAK_RATIO)` with `z₂` the highest evidence
    /// outside the main lobe: 1 means two equally good lags.
    pub peak_ratio: f64,
    /// The peak sits on the first or last lag searched (the true peak may
    /// lie beyond the range).
    pub at_edge: bool,
}

/// Finds the highest evidence and the highest one separated from it.
///
/// The main lobe extends from the peak on each side while the evidence
/// stays above half the peak or keeps falling; the second peak is the
/// highest evidence outside it. The lag returned is that of the highest
/// *correlation* within the main lobe.
pub(crate) fn analyze_peak(c: &Correlation) -> Option<Peak> {
    let z = &c.z;
    let (p, &z_max) = z.iter().enumerate().max_by(|a, b| a.1.total_cmp(b.1))?;
    let (q, &z_min) = z.iter().enumerate().min_by(|a, b| a.1.total_cmp(b.1))?;
    let half = 0.5 * z_max;
    let mut right = p;
    while right + 1 < z.len() && (z[right + 1] > half || z[right + 1] < z[right]) {
        right += 1;
    }
    let mut left = p;
    while left > 0 && (z[left - 1] > half || z[left - 1] < z[left]) {
        left -= 1;
    }
    let second = z[..left]
        .iter()
        .chain(&z[right + 1..])
        .copied()
        .max_by(f64::total_cmp);
    // Within the main lobe the overlap hardly changes, but its √n slope
    // would still tilt the evidence: take the correlation's own maximum.
    let (p, _) = c.rho[left..=right]
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .map_or((p, 0.0), |(i, r)| (left + i, *r));
    let peak_ratio = if z_max <= 0.0 {
        1.0
    } else {
        let floor = z_max / MAX_PEAK_RATIO;
        z_max / second.unwrap_or(floor).max(floor)
    };
    Some(Peak {
        lag: c.lo + p as i64,
        rho: c.rho[p],
        min_rho: c.rho[q],
        min_z: z_min,
        z: z_max,
        peak_ratio,
        at_edge: z.len() > 1 && (p == 0 || p == z.len() - 1),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn detrended(x: &[f64]) -> Vec<f64> {
        let n = x.len() as f64;
        let ic = (n - 1.0) / 2.0;
        let mean = x.iter().sum::<f64>() / n;
        let sxy: f64 = x
            .iter()
            .enumerate()
            .map(|(i, v)| (i as f64 - ic) * (v - mean))
            .sum();
        let sxx: f64 = (0..x.len()).map(|i| (i as f64 - ic).powi(2)).sum();
        x.iter()
            .enumerate()
            .map(|(i, v)| v - mean - sxy / sxx * (i as f64 - ic))
            .collect()
    }

    fn direct(a: &[f64], b: &[f64], m: i64) -> f64 {
        let (pa, pb): (Vec<f64>, Vec<f64>) = (0..a.len() as i64)
            .filter(|&k| k - m >= 0 && k - m < b.len() as i64)
            .map(|k| (a[k as usize], b[(k - m) as usize]))
            .unzip();
        let (da, db) = (detrended(&pa), detrended(&pb));
        let c: f64 = da.iter().zip(&db).map(|(x, y)| x * y).sum();
        let va: f64 = da.iter().map(|x| x * x).sum();
        let vb: f64 = db.iter().map(|x| x * x).sum();
        c / (va * vb).sqrt()
    }

    #[test]
    fn matches_direct_detrended_pearson_on_every_lag() {
        let a: Vec<f64> = (0..37)
            .map(|k| ((k * k) as f64 * 0.37).sin() + 0.1 * k as f64)
            .collect();
        let b: Vec<f64> = (0..23)
            .map(|k| ((k as f64) * 1.3).cos() - 0.05 * k as f64)
            .collect();
        let c = normalized_xcorr(&a, &b, -19, 33);
        for (i, r) in c.rho.iter().enumerate() {
            let m = -19 + i as i64;
            let want = direct(&a, &b, m);
            assert!((r - want).abs() < 1e-9, "lag {m}: {r} vs {want}");
            let n = (37i64.min(23 + m) - m.max(0)) as f64;
            assert!((c.z[i] - r * (n / 23.0).sqrt()).abs() < 1e-12);
        }
    }

    #[test]
    fn finds_a_shift_and_grades_ambiguity() {
        let s: Vec<f64> = (0..300)
            .map(|k| {
                ((k as f64) * 0.05).sin() * (1.0 + (k as f64 * 0.011).cos())
                    + ((k * 7 % 13) as f64) * 0.02
            })
            .collect();
        let a = s[40..240].to_vec();
        let b = s[0..250].to_vec();
        // a[k] = s[k + 40] = b[k + 40] → lag m = −40.
        let peak = analyze_peak(&normalized_xcorr(&a, &b, -200, 150)).unwrap();
        assert_eq!(peak.lag, -40);
        assert!(peak.rho > 0.999_999);
        assert!(!peak.at_edge);

        let per: Vec<f64> = (0..4000).map(|k| (k as f64 * 0.2).sin()).collect();
        let peak = analyze_peak(&normalized_xcorr(&per[..2000], &per, -3000, 1000)).unwrap();
        assert!(peak.peak_ratio < 1.01, "{peak:?}");
    }
}
