//! The baseline's quadratic damping on the velocity through the water when
//! a current is fitted or held.
//!
//! The hull's drag follows ν_r = ν − ν_c(ψ): D_q|δ_r|δ_r, not D_q|δ|δ of
//! the velocity over ground that the known side was formed with. It is
//! not linear in the current (V_N, V_E), so each fit linearizes it at the
//! previous pass's estimate θ̂ (Gauss–Newton inside the fixed point on M
//! and D̄): the known side moves by q(θ̂) − q(0) − Jθ̂ and the current's
//! regressors gain J = ∂q/∂θ. A held current enters exactly, q(θ_h) − q(0).
//! Only surge and sway feel ν_c; D_q is diagonal, so only their rows move.

use super::*;
use crate::models::quadratic_damping::surge_remainder;

/// How the baseline's D_q|δ|δ moves one row's equation on one run.
pub(super) struct ThroughWater {
    /// Filtered known-side shift, to subtract from the target.
    pub shift: Vec<f64>,
    /// Filtered J per coefficient (north, east) when the current is free.
    pub jacobian: Option<[Vec<f64>; 2]>,
}

impl Prepared<'_> {
    /// The shift of row `r` on `run` with the current at `at` (held: exact,
    /// no J), `None` when D_q does not act on that row's velocity through
    /// the water (no D_q, not surge or sway, or a zero entry).
    pub(super) fn through_water(
        &self,
        r: usize,
        run: usize,
        at: [f64; 2],
        held: bool,
    ) -> Option<ThroughWater> {
        let b = self.baseline;
        let q = b.quadratic.as_ref()?;
        let d = q.d_q.get(r).copied().filter(|d| *d != 0.0)?;
        let surge = b.index_of(Dof::Surge);
        let is_surge = surge == Some(r);
        if !is_surge && b.index_of(Dof::Sway) != Some(r) {
            return None;
        }
        // The row's drag f(δ) and its slope f'(δ): surge's remainder about
        // u₀, |v|v in sway.
        let f = |x: f64| {
            if is_surge {
                surge_remainder(x, q.u0)
            } else {
                x.abs() * x
            }
        };
        let slope = |x: f64| {
            if is_surge {
                2.0 * x.abs() - 2.0 * q.u0.abs()
            } else {
                2.0 * x.abs()
            }
        };
        let rec = &self.records[run];
        let len = rec.len();
        let mut shift = Vec::with_capacity(len);
        let (mut jn, mut je) = (Vec::with_capacity(len), Vec::with_capacity(len));
        let trig = self.stage_trig(run);
        for (k, t) in trig.iter().enumerate().take(len) {
            let (s, c) = t[0].psi;
            // `body_current(at, ψ)` with the sine and cosine in hand.
            let (uc, vc) = (at[0] * c + at[1] * s, -at[0] * s + at[1] * c);
            let v = rec.nu[(k, r)];
            let rel = v - if is_surge { uc } else { vc };
            // ∂ν_c,r/∂(V_N, V_E).
            let (dn, de) = if is_surge { (c, s) } else { (-s, c) };
            let g = -d * slope(rel);
            let (a, e) = (g * dn, g * de);
            let mut dq = d * (f(rel) - f(v));
            if !held {
                dq -= a * at[0] + e * at[1];
            }
            shift.push(dq);
            if !held {
                jn.push(a);
                je.push(e);
            }
        }
        Some(ThroughWater {
            shift: self.svf.foh(&shift),
            jacobian: (!held).then(|| [self.svf.foh(&jn), self.svf.foh(&je)]),
        })
    }
}
