//! The forces of the library's terms: φ_p(ν, η) per coefficient and row,
//! and Σ_p θ_p φ_p for every row at once (what the simulators integrate).

use super::*;
use crate::models::coriolis::coriolis_force6;

/// (sin, cos) of the attitude angles φ, θ, ψ of one η: the terms' forces
/// read them many times per state, and the loops that evaluate many terms
/// at the same η compute them once.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Trig {
    /// (sin φ, cos φ).
    pub phi: (f64, f64),
    /// (sin θ, cos θ).
    pub theta: (f64, f64),
    /// (sin ψ, cos ψ).
    pub psi: (f64, f64),
}

impl Trig {
    /// The angles of `eta` = (x, y, z, φ, θ, ψ).
    pub fn of(eta: &[f64; 6]) -> Self {
        Trig {
            phi: eta[3].sin_cos(),
            theta: eta[4].sin_cos(),
            psi: eta[5].sin_cos(),
        }
    }
}

/// The body axes x and y in NED's horizontal plane, (north, east) each:
/// the first two columns of R(Θ) = R_z(ψ)R_y(θ)R_x(φ), with a pull fixed
/// in NED's body components their dot products with [F_N F_E].
fn horizontal_axes(t: &Trig) -> [[f64; 2]; 2] {
    let (sp, cp) = t.phi;
    let (st, ct) = t.theta;
    let (ss, cs) = t.psi;
    [
        [cs * ct, ss * ct],
        [cs * st * sp - ss * cp, ss * st * sp + cs * cp],
    ]
}

impl Effect {
    /// φ_p for coefficient `p` in equation row `row` at (ν, η), the force
    /// it adds to the left-hand side per unit coefficient. Not used for
    /// [`Effect::Coupling`] (which enters M and D̄) nor actuator effects.
    pub fn regressor(
        &self,
        p: usize,
        row: usize,
        ctx: &TermContext<'_>,
        nu: &[f64],
        eta: &[f64; 6],
    ) -> f64 {
        self.regressor_at(p, row, ctx, nu, eta, None)
    }

    /// [`Self::regressor`] with the angles' sines and cosines given when
    /// the caller has them (`trig` must be [`Trig::of`] `eta`).
    pub fn regressor_at(
        &self,
        p: usize,
        row: usize,
        ctx: &TermContext<'_>,
        nu: &[f64],
        eta: &[f64; 6],
        trig: Option<&Trig>,
    ) -> f64 {
        let trig = || trig.copied().unwrap_or_else(|| Trig::of(eta));
        let row_dof = ctx.dofs[row];
        let v = |d: Dof| ctx.dofs.iter().position(|&x| x == d).map_or(0.0, |j| nu[j]);
        match *self {
            Effect::QuadraticDamping { dof } if dof == row_dof => {
                let x = v(dof);
                x.abs() * x
            }
            Effect::CubicDamping { dof } if dof == row_dof => v(dof).powi(3),
            Effect::CrossDamping { dof, from } if dof == row_dof => v(from).abs() * v(dof),
            Effect::CoriolisFromM => coriolis_force6(ctx.dofs, ctx.m_ref, nu)[row_dof.index()],
            Effect::CoriolisProduct { dof, a, b } if dof == row_dof => v(a) * v(b),
            Effect::Restoring { dof, shape } if dof == row_dof => {
                let t = trig();
                let ((sp, _), (st, ct)) = (t.phi, t.theta);
                match shape {
                    RestoringShape::SinTheta => st,
                    RestoringShape::CosThetaSinPhi => ct * sp,
                }
            }
            Effect::ConstantLoad { dof } if dof == row_dof => 1.0,
            Effect::Current => {
                let (Some(iu), Some(iv)) = (ctx.index(Dof::Surge), ctx.index(Dof::Sway)) else {
                    return 0.0;
                };
                let (du, dv) = (ctx.d_ref[(row, iu)], ctx.d_ref[(row, iv)]);
                let (mu, mv) = (ctx.m_ref[(row, iu)], ctx.m_ref[(row, iv)]);
                let r = v(Dof::Yaw);
                let (s, c) = trig().psi;
                // The hull feels ν_r = ν − ν_c, ν_c = R(ψ)ᵀ[V_N V_E]ᵀ =
                // [V_N c + V_E s, −V_N s + V_E c]: M ν̇_r + D̄ ν_r = τ moves
                // −D̄ ν_c and −M ν̇_c to the right, where the current turning
                // in the body frame gives ν̇_c = r·[v_c, −u_c].
                if p == 0 {
                    -(du * c - dv * s) + r * (mu * s + mv * c)
                } else {
                    -(du * s + dv * c) - r * (mu * c - mv * s)
                }
            }
            Effect::TetherPull => {
                // The pull's body components, moved to the left-hand side.
                let axis = match row_dof {
                    Dof::Surge => 0,
                    Dof::Sway => 1,
                    _ => return 0.0,
                };
                -horizontal_axes(&trig())[axis][p.min(1)]
            }
            _ => 0.0,
        }
    }
}

