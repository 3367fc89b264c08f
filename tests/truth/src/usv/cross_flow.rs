//! Cross-flow drag by strip theory (Fossen 2021, ch. 6, "cross-flow drag
//! principle"; MSS `LIBRARY/modeling/crossFlowDrag.m`): each strip dx of a
//! hull of draft T meets the local transverse relative velocity
//! v_r + x·r and feels the 2-D drag of a flat-bottomed section,
//!
//!   Y_cf = −½ ρ T ∫ C_d^2D |v_r + x r| (v_r + x r) dx,
//!   N_cf = −½ ρ T ∫ C_d^2D x |v_r + x r| (v_r + x r) dx,
//!
//! over x ∈ [−L/2, L/2] from the coordinate origin (midships). These are
//! forces on the vessel (right-hand side of the equations of motion).
//! C_d^2D is Hoerner's curve of the section's beam-to-draft ratio B/2T
//! ([`hoerner_cd`]). MSS sums 21 strip midpoints; here the integral is
//! exact: the integrand is ±(a + b x)² and ±x(a + b x)² on either side of
//! the zero of a + b x, and two-point Gauss–Legendre is exact for cubics.

/// Hoerner's 2-D cross-flow drag coefficient C_d^2D against B/2T, as
/// digitised in MSS `HYDRO/Hoerner.m` (Fossen; data from Hoerner 1965 via
/// Leite, Aranha, Umeda & Conti 1998, Applied Ocean Research 20): pairs
/// (B/2T, C_d).
pub const HOERNER_CURVE: [(f64, f64); 20] = [
    (0.0108623, 1.96608),
    (0.176606, 1.96573),
    (0.353025, 1.89756),
    (0.451863, 1.78718),
    (0.472838, 1.58374),
    (0.492877, 1.27862),
    (0.493252, 1.21082),
    (0.558473, 1.08356),
    (0.646401, 0.998631),
    (0.833589, 0.87959),
    (0.988002, 0.828415),
    (1.30807, 0.759941),
    (1.63918, 0.691442),
    (1.85998, 0.657076),
    (2.31288, 0.630693),
    (2.59998, 0.596186),
    (3.00877, 0.586846),
    (3.45075, 0.585909),
    (3.7379, 0.559877),
    (4.00309, 0.559315),
];

/// C_d^2D(B/2T) of a section of beam `beam` and draft `draft`: Hoerner's
/// curve ([`HOERNER_CURVE`]) interpolated linearly, held at its end values
/// outside the table (as MSS does above B/2T = 4.00309).
pub fn hoerner_cd(beam: f64, draft: f64) -> f64 {
    let x = beam / (2.0 * draft);
    let c = &HOERNER_CURVE;
    if x <= c[0].0 {
        return c[0].1;
    }
    for w in c.windows(2) {
        let ((x0, y0), (x1, y1)) = (w[0], w[1]);
        if x <= x1 {
            return y0 + (y1 - y0) * (x - x0) / (x1 - x0);
        }
    }
    c[c.len() - 1].1
}

/// A hull for cross-flow drag: length, draft and the 2-D drag coefficient
/// of its sections (the same along the hull, as in MSS).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CrossFlow {
    /// Length L over which strips are integrated (m), x ∈ [−L/2, L/2].
    pub length_m: f64,
    /// Draft T (m).
    pub draft_m: f64,
    /// C_d^2D (−); nominally [`hoerner_cd`] of the section's beam and draft.
    pub cd: f64,
    /// Water density ρ (kg/m³).
    pub rho: f64,
}

impl CrossFlow {
    /// (Y_cf, N_cf), the cross-flow force (N) and moment (N·m) on the vessel
    /// at relative sway velocity `v_r` (m/s) and yaw rate `r` (rad/s).
    pub fn force(&self, v_r: f64, r: f64) -> (f64, f64) {
        let (i0, i1) = strip_integrals(v_r, r, -0.5 * self.length_m, 0.5 * self.length_m);
        let k = -0.5 * self.rho * self.draft_m * self.cd;
        (k * i0, k * i1)
    }
}

/// (∫ |s| s dx, ∫ x |s| s dx) over [lo, hi] with s = a + b x, exact up to
/// rounding: split at the zero of s, two-point Gauss–Legendre per piece.
pub fn strip_integrals(a: f64, b: f64, lo: f64, hi: f64) -> (f64, f64) {
    let mut cuts = vec![lo];
    if b != 0.0 {
        let x0 = -a / b;
        if x0 > lo && x0 < hi {
            cuts.push(x0);
        }
    }
    cuts.push(hi);
    // Nodes ±1/√3, weights 1.
    let g = 1.0 / 3f64.sqrt();
    let (mut i0, mut i1) = (0.0, 0.0);
    for w in cuts.windows(2) {
        let (mid, half) = (0.5 * (w[0] + w[1]), 0.5 * (w[1] - w[0]));
        for node in [-g, g] {
            let x = mid + half * node;
            let s = a + b * x;
            let f = s.abs() * s;
            i0 += half * f;
            i1 += half * x * f;
        }
    }
    (i0, i1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hoerner_curve_interpolates_and_holds_its_ends() {
        // A table point, a midpoint, both ends.
        assert!((hoerner_cd(2.0 * 1.30807, 1.0) - 0.759941).abs() < 1e-12);
        let mid = hoerner_cd(1.30807 + 1.63918, 1.0);
        assert!((mid - 0.5 * (0.759941 + 0.691442)).abs() < 1e-12);
        assert_eq!(hoerner_cd(0.001, 1.0), 1.96608);
        assert_eq!(hoerner_cd(10.0, 1.0), 0.559315);
    }

    /// The integrals against a fine midpoint sum.
    #[test]
    fn strip_integrals_match_a_fine_sum() {
        for &(a, b) in &[(0.3, 0.0), (0.0, 0.7), (0.5, 1.0), (-0.2, 0.9), (1.0, -3.0)] {
            let (i0, i1) = strip_integrals(a, b, -1.3, 1.3);
            let n = 200_000;
            let dx = 2.6 / n as f64;
            let (mut s0, mut s1) = (0.0, 0.0);
            for k in 0..n {
                let x = -1.3 + (k as f64 + 0.5) * dx;
                let s = a + b * x;
                s0 += s.abs() * s * dx;
                s1 += x * s.abs() * s * dx;
            }
            assert!((i0 - s0).abs() < 1e-8, "{a} {b}: {i0} vs {s0}");
            assert!((i1 - s1).abs() < 1e-8, "{a} {b}: {i1} vs {s1}");
        }
    }
}
