//! Brent's derivative-free minimization of a 1-D function on an interval
//! (golden section with parabolic steps; R. P. Brent, *Algorithms for
//! Minimization without Derivatives*, 1973, procedure `localmin`).

/// The minimizer of `f` on `[a, b]` to absolute tolerance about `tol`, and
/// the value there. Converges to a local minimum; on a unimodal function,
/// to the minimum. At most `max_iter` evaluations after the first.
pub(crate) fn minimize(
    mut f: impl FnMut(f64) -> f64,
    mut a: f64,
    mut b: f64,
    tol: f64,
    max_iter: usize,
) -> (f64, f64) {
    const GOLDEN: f64 = 0.381_966_011_250_105_1; // (3 − √5) / 2
    let eps = f64::EPSILON.sqrt();
    let mut x = a + GOLDEN * (b - a);
    let (mut w, mut v) = (x, x);
    let mut fx = f(x);
    let (mut fw, mut fv) = (fx, fx);
    let (mut d, mut e) = (0.0_f64, 0.0_f64);
    for _ in 0..max_iter {
        let m = 0.5 * (a + b);
        let tol1 = eps * x.abs() + tol / 3.0;
        let tol2 = 2.0 * tol1;
        if (x - m).abs() <= tol2 - 0.5 * (b - a) {
            break;
        }
        let mut golden = true;
        if e.abs() > tol1 {
            // Parabola through (v, fv), (w, fw), (x, fx).
            let r = (x - w) * (fx - fv);
            let mut q = (x - v) * (fx - fw);
            let mut p = (x - v) * q - (x - w) * r;
            q = 2.0 * (q - r);
            if q > 0.0 {
                p = -p;
            } else {
                q = -q;
            }
            if p.abs() < (0.5 * q * e).abs() && p > q * (a - x) && p < q * (b - x) {
                e = d;
                d = p / q;
                let u = x + d;
                if u - a < tol2 || b - u < tol2 {
                    d = if x < m { tol1 } else { -tol1 };
                }
                golden = false;
            }
        }
        if golden {
            e = if x < m { b - x } else { a - x };
            d = GOLDEN * e;
        }
        let u = if d.abs() >= tol1 {
            x + d
        } else if d > 0.0 {
            x + tol1
        } else {
            x - tol1
        };
        let fu = f(u);
        if fu <= fx {
            if u < x {
                b = x;
            } else {
                a = x;
            }
            (v, fv) = (w, fw);
            (w, fw) = (x, fx);
            (x, fx) = (u, fu);
        } else {
            if u < x {
                a = u;
            } else {
                b = u;
            }
            if fu <= fw || w == x {
                (v, fv) = (w, fw);
                (w, fw) = (u, fu);
            } else if fu <= fv || v == x || v == w {
                (v, fv) = (u, fu);
            }
        }
    }
    (x, fx)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_minimum_of_a_smooth_function() {
        let (x, fx) = minimize(|x| (x - 0.3217).powi(2) + 2.0, -1.0, 1.0, 1e-10, 100);
        assert!((x - 0.3217).abs() < 1e-8, "{x}");
        assert!((fx - 2.0).abs() < 1e-12);
        let (x, _) = minimize(
            |x| (x - 1.0).cosh() + 0.1 * (x - 1.0).powi(4),
            0.0,
            3.0,
            1e-10,
            100,
        );
        assert!((x - 1.0).abs() < 1e-7, "{x}");
    }

    #[test]
    fn stays_in_the_interval_when_the_minimum_is_outside() {
        let (x, _) = minimize(|x| x, 2.0, 5.0, 1e-9, 100);
        assert!((2.0..2.0 + 1e-6).contains(&x), "{x}");
    }
}
