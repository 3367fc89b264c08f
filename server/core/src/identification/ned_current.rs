//! A current fixed in NED for horizontal (surge–sway–yaw) models of surface
//! vessels, estimated once for the campaign.
//!
//! Hull damping acts on the velocity through the water ν_r = ν − ν_c
//! (Fossen 2021, eq. 6.111), and a current of constant speed and direction
//! in NED, V = [V_N, V_E]ᵀ, is seen in the body frame as
//! ν_c(ψ) = [V_N cos ψ + V_E sin ψ, −V_N sin ψ + V_E cos ψ, 0]ᵀ
//! = Q(V)·e(ψ), Q(V) = [[V_N, V_E], [V_E, −V_N]], e(ψ) = [cos ψ, sin ψ]ᵀ.
//! In the λ regression M ν̇ + D̄ ν + F e = γ the current is the term
//! F = −D̄_{:,uv}·Q(V) on the heading shapes e(ψ): D̄'s surge and sway
//! columns hold the hydrodynamic damping and the Munk moment's linear part,
//! which act on ν_r (C_RB's terms sit in the yaw column).
//!
//! 1. With the constant loads, F is estimated freely per grid point
//!    ([`append`], [`specification`]); each point's F and D̄ give its V by
//!    weighted least squares ([`current_of`]).
//! 2. The points' V are pooled by inverse covariance ([`pool`]) — one
//!    current for the campaign — and kept only when it differs from zero
//!    beyond the data's noise.
//! 3. The sub-models are refitted on γ − F e(ψ) with F = −D̄₁·Q(V) of the
//!    first pass's D̄ ([`subtract`]); that F is stored per point and
//!    predictions integrate ψ from the model's own yaw rate
//!    ([`super::heading_loop`]).

use nalgebra::{DMatrix, DVector, Matrix2, Vector2};

use super::dataset::Segment;
use super::document::{NedCurrentDoc, ParameterRow};
use super::roles::Roles;
use crate::estimation::lambda::{Exogenous, Experiment, LambdaEstimate};
use crate::logs::schema::pose_column;
use crate::models::current::{body_current, body_current_tilted};
use crate::numbers::sig3;
use crate::planning::dof::Dof;
use crate::planning::vessel::VesselProfile;

/// Names of the heading shapes among the exogenous columns.
pub(crate) const COS_PSI: &str = "cos ψ";
pub(crate) const SIN_PSI: &str = "sin ψ";

/// χ² of V = 0 (2 degrees of freedom) above which the current is kept:
/// the 99 % point.
const KEEP_CHI2: f64 = 9.21;

/// Whether `dofs` is a horizontal model, on which the current is estimated
/// by default: surge, sway and yaw modelled, no heave, roll or pitch.
pub(crate) fn applies(dofs: &[Dof]) -> bool {
    [Dof::Surge, Dof::Sway, Dof::Yaw]
        .iter()
        .all(|d| dofs.contains(d))
        && !dofs
            .iter()
            .any(|d| matches!(d, Dof::Heave | Dof::Roll | Dof::Pitch))
}

/// Whether a current can be estimated for `dofs`: surge, sway and yaw
/// modelled. With heave, roll and pitch too, ν_c(η) = J₁(η)ᵀ[V_N V_E 0]ᵀ
/// is taken at small roll and pitch: [u_c, v_c] of the heading alone.
pub(crate) fn possible(dofs: &[Dof]) -> bool {
    [Dof::Surge, Dof::Sway, Dof::Yaw]
        .iter()
        .all(|d| dofs.contains(d))
}

/// e(ψ) = [cos ψ, sin ψ] held over each step like γ: row k is the mean of
/// its values at ψ_k and ψ_{k+1} (the last row e(ψ_{N−1})).
pub(crate) fn functions_of(psi: &[f64]) -> DMatrix<f64> {
    let n = psi.len();
    let e = |k: usize| {
        let (s, c) = psi[k].sin_cos();
        [c, s]
    };
    DMatrix::from_fn(n, 2, |k, j| {
        if k + 1 < n {
            0.5 * (e(k)[j] + e(k + 1)[j])
        } else {
            e(k)[j]
        }
    })
}

/// The heading ψ (rad) of a segment: its input column `psi_col`.
pub(crate) fn heading(seg: &Segment, psi_col: usize) -> Vec<f64> {
    seg.u.column(psi_col).iter().copied().collect()
}

