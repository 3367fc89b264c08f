//! Maps between the continuous-time model ν̇ = Aν + Bγ (A = −M⁻¹D̄,
//! B = M⁻¹, thesis eq. 2.10–2.12) and the regression matrices A_λ, B_λ of
//! ν = A_λ[λν] + B_λ[λγ].
//!
//! In continuous time (app. 7.1) A_λ = I + T·A and B_λ = T·B, inverted by
//! A = (A_λ − I)/T, B = B_λ/T (eq. 2.14–2.15): [`Inversion::Thesis`]. On
//! sampled data filtered by the exact discrete λ filter (pole a = e^{−h/T},
//! gain c = 1 − a) the identity that holds exactly is
//! ν_k = Ã[λν]_k + B̃[λγ]_k with Ã = (Φ − aI)/c and B̃ = Γ/c, where
//! Φ = e^{hA}, Γ = ∫₀ʰ e^{As} ds·B is the ZOH model: [`Inversion::Exact`]
//! recovers A = log(aI + cÃ)/h and B from Γ = cB̃. Both agree as h/T → 0;
//! the thesis map carries a relative bias ≈ h/(2T) + h·A/2 on the sampled
//! data (proved in the tests), the exact map none.

use nalgebra::DMatrix;

use super::error::LambdaError;
use super::filter::LambdaFilter;

/// How A_λ, B_λ are mapped back to A, B.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Inversion {
    /// The exact sampled-data inverse (matrix logarithm of Φ = aI + cÃ):
    /// unbiased for any h/T, so the estimate does not depend on T.
    #[default]
    Exact,
    /// Thesis eq. 2.14–2.15, A = (A_λ − I)/T, B = B_λ/T: the continuous-time
    /// relation, first-order accurate in h.
    Thesis,
}

/// e^X by scaling and squaring of a degree-≤30 Taylor series (no
/// factorization, so no failure path: a non-finite X gives a non-finite
/// result, which callers check).
pub(crate) fn expm(x: &DMatrix<f64>) -> DMatrix<f64> {
    let n = x.nrows();
    let norm = x.column_iter().map(|c| c.abs().sum()).fold(0.0, f64::max);
    if !norm.is_finite() {
        return DMatrix::from_element(n, n, f64::NAN);
    }
    let s = if norm > 0.5 {
        ((norm / 0.5).log2().ceil() as i32).clamp(0, 1000)
    } else {
        0
    };
    let y = x / 2f64.powi(s);
    let mut sum = DMatrix::identity(n, n);
    let mut term = DMatrix::identity(n, n);
    for k in 1..=30 {
        term = &term * &y / k as f64;
        sum += &term;
        if term.amax() <= 1e-18 * sum.amax() {
            break;
        }
    }
    for _ in 0..s {
        sum = &sum * &sum;
    }
    sum
}

/// Principal square root by the Denman–Beavers iteration; `None` if an
/// iterate is singular or it does not converge (eigenvalues on the closed
/// negative real axis).
fn sqrtm(a: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let n = a.nrows();
    let mut y = a.clone();
    let mut z = DMatrix::identity(n, n);
    for _ in 0..100 {
        let yi = y.clone().try_inverse()?;
        let zi = z.clone().try_inverse()?;
        let y1 = (&y + zi) * 0.5;
        let z1 = (&z + yi) * 0.5;
        let change = (&y1 - &y).amax();
        y = y1;
        z = z1;
        if !y.amax().is_finite() {
            return None;
        }
        if change <= 1e-15 * y.amax() {
            return Some(y);
        }
    }
    None
}

/// Principal matrix logarithm by inverse scaling and squaring: square
/// roots until ‖Φ^{1/2^s} − I‖₁ ≤ 1/4, then the series of log(I + X).
/// `None` when Φ has no real principal logarithm.
pub(crate) fn logm(phi: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let n = phi.nrows();
    if phi.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let eye = DMatrix::<f64>::identity(n, n);
    let norm1 = |m: &DMatrix<f64>| m.column_iter().map(|c| c.abs().sum()).fold(0.0, f64::max);
    let mut y = phi.clone();
    let mut s = 0;
    while norm1(&(&y - &eye)) > 0.25 {
        y = sqrtm(&y)?;
        s += 1;
        if s > 60 {
            return None;
        }
    }
    let x = &y - &eye;
    let mut sum = x.clone();
    let mut power = x.clone();
    for k in 2..200 {
        power = &power * &x;
        let term = &power / k as f64;
        if k % 2 == 0 {
            sum -= &term;
        } else {
            sum += &term;
        }
        if term.amax() <= 1e-18 * sum.amax().max(f64::MIN_POSITIVE) {
            break;
        }
    }
    Some(sum * 2f64.powi(s))
}

