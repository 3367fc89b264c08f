//! The Newey–West long-run covariance of score series with Bartlett
//! weights, from window sums.
//!
//! S = Γ₀ + Σ_{l=1..L} (1 − l/(L+1)) (Γ_l + Γ_lᵀ), Γ_l = Σ_k h_k h_{k−l}ᵀ,
//! equals (1/(L+1)) Σ_k B_k B_kᵀ with B_k = Σ_{j=k..k+L} h_j over the
//! zero-padded series (k = −L … len−1): the Bartlett kernel is the
//! autocorrelation of a box of width L+1, so lag l appears in L+1−|l| of
//! the windows' products. That costs t² products of length len + L per
//! block instead of t²(L+1) of length len.

use nalgebra::DMatrix;

/// Adds the Bartlett long-run covariance of the series `h` (t series of
/// one length) with `lags` lags to `s` (t × t).
pub(super) fn add_bartlett(h: &[Vec<f64>], lags: usize, s: &mut DMatrix<f64>) {
    let t = h.len();
    let Some(len) = h.first().map(Vec::len) else {
        return;
    };
    if len == 0 {
        return;
    }
    let width = lags + 1;
    // Window sums from prefix sums: P_j = Σ_{i<j} h_i.
    let sums: Vec<Vec<f64>> = h
        .iter()
        .map(|x| {
            let mut p = Vec::with_capacity(len + 1);
            let mut acc = 0.0;
            p.push(0.0);
            for v in x {
                acc += v;
                p.push(acc);
            }
            (0..len + lags)
                .map(|w| {
                    // Window w covers samples w − L … w of the series.
                    let hi = (w + 1).min(len);
                    let lo = (w + 1).saturating_sub(width);
                    p[hi] - p[lo]
                })
                .collect()
        })
        .collect();
    let scale = 1.0 / width as f64;
    let mut out = vec![0.0; t];
    for a in 0..t {
        let ys: Vec<&[f64]> = sums[a..].iter().map(Vec::as_slice).collect();
        let out = &mut out[..ys.len()];
        out.fill(0.0);
        crate::kernels::dots(&sums[a], &ys, out);
        for (b, v) in (a..t).zip(out.iter()) {
            s[(a, b)] += scale * v;
            if a != b {
                s[(b, a)] += scale * v;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::add_bartlett;
    use crate::rng::SplitMix64;
    use nalgebra::DMatrix;

    /// The definition: Γ₀ + Σ_l (1 − l/(L+1)) (Γ_l + Γ_lᵀ), summed directly.
    fn direct(h: &[Vec<f64>], lags: usize) -> DMatrix<f64> {
        let t = h.len();
        let len = h[0].len();
        let mut s = DMatrix::zeros(t, t);
        for l in 0..=lags.min(len - 1) {
            let w = 1.0 - l as f64 / (lags as f64 + 1.0);
            for a in 0..t {
                for b in 0..t {
                    let g: f64 = (l..len).map(|k| h[a][k] * h[b][k - l]).sum();
                    if l == 0 {
                        s[(a, b)] += g;
                    } else {
                        s[(a, b)] += w * g;
                        s[(b, a)] += w * g;
                    }
                }
            }
        }
        s
    }

    #[test]
    fn window_sums_give_the_bartlett_sum_of_lagged_products() {
        let mut rng = SplitMix64::new(17);
        // Coloured series with a mean, lags shorter and longer than the
        // series, a single sample.
        for &(t, len, lags) in &[(3, 200, 30), (2, 40, 30), (1, 25, 60), (4, 1, 5), (2, 9, 0)] {
            let h: Vec<Vec<f64>> = (0..t)
                .map(|_| {
                    let mut x = 0.0;
                    (0..len)
                        .map(|_| {
                            x = 0.8 * x + rng.normal();
                            x + 0.3
                        })
                        .collect()
                })
                .collect();
            let want = direct(&h, lags);
            let mut got = DMatrix::zeros(t, t);
            add_bartlett(&h, lags, &mut got);
            let scale = want.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            for (g, w) in got.iter().zip(want.iter()) {
                assert!(
                    (g - w).abs() <= 1e-12 * scale,
                    "t {t} len {len} L {lags}: {g} vs {w}"
                );
            }
            assert_eq!(got, got.transpose());
        }
    }
}