/// `exp` with e(ψ) of `seg` (ψ its input column `psi_col`) appended to
/// its exogenous columns.
pub(crate) fn append(exp: Experiment, seg: &Segment, psi_col: usize) -> Experiment {
    let e = functions_of(&heading(seg, psi_col));
    let rows = exp.exogenous.nrows();
    let q = exp.exogenous.ncols();
    let mut x = DMatrix::zeros(rows, q + 2);
    x.columns_mut(0, q).copy_from(&exp.exogenous);
    x.columns_mut(q, 2).copy_from(&e.rows(0, rows));
    Experiment {
        exogenous: x,
        ..exp
    }
}

/// `base` (or nothing) with the heading shapes on every DOF; their prior
/// std is ten times each DOF's force limit (weak), like the loads'.
pub(crate) fn specification(
    base: Option<Exogenous>,
    profile: &VesselProfile,
    dofs: &[Dof],
) -> Exogenous {
    let n = dofs.len();
    let base = base.unwrap_or_else(|| super::joint_restoring::no_exogenous(profile, dofs));
    let q = base.names.len();
    let mut names = base.names.clone();
    names.extend([COS_PSI.to_string(), SIN_PSI.to_string()]);
    let pattern = DMatrix::from_fn(n, q + 2, |i, j| j >= q || base.pattern[(i, j)]);
    Exogenous {
        names,
        pattern,
        force_std: base.force_std,
    }
}

/// A current V = [V_N, V_E] (m/s) with its covariance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct CurrentEstimate {
    pub v: Vector2<f64>,
    pub cov: Matrix2<f64>,
    /// χ²/dof of the estimates pooled about the mean (1 for one).
    pub birge_ratio_sq: f64,
    /// Estimates pooled.
    pub count: usize,
}

impl CurrentEstimate {
    /// Speed |V| (m/s) and its std (first order).
    pub fn speed(&self) -> (f64, f64) {
        let s = self.v.norm();
        if s == 0.0 {
            return (0.0, self.cov.trace().max(0.0).sqrt());
        }
        let d = self.v / s;
        (s, (d.transpose() * self.cov * d)[0].max(0.0).sqrt())
    }

    /// Direction the current flows towards (rad, from north towards east)
    /// and its std (first order).
    pub fn direction(&self) -> (f64, f64) {
        let s2 = self.v.norm_squared();
        let beta = self.v[1].atan2(self.v[0]);
        if s2 == 0.0 {
            return (beta, std::f64::consts::PI);
        }
        let g = Vector2::new(-self.v[1], self.v[0]) / s2;
        (beta, (g.transpose() * self.cov * g)[0].max(0.0).sqrt())
    }

    /// χ² of V = 0 under the covariance.
    pub fn chi2_of_zero(&self) -> f64 {
        match self.cov.try_inverse() {
            Some(inv) => (self.v.transpose() * inv * self.v)[0],
            None => 0.0,
        }
    }

    /// Whether the data hold a current beyond their noise.
    pub fn significant(&self) -> bool {
        self.chi2_of_zero() > KEEP_CHI2
    }
}

/// Indices of surge and sway in `dofs`.
fn uv(dofs: &[Dof]) -> Option<(usize, usize)> {
    let u = dofs.iter().position(|d| *d == Dof::Surge)?;
    let v = dofs.iter().position(|d| *d == Dof::Sway)?;
    Some((u, v))
}

/// The current one sub-model's F on e(ψ) and its D̄ imply: F = −D̄_{:,uv}
/// Q(V), two unknowns from 2n entries weighted by F's std (D̄'s own error
/// is second order against F's). `None` without the heading columns or
/// when D̄'s surge and sway columns cannot carry a current.
pub(crate) fn current_of(est: &LambdaEstimate) -> Option<CurrentEstimate> {
    let (iu, iv) = uv(&est.dofs)?;
    let jc = est.exogenous.iter().position(|e| e == COS_PSI)?;
    let js = est.exogenous.iter().position(|e| e == SIN_PSI)?;
    let n = est.dofs.len();
    let d = &est.d_bar;
    let mut normal = Matrix2::zeros();
    let mut rhs = Vector2::zeros();
    let mut rows = Vec::new();
    for i in 0..n {
        // cos ψ column: F_ic = −D_iu V_N − D_iv V_E; sin ψ: F_is = D_iv V_N − D_iu V_E.
        for (j, g) in [
            (jc, Vector2::new(-d[(i, iu)], -d[(i, iv)])),
            (js, Vector2::new(d[(i, iv)], -d[(i, iu)])),
        ] {
            let sd = est.std_force[(i, j)];
            let f = est.force[(i, j)];
            if !(sd.is_finite() && sd > 0.0 && f.is_finite()) {
                continue;
            }
            let w = 1.0 / (sd * sd);
            normal += g * g.transpose() * w;
            rhs += g * (f * w);
            rows.push((g, f, w));
        }
    }
    let cov = normal.try_inverse()?;
    let v = cov * rhs;
    if !v.iter().all(|x| x.is_finite()) {
        return None;
    }
    let dof = rows.len().saturating_sub(2).max(1);
    let chi2: f64 = rows
        .iter()
        .map(|(g, f, w)| (f - g.dot(&v)).powi(2) * w)
        .sum();
    let birge = chi2 / dof as f64;
    Some(CurrentEstimate {
        v,
        cov: cov * birge.max(1.0),
        birge_ratio_sq: birge,
        count: 1,
    })
}