/// ZOH discretization of ν̇ = Aν + Bγ at step h: Φ = e^{hA},
/// Γ = ∫₀ʰ e^{As} ds·B, from one exponential of [[hA, hB], [0, 0]].
///
/// # Errors
/// `a`/`b` not square n × n or non-finite; h ≤ 0.
pub fn zoh(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    h: f64,
) -> Result<(DMatrix<f64>, DMatrix<f64>), LambdaError> {
    let n = a.nrows();
    if a.ncols() != n {
        return Err(LambdaError::shape("a", "must be square"));
    }
    if b.nrows() != n {
        return Err(LambdaError::shape("b", format!("must have {n} rows")));
    }
    super::error::require_positive("h", h)?;
    super::error::require_finite_matrix("a", a)?;
    super::error::require_finite_matrix("b", b)?;
    let m = b.ncols();
    let mut big = DMatrix::zeros(n + m, n + m);
    big.view_mut((0, 0), (n, n)).copy_from(&(a * h));
    big.view_mut((0, n), (n, m)).copy_from(&(b * h));
    let e = expm(&big);
    Ok((
        e.view((0, 0), (n, n)).into_owned(),
        e.view((0, n), (n, m)).into_owned(),
    ))
}

/// (A, B) → (A_λ, B_λ) for the prior.
pub(crate) fn to_lambda(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    f: &LambdaFilter,
    inversion: Inversion,
) -> Result<(DMatrix<f64>, DMatrix<f64>), LambdaError> {
    let n = a.nrows();
    match inversion {
        Inversion::Thesis => Ok((DMatrix::identity(n, n) + a * f.t, b * f.t)),
        Inversion::Exact => {
            let (phi, gam) = zoh(a, b, f.h)?;
            Ok(((phi - DMatrix::identity(n, n) * f.a) / f.c, gam / f.c))
        }
    }
}

/// (A_λ, B_λ) → (A, B) (eq. 2.14–2.15 or the exact inverse).
///
/// # Errors
/// [`LambdaError::Singular`] naming `a_lambda` when aI + cA_λ has no real
/// logarithm, or `b_lambda` when ∫₀ʰ e^{As} ds is singular.
pub(crate) fn from_lambda(
    a_l: &DMatrix<f64>,
    b_l: &DMatrix<f64>,
    f: &LambdaFilter,
    inversion: Inversion,
) -> Result<(DMatrix<f64>, DMatrix<f64>), LambdaError> {
    let n = a_l.nrows();
    let eye = DMatrix::<f64>::identity(n, n);
    match inversion {
        Inversion::Thesis => Ok(((a_l - eye) / f.t, b_l / f.t)),
        Inversion::Exact => {
            let phi = eye * f.a + a_l * f.c;
            let a = logm(&phi).ok_or_else(|| {
                LambdaError::singular(
                    "a_lambda",
                    "Φ = e^{−h/T}·I + (1 − e^{−h/T})·A_λ has no real logarithm (an eigenvalue on the negative real axis): the estimate is not a sampled continuous-time model",
                )
            })? / f.h;
            // W = ∫₀ʰ e^{As} ds from the exponential of [[hA, hI], [0, 0]].
            let mut big = DMatrix::zeros(2 * n, 2 * n);
            big.view_mut((0, 0), (n, n)).copy_from(&(&a * f.h));
            big.view_mut((0, n), (n, n))
                .copy_from(&(DMatrix::<f64>::identity(n, n) * f.h));
            let w = expm(&big).view((0, n), (n, n)).into_owned();
            let b = w
                .lu()
                .solve(&(b_l * f.c))
                .ok_or_else(|| LambdaError::singular("a_lambda", "∫₀ʰ e^{As} ds is singular"))?;
            Ok((a, b))
        }
    }
}

/// (A, B) → (M, D̄) = (B⁻¹, −B⁻¹A) (eq. 2.11–2.12).
///
/// # Errors
/// [`LambdaError::Singular`] naming `b` when B is not invertible.
pub fn mass_damping(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
) -> Result<(DMatrix<f64>, DMatrix<f64>), LambdaError> {
    let m = b
        .clone()
        .try_inverse()
        .ok_or_else(|| LambdaError::singular("b", "B = M⁻¹ is singular, so M is undefined"))?;
    if m.iter().any(|v| !v.is_finite()) {
        return Err(LambdaError::singular(
            "b",
            "B = M⁻¹ is numerically singular",
        ));
    }
    let d = -(&m * a);
    Ok((m, d))
}

/// (M, D̄) → (A, B) = (−M⁻¹D̄, M⁻¹).
///
/// # Errors
/// [`LambdaError::Singular`] naming `field` when M is not invertible.
pub(crate) fn state_space(
    m: &DMatrix<f64>,
    d: &DMatrix<f64>,
    field: &str,
) -> Result<(DMatrix<f64>, DMatrix<f64>), LambdaError> {
    let b = m
        .clone()
        .try_inverse()
        .filter(|b| b.iter().all(|v| v.is_finite()))
        .ok_or_else(|| LambdaError::singular(field, "M is singular"))?;
    Ok((-(&b * d), b))
}

