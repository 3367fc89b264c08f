//! Real polynomials from and to roots: the characteristic polynomial of a
//! matrix and the roots of a polynomial (companion-matrix eigenvalues, as
//! `numpy.roots`).

use nalgebra::{Complex, DMatrix};

/// Coefficients, highest power first, of Π (s − rᵢ) (real parts: complex
/// roots of a real matrix come in conjugate pairs).
pub fn from_roots(roots: &[Complex<f64>]) -> Vec<f64> {
    let mut c = vec![Complex::new(1.0, 0.0)];
    for r in roots {
        let mut next = vec![Complex::new(0.0, 0.0); c.len() + 1];
        for (i, ci) in c.iter().enumerate() {
            next[i] += ci;
            next[i + 1] -= ci * r;
        }
        c = next;
    }
    c.iter().map(|z| z.re).collect()
}

/// det(sI − A), highest power first.
pub fn characteristic(a: &DMatrix<f64>) -> Vec<f64> {
    if a.is_empty() {
        return vec![1.0];
    }
    let eig: Vec<Complex<f64>> = a.complex_eigenvalues().iter().copied().collect();
    from_roots(&eig)
}

/// Roots of a polynomial (highest power first). Leading coefficients below
/// `rel_tol` times the largest are taken as zero (they are the rounding of
/// a cancelled difference); a constant has no roots.
pub fn roots(coeffs: &[f64], rel_tol: f64) -> Vec<Complex<f64>> {
    let scale = coeffs.iter().fold(0.0_f64, |m, c| m.max(c.abs()));
    if scale == 0.0 {
        return Vec::new();
    }
    let first = coeffs
        .iter()
        .position(|c| c.abs() > rel_tol * scale)
        .unwrap_or(coeffs.len());
    let c = &coeffs[first..];
    let deg = c.len().saturating_sub(1);
    if deg == 0 {
        return Vec::new();
    }
    // Companion matrix: first row −c[1..]/c[0], ones below the diagonal.
    let mut m = DMatrix::zeros(deg, deg);
    for j in 0..deg {
        m[(0, j)] = -c[j + 1] / c[0];
    }
    for i in 1..deg {
        m[(i, i - 1)] = 1.0;
    }
    m.complex_eigenvalues().iter().copied().collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sorted_re(mut r: Vec<Complex<f64>>) -> Vec<f64> {
        r.sort_by(|a, b| a.re.total_cmp(&b.re));
        r.iter().map(|z| z.re).collect()
    }

    #[test]
    fn roots_of_a_known_quadratic_and_cubic() {
        // s² + 3s + 2 = (s + 1)(s + 2)
        let r = sorted_re(roots(&[1.0, 3.0, 2.0], 1e-12));
        assert!((r[0] + 2.0).abs() < 1e-12 && (r[1] + 1.0).abs() < 1e-12);
        // s² + 1: ± j
        let r = roots(&[1.0, 0.0, 1.0], 1e-12);
        assert!(
            r.iter()
                .all(|z| z.re.abs() < 1e-12 && (z.im.abs() - 1.0).abs() < 1e-12)
        );
        // A cancelled leading term is dropped: 1e-17 s² + s + 2 → −2.
        let r = roots(&[1e-17, 1.0, 2.0], 1e-10);
        assert_eq!(r.len(), 1);
        assert!((r[0].re + 2.0).abs() < 1e-12);
        assert!(roots(&[3.0], 1e-12).is_empty());
    }

    #[test]
    fn characteristic_polynomial_of_a_companion_matrix() {
        // A in controllable canonical form of s³ + 6s² + 11s + 6.
        let a = DMatrix::from_row_slice(3, 3, &[0.0, 1.0, 0.0, 0.0, 0.0, 1.0, -6.0, -11.0, -6.0]);
        let c = characteristic(&a);
        for (x, y) in c.iter().zip([1.0, 6.0, 11.0, 6.0]) {
            assert!((x - y).abs() < 1e-10, "{c:?}");
        }
    }
}
