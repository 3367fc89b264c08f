//! The state-variable filter λ(s) = 1/(1+sT) (thesis eq. 1.9) on sampled
//! signals, and the derivative it yields without raw differencing:
//! [sλν] = (ν − [λν])/T.
//!
//! Two exact discretizations, because the signals of M·ν̇ + D̄ν = γ are of two
//! kinds: the commanded τ is held between samples (zero-order hold), while ν
//! and anything computed from ν or η is continuous (first-order hold is
//! exact to O(h²)). Filtering both kinds alike would shift one against the
//! other by h/2 — a spurious "input delay" in every regression.

/// λ(s) = 1/(1+sT) discretized at sample time h.
#[derive(Debug, Clone, Copy)]
pub struct Svf {
    /// Filter time constant T (s).
    pub t: f64,
    /// e^{−h/T}.
    a: f64,
    /// Weight of s_{k+1} in the first-order-hold recursion.
    c: f64,
}

impl Svf {
    /// λ with time constant `t` at sample time `h` (both > 0).
    pub fn new(t: f64, h: f64) -> Self {
        let a = (-h / t).exp();
        // ∫ over one step of (σ/h)·e^{−(h−σ)/T}/T dσ, the weight of the
        // interpolated end sample.
        let c = 1.0 - t * (1.0 - a) / h;
        Svf { t, a, c }
    }

    /// [λx] for x held constant over each step; the state starts at x₀
    /// (so a constant signal passes unchanged).
    pub fn zoh(&self, x: &[f64]) -> Vec<f64> {
        let mut out = Vec::with_capacity(x.len());
        let Some(&x0) = x.first() else {
            return out;
        };
        let mut s = x0;
        out.push(s);
        for &xk in &x[..x.len() - 1] {
            s = self.a * s + (1.0 - self.a) * xk;
            out.push(s);
        }
        out
    }

    /// [λx] for x linear between samples; the state starts at x₀.
    pub fn foh(&self, x: &[f64]) -> Vec<f64> {
        let mut out = Vec::with_capacity(x.len());
        let Some(&x0) = x.first() else {
            return out;
        };
        let mut s = x0;
        out.push(s);
        let b0 = 1.0 - self.a - self.c;
        for w in x.windows(2) {
            s = self.a * s + b0 * w[0] + self.c * w[1];
            out.push(s);
        }
        out
    }

    /// [sλx] = (x − [λx])/T given x and its filtered version.
    pub fn derivative(&self, x: &[f64], filtered: &[f64]) -> Vec<f64> {
        x.iter()
            .zip(filtered)
            .map(|(x, f)| (x - f) / self.t)
            .collect()
    }
}

/// Samples of a first-order actuator lag τ_a = τ_c/(1+sT_a) driven by the
/// held command τ_c, starting at rest on τ_c(0) (exact for ZOH input).
pub fn lag_zoh(x: &[f64], t_a: f64, h: f64) -> Vec<f64> {
    Svf::new(t_a, h).zoh(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn derivative_of_a_sine_matches_the_filtered_cosine() {
        // x = sin ωt, T = 0.3: [sλx] must equal λ·(ω cos ωt) in steady state.
        let (h, t, w) = (0.1, 0.3, 0.7);
        let n = 600;
        let x: Vec<f64> = (0..n).map(|k| (w * k as f64 * h).sin()).collect();
        let svf = Svf::new(t, h);
        let d = svf.derivative(&x, &svf.foh(&x));
        // Treating ν as held would shift it by h/2: errors ≈ ω²h/2.
        let d_zoh = svf.derivative(&x, &svf.zoh(&x));
        // Steady-state response of λ to ω cos ωt: |λ| = 1/√(1+ω²T²), phase −atan(ωT).
        let g = 1.0 / (1.0 + (w * t).powi(2)).sqrt();
        let ph = -(w * t).atan();
        let mut worst = (0.0_f64, 0.0_f64);
        for (k, (dk, dz)) in d.iter().zip(&d_zoh).enumerate().skip(100) {
            let exact = w * g * (w * k as f64 * h + ph).cos();
            worst.0 = worst.0.max((dk - exact).abs());
            worst.1 = worst.1.max((dz - exact).abs());
        }
        // First-order hold: O(ω²h²) of linear interpolation, well below the
        // half-sample shift of a zero-order hold.
        assert!(worst.0 < 1.5e-3, "FOH error {}", worst.0);
        assert!(
            worst.1 > 10.0 * worst.0,
            "ZOH {} vs FOH {}",
            worst.1,
            worst.0
        );
    }

    #[test]
    fn zoh_filter_is_exact_for_held_steps_and_constants_pass() {
        let (h, t) = (0.1, 0.5);
        let x: Vec<f64> = (0..50).map(|k| if k < 10 { 0.0 } else { 1.0 }).collect();
        let f = Svf::new(t, h).zoh(&x);
        for (k, fk) in f.iter().enumerate().skip(11) {
            let exact = 1.0 - (-((k - 10) as f64) * h / t).exp();
            assert!((fk - exact).abs() < 1e-12);
        }
        let c = Svf::new(t, h).foh(&[2.0; 20]);
        assert!(c.iter().all(|v| (v - 2.0).abs() < 1e-12));
        assert!(Svf::new(t, h).zoh(&[]).is_empty());
    }
}