/// A, B, M, D̄ and the exogenous terms from A_λ, B_λ and K_λ (n × q): the
/// exogenous columns map like inputs, K = (∫₀ʰe^{As}ds)⁻¹·c·K_λ (exact) or
/// K_λ/T (thesis), and their force coefficients are F = −M·K, so that
/// M ν̇ + D̄ ν + F e = γ. Entries of A and B outside `blocks` (the coupling
/// closure of the mask) are zeroed so round-off does not couple DOFs the
/// structure keeps apart.
///
/// # Errors
/// As [`from_lambda`] and [`mass_damping`].
pub(crate) fn physical(
    a_l: &DMatrix<f64>,
    b_l: &DMatrix<f64>,
    k_l: &DMatrix<f64>,
    f: &LambdaFilter,
    inversion: Inversion,
    blocks: &DMatrix<bool>,
) -> Result<[DMatrix<f64>; 6], LambdaError> {
    let n = a_l.nrows();
    let q = k_l.ncols();
    let mut inputs = DMatrix::zeros(n, n + q);
    inputs.columns_mut(0, n).copy_from(b_l);
    inputs.columns_mut(n, q).copy_from(k_l);
    let (mut a, bk) = from_lambda(a_l, &inputs, f, inversion)?;
    let mut b = bk.columns(0, n).into_owned();
    let k = bk.columns(n, q).into_owned();
    for ((x, y), &keep) in a.iter_mut().zip(b.iter_mut()).zip(blocks.iter()) {
        if !keep {
            *x = 0.0;
            *y = 0.0;
        }
    }
    let (m, d) = mass_damping(&a, &b)?;
    let force = -(&m * &k);
    Ok([a, b, m, d, k, force])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn example() -> (DMatrix<f64>, DMatrix<f64>) {
        let a = DMatrix::from_row_slice(3, 3, &[-0.5, 0.2, 0.0, -0.1, -1.2, 0.3, 0.05, 0.0, -2.0]);
        let b = DMatrix::from_row_slice(
            3,
            3,
            &[2e-3, 1e-4, 0.0, 1e-4, 1e-3, -2e-4, 0.0, -2e-4, 4e-3],
        );
        (a, b)
    }

    #[test]
    fn expm_matches_the_eigen_solution_of_a_rotation() {
        // e^{[[0, −w], [w, 0]]} is the rotation by w.
        let w = 7.3;
        let x = DMatrix::from_row_slice(2, 2, &[0.0, -w, w, 0.0]);
        let e = expm(&x);
        let r = DMatrix::from_row_slice(2, 2, &[w.cos(), -w.sin(), w.sin(), w.cos()]);
        assert!((e - r).amax() < 1e-12);
    }

    #[test]
    fn logm_inverts_expm() {
        let (a, _) = example();
        for scale in [0.01, 0.3, 2.0] {
            let x = &a * scale;
            let l = logm(&expm(&x)).unwrap();
            assert!((l - &x).amax() < 1e-12 * x.amax().max(1.0), "scale {scale}");
        }
        // −I has no real logarithm.
        assert!(logm(&(-DMatrix::<f64>::identity(2, 2))).is_none());
    }

    #[test]
    fn zoh_matches_the_scalar_formula() {
        let a = DMatrix::from_element(1, 1, -0.4);
        let b = DMatrix::from_element(1, 1, 2.0);
        let (phi, gam) = zoh(&a, &b, 0.1).unwrap();
        assert!((phi[(0, 0)] - (-0.04f64).exp()).abs() < 1e-15);
        let g = 2.0 * (1.0 - (-0.04f64).exp()) / 0.4;
        assert!((gam[(0, 0)] - g).abs() < 1e-15);
    }

    #[test]
    fn lambda_maps_round_trip_and_the_thesis_map_is_the_small_h_limit() {
        let (a, b) = example();
        for inv in [Inversion::Exact, Inversion::Thesis] {
            let f = LambdaFilter::new(1.5, 0.1).unwrap();
            let (al, bl) = to_lambda(&a, &b, &f, inv).unwrap();
            let (a2, b2) = from_lambda(&al, &bl, &f, inv).unwrap();
            assert!((a2 - &a).amax() < 1e-11);
            assert!((b2 - &b).amax() < 1e-14);
        }
        // As h → 0 the exact A_λ tends to I + T·A with an O(h) gap.
        let t = 1.5;
        let mut gaps = Vec::new();
        for h in [0.1, 0.01, 0.001] {
            let f = LambdaFilter::new(t, h).unwrap();
            let (al, _) = to_lambda(&a, &b, &f, Inversion::Exact).unwrap();
            let thesis = DMatrix::identity(3, 3) + &a * t;
            gaps.push((al - thesis).amax());
        }
        assert!(
            gaps[0] / gaps[1] > 8.0 && gaps[1] / gaps[2] > 8.0,
            "{gaps:?}"
        );
    }

    #[test]
    fn mass_damping_inverts_state_space() {
        let m = DMatrix::from_row_slice(2, 2, &[500.0, 20.0, 20.0, 300.0]);
        let d = DMatrix::from_row_slice(2, 2, &[100.0, 5.0, -3.0, 80.0]);
        let (a, b) = state_space(&m, &d, "m").unwrap();
        let (m2, d2) = mass_damping(&a, &b).unwrap();
        assert!((m2 - m).amax() < 1e-9 && (d2 - d).amax() < 1e-9);
        assert_eq!(
            mass_damping(&a, &DMatrix::zeros(2, 2)).unwrap_err().field(),
            "b"
        );
    }
}