/// The grid points' currents pooled by inverse covariance, the covariance
/// inflated by the Birge ratio when they disagree beyond their own.
pub(crate) fn pool(estimates: &[CurrentEstimate]) -> Option<CurrentEstimate> {
    let mut info = Matrix2::zeros();
    let mut rhs = Vector2::zeros();
    let mut used = Vec::new();
    for e in estimates {
        if let Some(w) = e.cov.try_inverse() {
            info += w;
            rhs += w * e.v;
            used.push((e.v, w));
        }
    }
    let cov = info.try_inverse()?;
    let v = cov * rhs;
    let dof = 2 * used.len().saturating_sub(1);
    let chi2: f64 = used
        .iter()
        .map(|(x, w)| ((x - v).transpose() * w * (x - v))[0])
        .sum();
    let birge = if dof > 0 { chi2 / dof as f64 } else { 1.0 };
    Some(CurrentEstimate {
        v,
        cov: cov * birge.max(1.0),
        birge_ratio_sq: birge,
        count: used.len(),
    })
}

/// F (n × 2) of a sub-model's D̄ for the current `v`: −D̄_{:,uv}·Q(V).
pub(crate) fn force(d_bar: &DMatrix<f64>, dofs: &[Dof], v: &Vector2<f64>) -> DMatrix<f64> {
    let Some((iu, iv)) = uv(dofs) else {
        return DMatrix::zeros(dofs.len(), 2);
    };
    DMatrix::from_fn(dofs.len(), 2, |i, j| {
        let (du, dv) = (d_bar[(i, iu)], d_bar[(i, iv)]);
        match j {
            0 => -du * v[0] - dv * v[1],
            _ => dv * v[0] - du * v[1],
        }
    })
}

/// The current's surge component in the body frame,
/// u_c(ψ) = V_N cos ψ + V_E sin ψ (m/s), V = [V_N, V_E]: the forward speed
/// through the water is u − u_c(ψ).
pub(crate) fn surge_component(v: [f64; 2], psi: f64) -> f64 {
    body_current(v, psi).0
}

/// ν_c = R(φ, θ, ψ)ᵀ[V_N V_E 0]ᵀ in the order of `dofs` (its linear
/// components; the rates are the vehicle's own).
pub(crate) fn nu_c_tilted(
    dofs: &[Dof],
    v: [f64; 2],
    phi: f64,
    theta: f64,
    psi: f64,
) -> DVector<f64> {
    let (u_c, v_c, w_c) = body_current_tilted(v, phi, theta, psi);
    DVector::from_iterator(
        dofs.len(),
        dofs.iter().map(|d| match d {
            Dof::Surge => u_c,
            Dof::Sway => v_c,
            Dof::Heave => w_c,
            _ => 0.0,
        }),
    )
}

/// A known current, for the sub-models' fits on the velocity through the
/// water ([`Relative::apply`]).
#[derive(Debug, Clone)]
pub(crate) struct Relative {
    pub dofs: Vec<Dof>,
    /// V = [V_N, V_E] (m/s).
    pub v: Vector2<f64>,
    /// The columns of φ and θ in the segments, when the attitude is logged
    /// (a 6-DOF vehicle): ν_c then comes from the whole rotation.
    pub tilt: Option<(usize, usize)>,
}

impl Relative {
    /// `exp` of `seg` (ψ its input column `psi_col`) on the velocity
    /// through the water: ν_r = ν − ν_c(ψ) per sample in place of ν, γ
    /// unchanged. For a current constant in NED the whole model reads
    /// M ν̇_r + C(ν_r)ν_r + D̄ ν_r + b = τ: M_RB ν̇ + C_RB(ν)ν =
    /// M_RB ν̇_r + C_RB(ν_r)ν_r (Fossen 2011, Property 8.1), and the added
    /// mass's M_A and C_A act on ν_r, as the damping does. So
    /// fitted on ν_r it needs no M on the known side: M ν̇_c through a mass
    /// the runs never forced (the Otter's sway) would otherwise make a row
    /// that τ leaves homogeneous depend on that mass.
    pub fn apply(&self, exp: Experiment, seg: &Segment, psi_col: usize) -> Experiment {
        let psi = heading(seg, psi_col);
        let mut nu = exp.nu.clone();
        let v = [self.v[0], self.v[1]];
        for (k, &p) in psi.iter().enumerate().take(nu.nrows()) {
            let (phi, theta) = self
                .tilt
                .map_or((0.0, 0.0), |(i, j)| (seg.u[(k, i)], seg.u[(k, j)]));
            let c = nu_c_tilted(&self.dofs, v, phi, theta, p);
            for i in 0..nu.ncols() {
                nu[(k, i)] -= c[i];
            }
        }
        Experiment { nu, ..exp }
    }
}

