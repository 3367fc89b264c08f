//! A DOF no estimation run ever forced — an underactuated vessel's sway
//! (the Otter's two stern propellers give τ_Y = 0) — is excited only
//! through its couplings. Its row M_i· ν̇ + D̄_i· ν = 0 is then homogeneous:
//! the data give its ratios (how it answers the forced DOFs, hence every
//! entry of A = −M⁻¹D̄) but not its scale, so the column of B = M⁻¹ on that
//! force, and with it M_ii, stays at the prior.
//!
//! Anything that turns a known force on that DOF into acceleration through
//! the estimated M then multiplies by a mass the data never saw. C(ν)ν of M
//! at the grid speed (`lambda_coriolis`) is such a force: on the
//! independent Otter it gave M_vv from 0.3 to 2589 kg (true 165) across
//! three grid speeds and free runs from −3.8 to 0.68 in sway; without it
//! the couplings at speed are estimated freely in D̄ and the free runs come
//! within 0.04 of the true model's.

use crate::identification::Segment;
use crate::numbers::sig3;
use crate::planning::VesselProfile;
use crate::planning::dof::Dof;

/// A force column whose RMS over the estimation data is below this
/// fraction of the DOF's force limit is taken as never applied.
pub(crate) const UNFORCED_FRACTION: f64 = 1e-3;

/// The DOFs of `dofs` whose force (input column i of every segment) stays
/// below [`UNFORCED_FRACTION`] of the profile's force limit in RMS over all
/// estimation segments. Empty without segments.
pub(crate) fn unforced_dofs(
    segments: &[&Segment],
    dofs: &[Dof],
    profile: &VesselProfile,
) -> Vec<Dof> {
    let samples: usize = segments.iter().map(|s| s.u.nrows()).sum();
    if samples == 0 {
        return Vec::new();
    }
    dofs.iter()
        .enumerate()
        .filter(|&(i, &d)| {
            let sum_sq: f64 = segments
                .iter()
                .filter(|s| i < s.u.ncols())
                .map(|s| s.u.column(i).iter().map(|x| x * x).sum::<f64>())
                .sum();
            let rms = (sum_sq / samples as f64).sqrt();
            rms <= UNFORCED_FRACTION * profile.limit(d).max_force.abs()
        })
        .map(|(_, &d)| d)
        .collect()
}

/// What the model says about the unforced DOFs: the mass the data leave
/// at its prior (`m_prior[i]` per DOF of `dofs`) and that the couplings at
/// speed were fitted freely (`coriolis_dropped`).
pub(crate) fn note(
    unforced: &[Dof],
    dofs: &[Dof],
    m_prior: &[f64],
    coriolis_dropped: bool,
) -> String {
    let names: Vec<String> = unforced
        .iter()
        .map(|d| {
            let i = dofs.iter().position(|x| x == d).unwrap_or(0);
            format!(
                "{} ({} = 0 throughout; M[{0},{0}] at its prior {} {})",
                d.name(),
                d.force_column(),
                sig3(m_prior.get(i).copied().unwrap_or(0.0)),
                mass_unit(*d)
            )
        })
        .collect();
    let coriolis = if coriolis_dropped {
        "; the couplings at speed are estimated freely in D̄ instead of from C(ν) of M, which would turn known forces on that DOF into acceleration through the undetermined mass"
    } else {
        ""
    };
    format!(
        "never forced in the estimation runs: {}. The data give how such a DOF answers the forced ones (its row of A = −M⁻¹D̄) but not its mass, which is the profile's prior T·F_max/v_max; predictions of the flown inputs do not depend on it, a force on that DOF (a lateral thruster, wind) would be predicted with it{coriolis}",
        names.join(", ")
    )
}

fn mass_unit(d: Dof) -> &'static str {
    if d.is_angular() { "kg·m²" } else { "kg" }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DMatrix;

    fn segment(u: DMatrix<f64>) -> Segment {
        Segment {
            run_id: "r".into(),
            h: 0.1,
            t0: 0.0,
            y: DMatrix::zeros(u.nrows(), 3),
            u,
        }
    }

    #[test]
    fn a_zero_sway_force_is_unforced_and_a_small_one_is_not() {
        let profile = crate::planning::examples::supply_vessel();
        let dofs = Dof::HORIZONTAL.to_vec();
        let n = 200;
        let forced = |k: usize| ((k as f64) * 0.3).sin();
        let limit = |d: Dof| profile.limit(d).max_force;
        // τ_Y identically zero: unforced.
        let u = DMatrix::from_fn(n, 3, |k, j| {
            if j == 1 {
                0.0
            } else {
                limit(dofs[j]) * forced(k)
            }
        });
        let s = segment(u);
        assert_eq!(unforced_dofs(&[&s], &dofs, &profile), vec![Dof::Sway]);
        // τ_Y at 1 % of its limit: forced (weakly, but the data see it).
        let u = DMatrix::from_fn(n, 3, |k, j| {
            let f = if j == 1 { 0.01 } else { 1.0 };
            f * limit(dofs[j]) * forced(k)
        });
        let s = segment(u);
        assert!(unforced_dofs(&[&s], &dofs, &profile).is_empty());
        assert!(unforced_dofs(&[], &dofs, &profile).is_empty());
    }
}
