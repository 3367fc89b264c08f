//! Fixed-step fourth-order Runge–Kutta with the input held over the step
//! (zero-order hold), as a logger sampling a 20 Hz controller sees it.

/// One RK4 step of ẋ = f(x, u) over `h` with `u` held constant.
///
/// `f(x, u, dx)` writes the derivative into `dx` (no allocation per call).
pub fn rk4_step<F>(f: &mut F, x: &mut [f64], u: &[f64], h: f64)
where
    F: FnMut(&[f64], &[f64], &mut [f64]),
{
    let n = x.len();
    with_stages(5 * n, |buf| rk4_stages(f, x, u, h, buf));
}

/// Runs `f` on `len` zeroed scratch values: on the stack for the small
/// systems stepped millions of times (a vehicle's ν with a few extra
/// states: nine stages of 16), on the heap beyond.
pub(crate) fn with_stages<R>(len: usize, f: impl FnOnce(&mut [f64]) -> R) -> R {
    const SMALL: usize = 144;
    if len <= SMALL {
        let mut stack = [0.0f64; SMALL];
        f(&mut stack[..len])
    } else {
        f(&mut vec![0.0; len])
    }
}

fn rk4_stages<F>(f: &mut F, x: &mut [f64], u: &[f64], h: f64, buf: &mut [f64])
where
    F: FnMut(&[f64], &[f64], &mut [f64]),
{
    let n = x.len();
    let (k1, rest) = buf.split_at_mut(n);
    let (k2, rest) = rest.split_at_mut(n);
    let (k3, rest) = rest.split_at_mut(n);
    let (k4, tmp) = rest.split_at_mut(n);
    f(x, u, k1);
    for i in 0..n {
        tmp[i] = x[i] + 0.5 * h * k1[i];
    }
    f(tmp, u, k2);
    for i in 0..n {
        tmp[i] = x[i] + 0.5 * h * k2[i];
    }
    f(tmp, u, k3);
    for i in 0..n {
        tmp[i] = x[i] + h * k3[i];
    }
    f(tmp, u, k4);
    for i in 0..n {
        x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    }
}

/// Integrates ẋ = f(x, u) from `x0` with sample time `h` over the inputs
/// `u[k]` (each held for one step); returns the states x[0..=len(u)].
pub fn simulate<F>(mut f: F, x0: &[f64], u: &[Vec<f64>], h: f64) -> Vec<Vec<f64>>
where
    F: FnMut(&[f64], &[f64], &mut [f64]),
{
    let mut x = x0.to_vec();
    let mut out = Vec::with_capacity(u.len() + 1);
    out.push(x.clone());
    for uk in u {
        rk4_step(&mut f, &mut x, uk, h);
        out.push(x.clone());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_order_lag_matches_the_exponential() {
        // ẋ = (−x + u)/T, step input: x(t) = 1 − e^{−t/T}.
        let t_c = 2.0;
        let h = 0.1;
        let u = vec![vec![1.0]; 100];
        let xs = simulate(|x, u, dx| dx[0] = (u[0] - x[0]) / t_c, &[0.0], &u, h);
        for (k, x) in xs.iter().enumerate() {
            let exact = 1.0 - (-(k as f64) * h / t_c).exp();
            assert!((x[0] - exact).abs() < 1e-7, "k={k}: {} vs {exact}", x[0]);
        }
    }

    #[test]
    fn harmonic_oscillator_keeps_its_energy() {
        // ẍ = −x: energy x² + ẋ² is conserved to RK4's O(h⁴) per period.
        let u = vec![vec![]; 6283];
        let xs = simulate(
            |x, _u, dx| {
                dx[0] = x[1];
                dx[1] = -x[0];
            },
            &[1.0, 0.0],
            &u,
            1e-3,
        );
        let last = xs.last().unwrap();
        assert!((last[0] * last[0] + last[1] * last[1] - 1.0).abs() < 1e-9);
        // After ≈ 2π the state is back near (1, 0).
        assert!((last[0] - 1.0).abs() < 1e-3 && last[1].abs() < 1e-3);
    }
}