/// Whether every run the identification reads logs the heading `psi`; a
/// note names the first that does not (the model then carries no current).
pub(crate) fn heading_logged(roles: &Roles<'_>, notes: &mut Vec<String>) -> bool {
    let psi = pose_column(Dof::Yaw);
    let missing = roles
        .estimation
        .iter()
        .chain(&roles.validation)
        .find(|r| r.record.column(psi).is_none());
    match missing {
        Some(r) => {
            notes.push(format!(
                "run '{}' logs no heading `{psi}`: a current fixed in NED is seen through the heading, so the model carries none (constant loads only)",
                r.name
            ));
            false
        }
        None => true,
    }
}

/// The campaign's current, pooled over the grid points of the first pass.
#[derive(Debug, Clone)]
pub(crate) struct CampaignCurrent {
    pub estimate: CurrentEstimate,
}

impl CampaignCurrent {
    /// Parameter rows: V_c (m/s) and β_c (°), one for the campaign.
    pub fn parameters(&self) -> Vec<ParameterRow> {
        let (s, s_sd) = self.estimate.speed();
        let (b, b_sd) = self.estimate.direction();
        let row = |symbol: &str, value: f64, std: f64, unit: &str| ParameterRow {
            group: "current".into(),
            symbol: symbol.into(),
            grid_speed_mps: None,
            value,
            std: Some(std),
            unit: unit.into(),
        };
        vec![
            row("V_c", s, s_sd, "m/s"),
            row(
                "β_c",
                b.to_degrees().rem_euclid(360.0),
                b_sd.to_degrees(),
                "°",
            ),
        ]
    }

    /// The document's summary.
    pub fn doc(&self) -> NedCurrentDoc {
        let (s, s_sd) = self.estimate.speed();
        let (b, b_sd) = self.estimate.direction();
        NedCurrentDoc {
            speed_mps: s,
            speed_std_mps: s_sd,
            direction_deg: b.to_degrees().rem_euclid(360.0),
            direction_std_deg: b_sd.to_degrees(),
            ned_mps: [self.estimate.v[0], self.estimate.v[1]],
            evidence: note(&self.estimate, true),
        }
    }
}

/// The current of the first pass's sub-models (`joint`: each fitted with
/// the heading shapes free), pooled over the grid; `None` (with a note)
/// when no point carries one or it is within the noise.
pub(crate) fn campaign_current(
    joint: &[(f64, LambdaEstimate)],
    notes: &mut Vec<String>,
) -> Option<CampaignCurrent> {
    let per_point: Vec<CurrentEstimate> = joint.iter().filter_map(|(_, e)| current_of(e)).collect();
    let Some(pooled) = pool(&per_point) else {
        notes.push(
            "no grid point's damping could carry a current (its surge and sway columns give no solution): the model carries none".into(),
        );
        return None;
    };
    let kept = pooled.significant();
    notes.push(note(&pooled, kept));
    kept.then_some(CampaignCurrent { estimate: pooled })
}

/// The note on the pooled current.
pub(crate) fn note(c: &CurrentEstimate, kept: bool) -> String {
    let (s, s_sd) = c.speed();
    let (b, b_sd) = c.direction();
    let head = format!(
        "a current fixed in NED, estimated once for the campaign through the damping of the velocity through the water (ν_r = ν − ν_c(ψ)): {} ± {} m/s towards {}° ± {}° (from north towards east), from {} grid point(s) (χ²/dof between them {:.2}); χ² of no current {:.1} on 2",
        sig3(s),
        sig3(s_sd),
        sig3(b.to_degrees().rem_euclid(360.0)),
        sig3(b_sd.to_degrees()),
        c.count,
        c.birge_ratio_sq,
        c.chi2_of_zero()
    );
    if kept {
        format!(
            "{head}: the sub-models were refitted with it known, and predictions integrate the heading from the model's own yaw rate"
        )
    } else {
        format!(
            "{head}: within the noise (99 % point 9.21), so the model carries no current and the constant loads hold what there is"
        )
    }
}

#[cfg(test)]
mod tests;
