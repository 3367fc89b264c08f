//! Spectral-analysis windows (scipy's `get_window(..., fftbins=True)`).

use serde::{Deserialize, Serialize};

/// Taper applied to each Welch segment before its FFT.
///
/// Windows are the *periodic* (DFT-even, `sym=False`) variants that
/// `scipy.signal.get_window` returns for spectral analysis.
#[non_exhaustive]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Window {
    /// Periodic Hann: `w[i] = 0.5 − 0.5·cos(2π i / N)` for `i = 0..N`
    /// (scipy `'hann'`, the default of `scipy.signal.welch`). For `N = 1`
    /// the window is `[1.0]`, as in scipy.
    #[default]
    Hann,
}

impl Window {
    /// The `n` window coefficients (empty for `n == 0`).
    pub fn coefficients(&self, n: usize) -> Vec<f64> {
        match self {
            Window::Hann => hann_periodic(n),
        }
    }
}

fn hann_periodic(n: usize) -> Vec<f64> {
    if n <= 1 {
        // scipy's window length guard returns ones for M <= 1.
        return vec![1.0; n];
    }
    let step = 2.0 * std::f64::consts::PI / n as f64;
    (0..n)
        .map(|i| 0.5 - 0.5 * (step * i as f64).cos())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hann_matches_scipy_values() {
        // scipy.signal.get_window('hann', 8)
        let expected = [
            0.0,
            0.146_446_609_406_726_27,
            0.5,
            0.853_553_390_593_273_7,
            1.0,
            0.853_553_390_593_273_7,
            0.5,
            0.146_446_609_406_726_27,
        ];
        let w = Window::Hann.coefficients(8);
        assert_eq!(w.len(), 8);
        for (a, e) in w.iter().zip(expected) {
            assert!((a - e).abs() < 1e-15, "{a} vs {e}");
        }
    }

    #[test]
    fn hann_is_periodic_not_symmetric() {
        // Periodic: w[i] == w[N - i] for i >= 1, w[0] == 0 and w[N-1] != 0.
        let n = 9;
        let w = Window::Hann.coefficients(n);
        assert_eq!(w[0], 0.0);
        assert!(w[n - 1] > 0.0);
        for i in 1..n {
            assert!((w[i] - w[n - i]).abs() < 1e-15);
        }
        // Mean of a periodic Hann is exactly 1/2 and sum of squares 3N/8.
        let sum: f64 = w.iter().sum();
        let sum2: f64 = w.iter().map(|v| v * v).sum();
        assert!((sum - 0.5 * n as f64).abs() < 1e-12);
        assert!((sum2 - 3.0 * n as f64 / 8.0).abs() < 1e-12);
    }

    #[test]
    fn degenerate_lengths() {
        assert!(Window::Hann.coefficients(0).is_empty());
        assert_eq!(Window::Hann.coefficients(1), vec![1.0]);
        assert_eq!(Window::Hann.coefficients(2), vec![0.0, 1.0]);
    }

    #[test]
    fn serde_name() {
        assert_eq!(serde_json::to_string(&Window::Hann).unwrap(), "\"hann\"");
        assert_eq!(Window::default(), Window::Hann);
    }
}