impl Effect {
    /// Whether the term's force reads the attitude angles (through
    /// [`Trig`]).
    pub fn reads_attitude(&self) -> bool {
        matches!(
            self,
            Effect::Restoring { .. } | Effect::Current | Effect::TetherPull
        )
    }

    /// Adds the term's force Σ_p θ_p φ_p (left-hand side) to `out`, every
    /// row at once: the same as summing [`Self::regressor`] row by row, with
    /// C(ν)ν and the current's rotation computed once per state (the
    /// simulators call this four times per RK4 step).
    pub fn add_force(
        &self,
        theta: &[f64],
        ctx: &TermContext<'_>,
        nu: &[f64],
        eta: &[f64; 6],
        out: &mut [f64],
    ) {
        self.add_force_at(theta, ctx, nu, eta, None, out)
    }

    /// [`Self::add_force`] with the angles' sines and cosines given when
    /// the caller has them (`trig` must be [`Trig::of`] `eta`).
    pub fn add_force_at(
        &self,
        theta: &[f64],
        ctx: &TermContext<'_>,
        nu: &[f64],
        eta: &[f64; 6],
        trig: Option<&Trig>,
        out: &mut [f64],
    ) {
        match *self {
            Effect::CoriolisFromM => {
                let c = coriolis_force6(ctx.dofs, ctx.m_ref, nu);
                for (o, d) in out.iter_mut().zip(ctx.dofs) {
                    *o += theta[0] * c[d.index()];
                }
            }
            Effect::Current => {
                let (Some(iu), Some(iv)) = (ctx.index(Dof::Surge), ctx.index(Dof::Sway)) else {
                    return;
                };
                let r = ctx.index(Dof::Yaw).map_or(0.0, |j| nu[j]);
                let (s, c) = trig.map_or_else(|| eta[5].sin_cos(), |t| t.psi);
                for (row, o) in out.iter_mut().enumerate().take(ctx.dofs.len()) {
                    let (du, dv) = (ctx.d_ref[(row, iu)], ctx.d_ref[(row, iv)]);
                    let (mu, mv) = (ctx.m_ref[(row, iu)], ctx.m_ref[(row, iv)]);
                    let north = -(du * c - dv * s) + r * (mu * s + mv * c);
                    let east = -(du * s + dv * c) - r * (mu * c - mv * s);
                    *o += theta[0] * north + theta[1] * east;
                }
            }
            _ => {
                let own = (trig.is_none() && self.reads_attitude()).then(|| Trig::of(eta));
                let trig = trig.or(own.as_ref());
                for (row, o) in out.iter_mut().enumerate().take(ctx.dofs.len()) {
                    for (p, th) in theta.iter().enumerate() {
                        *o += th * self.regressor_at(p, row, ctx, nu, eta, trig);
                    }
                }
            }
        }
    }
}
