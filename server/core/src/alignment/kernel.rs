//! Gaussian-kernel (Nadaraya–Watson) smoothing of irregular samples: the
//! zero-phase prefilter of the sub-sample refinement.
//!
//! Why smooth: an interpolant through noisy samples (linear, cubic) weights
//! their noise differently at different fractional positions, so the noise
//! energy of the interpolated record — and with it the mismatch — varies
//! with the offset's fraction and pulls its minimum (measured ~0.05–0.15
//! sample at 30 dB SNR with equal rates, where every sample sits at the same
//! fraction). A Gaussian kernel of width σ ≥ one sample interval weights the
//! noise alike at every fraction (`Σ wᵢ²` ripple ≈ 2·exp(−π²σ²/Δ²), 1e-4 at
//! σ = Δ) and, being symmetric, delays nothing. Applied with the same σ to
//! both logs it also leaves their signal parts equal, and removes the noise
//! above the shared band that only adds scatter.

/// Kernel half-support in kernel widths (weights below exp(−8) ignored).
pub(crate) const SUPPORT: f64 = 4.0;

/// Nadaraya–Watson smoothing of `(t, x − center)` (t strictly increasing)
/// with a Gaussian of width `sigma` (s), evaluated at the ascending times
/// `at`. A time with no sample within reach gets 0.
pub(crate) fn smooth(
    t: &[f64],
    x: &[f64],
    center: f64,
    sigma: f64,
    at: impl Iterator<Item = f64>,
) -> Vec<f64> {
    let n = t.len().min(x.len());
    let (t, x) = (&t[..n], &x[..n]);
    let inv_2s2 = 0.5 / (sigma * sigma);
    let reach = SUPPORT * sigma;
    let mut first = 0usize;
    at.map(|s| {
        let lo = s - reach;
        if first > 0 && t[first - 1] >= lo {
            first = t.partition_point(|&v| v < lo);
        }
        while first < n && t[first] < lo {
            first += 1;
        }
        let (mut num, mut den) = (0.0, 0.0);
        for (ti, xi) in t[first..].iter().zip(&x[first..]) {
            let u = ti - s;
            if u > reach {
                break;
            }
            let g = (-u * u * inv_2s2).exp();
            num += g * (xi - center);
            den += g;
        }
        if den > 0.0 { num / den } else { 0.0 }
    })
    .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reproduces_a_line_between_jittered_samples() {
        let t: Vec<f64> = (0..100)
            .map(|k| k as f64 * 0.1 + 0.001 * ((k * 7) % 5) as f64)
            .collect();
        let x: Vec<f64> = t.iter().map(|v| 2.0 - 0.5 * v).collect();
        let at: Vec<f64> = (0..40).map(|j| 2.0 + j as f64 * 0.137).collect();
        let y = smooth(&t, &x, 1.0, 0.1, at.iter().copied());
        for (s, v) in at.iter().zip(&y) {
            // Symmetric weights reproduce a line up to the tiny imbalance of
            // the jittered stamps.
            assert!((v + 1.0 - (2.0 - 0.5 * s)).abs() < 1e-3, "{s}: {v}");
        }
        // A time far from every sample gets 0; going backwards is fine.
        let y = smooth(&t, &x, 0.0, 0.1, [50.0, 3.0].into_iter());
        assert_eq!(y[0], 0.0);
        assert!((y[1] - 0.5).abs() < 1e-2);
    }

    #[test]
    fn noise_gain_does_not_depend_on_the_fraction() {
        // Σ wᵢ² at fractions 0 and 0.5 of a uniform grid, σ = one interval.
        let gain = |s: f64| {
            let w: Vec<f64> = (0..50)
                .map(|i| (-(i as f64 - s).powi(2) / 2.0).exp())
                .collect();
            let sum: f64 = w.iter().sum();
            w.iter().map(|v| (v / sum).powi(2)).sum::<f64>()
        };
        let (a, b) = (gain(25.0), gain(25.5));
        assert!((a / b - 1.0).abs() < 3e-4, "{a} {b}");
    }
}
