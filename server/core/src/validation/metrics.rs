//! Fit measures of predictions against measurements.

use nalgebra::DMatrix;

/// NRMSE fit of one channel (thesis eq. 1.13, Ljung's "fit"):
/// 1 − ‖x − x̂‖₂ / ‖x − x̄‖₂, where x̄ is the mean of the measured x.
///
/// 1 means the prediction coincides with the measurement, 0 that it does no
/// better than the mean; it is negative for worse. Samples where either value
/// is NaN (no prediction exists, e.g. the first k rows of a k-step
/// prediction) are skipped. `None` when fewer than two samples remain or the
/// measurement is constant (the measure is undefined).
pub fn nrmse_fit(measured: &[f64], predicted: &[f64]) -> Option<f64> {
    let pairs = || {
        measured
            .iter()
            .zip(predicted)
            .filter(|(x, p)| x.is_finite() && p.is_finite())
    };
    let n = pairs().count();
    if n < 2 {
        return None;
    }
    let mean = pairs().map(|(x, _)| x).sum::<f64>() / n as f64;
    let err = pairs().map(|(x, p)| (x - p) * (x - p)).sum::<f64>().sqrt();
    let spread = pairs()
        .map(|(x, _)| (x - mean) * (x - mean))
        .sum::<f64>()
        .sqrt();
    (spread > 0.0).then(|| 1.0 - err / spread)
}

/// [`nrmse_fit`] per column of N × p matrices (one row per sample).
pub fn nrmse_fit_columns(measured: &DMatrix<f64>, predicted: &DMatrix<f64>) -> Vec<Option<f64>> {
    assert_eq!(
        measured.shape(),
        predicted.shape(),
        "measured and predicted shapes differ"
    );
    (0..measured.ncols())
        .map(|j| {
            nrmse_fit(
                measured.column(j).as_slice(),
                predicted.column(j).as_slice(),
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn perfect_mean_and_scaled_predictions() {
        let x: Vec<f64> = (0..100).map(|k| (k as f64 * 0.1).sin()).collect();
        assert_eq!(nrmse_fit(&x, &x), Some(1.0));
        let mean = x.iter().sum::<f64>() / x.len() as f64;
        let flat = vec![mean; x.len()];
        assert!(nrmse_fit(&x, &flat).unwrap().abs() < 1e-12);
        // x̂ = x̄ + 0.5 (x − x̄): error is half the spread → fit 0.5.
        let half: Vec<f64> = x.iter().map(|v| mean + 0.5 * (v - mean)).collect();
        assert!((nrmse_fit(&x, &half).unwrap() - 0.5).abs() < 1e-12);
    }

    #[test]
    fn nan_rows_are_skipped_and_degenerate_cases_are_none() {
        let x = [1.0, 2.0, 3.0, 4.0];
        let p = [f64::NAN, 2.0, 3.0, 4.0];
        assert_eq!(nrmse_fit(&x, &p), Some(1.0));
        assert_eq!(nrmse_fit(&[1.0, 1.0, 1.0], &[1.0, 1.0, 1.0]), None);
        assert_eq!(nrmse_fit(&[1.0], &[1.0]), None);
        let m = DMatrix::from_column_slice(4, 2, &[1.0, 2.0, 3.0, 4.0, 0.0, 1.0, 0.0, 1.0]);
        let fits = nrmse_fit_columns(&m, &m);
        assert_eq!(fits, vec![Some(1.0), Some(1.0)]);
    }
}
