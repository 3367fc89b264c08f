//! In-place removal of a segment's trend (scipy.signal.detrend semantics).

use super::Detrend;

/// Removes the trend selected by `kind` from `seg`, in place.
///
/// - `Constant`: subtracts the arithmetic mean.
/// - `Linear`: subtracts the least-squares straight line through
///   `(i, seg[i])`; computed on a centred time axis for accuracy. For one or
///   two samples the line fits exactly and the result is all zeros (scipy's
///   least-squares answer too, up to rounding).
pub(crate) fn detrend_in_place(kind: Detrend, seg: &mut [f64]) {
    match kind {
        Detrend::None => {}
        Detrend::Constant => {
            remove_mean(seg);
        }
        Detrend::Linear => remove_line(seg),
    }
}

fn remove_mean(seg: &mut [f64]) -> f64 {
    if seg.is_empty() {
        return 0.0;
    }
    let mean = seg.iter().sum::<f64>() / seg.len() as f64;
    seg.iter_mut().for_each(|v| *v -= mean);
    mean
}

fn remove_line(seg: &mut [f64]) {
    let n = seg.len();
    remove_mean(seg);
    if n < 2 {
        // A single demeaned sample is already 0.
        return;
    }
    let centre = (n - 1) as f64 / 2.0;
    let nf = n as f64;
    // Σ (i − centre)² = n (n² − 1) / 12.
    let stt = nf * (nf * nf - 1.0) / 12.0;
    let sty: f64 = seg
        .iter()
        .enumerate()
        .map(|(i, v)| (i as f64 - centre) * v)
        .sum();
    let slope = sty / stt;
    seg.iter_mut()
        .enumerate()
        .for_each(|(i, v)| *v -= slope * (i as f64 - centre));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn none_leaves_data_alone() {
        let mut s = vec![1.0, 5.0, -2.0];
        detrend_in_place(Detrend::None, &mut s);
        assert_eq!(s, vec![1.0, 5.0, -2.0]);
    }

    #[test]
    fn constant_removes_mean() {
        let mut s = vec![1.0, 2.0, 3.0, 6.0];
        detrend_in_place(Detrend::Constant, &mut s);
        assert_eq!(s, vec![-2.0, -1.0, 0.0, 3.0]);
    }

    #[test]
    fn linear_removes_exact_line_and_matches_scipy() {
        let mut s: Vec<f64> = (0..7).map(|i| 3.0 - 0.5 * i as f64).collect();
        detrend_in_place(Detrend::Linear, &mut s);
        assert!(s.iter().all(|v| v.abs() < 1e-14), "{s:?}");

        // scipy.signal.detrend([1., 4., 2., 8., 5.], type='linear')
        let mut s = vec![1.0, 4.0, 2.0, 8.0, 5.0];
        detrend_in_place(Detrend::Linear, &mut s);
        // slope 12/10 about the mean 4 -> residual [-0.6, 1.2, -2, 2.8, -1.4]
        let expected = [-0.6, 1.2, -2.0, 2.8, -1.4];
        for (a, e) in s.iter().zip(expected) {
            assert!((a - e).abs() < 1e-14, "{a} vs {e}");
        }
        // Residual is orthogonal to 1 and t.
        let sum: f64 = s.iter().sum();
        let sumt: f64 = s.iter().enumerate().map(|(i, v)| i as f64 * v).sum();
        assert!(sum.abs() < 1e-13 && sumt.abs() < 1e-13);
    }

    #[test]
    fn linear_short_segments_give_zeros() {
        let mut one = vec![7.0];
        detrend_in_place(Detrend::Linear, &mut one);
        assert_eq!(one, vec![0.0]);
        let mut two = vec![7.0, -3.0];
        detrend_in_place(Detrend::Linear, &mut two);
        assert!(two.iter().all(|v| v.abs() < 1e-15));
        let mut empty: Vec<f64> = vec![];
        detrend_in_place(Detrend::Linear, &mut empty);
        detrend_in_place(Detrend::Constant, &mut empty);
        assert!(empty.is_empty());
    }
}
