//! The thrust layout a DP vessel is identified with, and which θ″ each
//! stage of the parallel EKF estimates.
//!
//! Any thruster set is described by its configuration T″ (Bis: force rows
//! direction cosines, the yaw row the lever arm over L) and coefficient
//! groups: thrusters of one group share a thrust coefficient K″ (Fossen et
//! al. 1995, eq. 47: the two mains K1 = K2, the aft tunnels K3 = K4), so
//! τ″ = Σ_j T″_j·K″_{g(j)}·u_j with up to four groups (θ″6 … θ″9). A vessel
//! that logs generalized forces τ (N, N·m) is one group: T″ =
//! diag(1, 1, 1/L)/F_ref with F_ref its surge force limit, so that its
//! K″ = F_ref/(m·g) and the displacement follows as m = F_ref/(g·K″).
//!
//! Stages follow the paper's decoupling (sec. 4.2, Fig. 4): SI1 estimates
//! A″_h11, SI2 the sway–yaw block of A″_h, and each stage the K″ of the
//! groups its runs drive that no earlier stage estimated.

use super::error::IdentifyError;
use crate::numbers::sig3;
use crate::planning::dof::Dof;
use crate::planning::vessel::{InputChannels, ThrusterKind, VesselProfile};
use crate::simulation::dp_ship::{N_GROUPS, N_THETA, ThrustLayout};

/// The thruster kinds of the paper's six-thruster layout, in column order:
/// two mains (K1 = K2), three tunnels (the two aft ones K3 = K4, the bow one
/// K5), one azimuth (K6).
pub(crate) const PAPER_KINDS: [ThrusterKind; 6] = [
    ThrusterKind::Main,
    ThrusterKind::Main,
    ThrusterKind::Tunnel,
    ThrusterKind::Tunnel,
    ThrusterKind::Tunnel,
    ThrusterKind::Azimuth,
];

/// A group is driven by a stage when its force's RMS there is at least this
/// share of its largest RMS over the stages.
const DRIVEN_SHARE: f64 = 0.1;

/// The layout of a DP profile with what was inferred about it (for the
/// model's notes), or the field that makes it unusable.
#[derive(Debug, Clone, PartialEq)]
pub struct EkfLayout {
    /// T″ and the coefficient group of each input column.
    pub thrust: ThrustLayout,
    /// The input columns, in the column order of T″ (thr_j or tau_*).
    pub columns: Vec<String>,
    /// Names of θ″1 … θ″9 for this layout.
    pub names: [String; N_THETA],
    /// F_ref (N) when the vessel logs generalized forces.
    pub force_ref_n: Option<f64>,
    /// How the groups were chosen.
    pub note: String,
}

/// Whether a profile's thrusters are the paper's layout (kinds in eq. 29's
/// order, no groups given).
pub(crate) fn is_paper_layout(profile: &VesselProfile) -> bool {
    match &profile.inputs {
        InputChannels::Thrusters { thrusters, .. } => {
            thrusters.iter().map(|t| t.kind).eq(PAPER_KINDS)
                && thrusters.iter().all(|t| t.coefficient_group.is_none())
        }
        InputChannels::GeneralizedForces => false,
    }
}

/// The EKF layout of a DP profile (surge, sway, yaw) whose Bis length is
/// `length_m`.
pub fn ekf_layout(profile: &VesselProfile, length_m: f64) -> Result<EkfLayout, IdentifyError> {
    let columns = crate::logs::commanded_columns(profile);
    let (thrust, force_ref_n, note) = match &profile.inputs {
        InputChannels::GeneralizedForces => {
            let f = profile.limit(Dof::Surge).max_force;
            let t = nalgebra::DMatrix::from_diagonal(&nalgebra::DVector::from_column_slice(&[
                1.0 / f,
                1.0 / f,
                1.0 / (length_m * f),
            ]));
            let note = format!(
                "Generalized forces logged: τ″ = K″·diag(1, 1, 1/L)·τ/F_ref with F_ref = {} N (the surge force limit) and one coefficient K″ = F_ref/(m·g) estimated.",
                sig3(f)
            );
            (
                ThrustLayout {
                    t,
                    groups: vec![0; 3],
                },
                Some(f),
                note,
            )
        }
        InputChannels::Thrusters { thrusters, .. } => {
            let inputs = crate::logs::commanded_inputs(profile);
            let t = nalgebra::DMatrix::from_fn(3, inputs.len(), |i, c| inputs[c].t[i]);
            let (groups, note) = if is_paper_layout(profile) {
                (
                    ThrustLayout::paper().groups,
                    "Thrust coefficients grouped as in the paper's eq. 47 (mains K1 = K2, aft tunnels K3 = K4, bow tunnel K5, azimuth K6).".to_string(),
                )
            } else if thrusters.iter().any(|t| t.coefficient_group.is_some()) {
                let mut labels: Vec<String> = Vec::new();
                let mut groups = Vec::new();
                for (j, th) in thrusters.iter().enumerate() {
                    let label = th
                        .coefficient_group
                        .clone()
                        .unwrap_or_else(|| format!("{} (own)", th.name));
                    let g = match labels.iter().position(|l| *l == label) {
                        Some(g) => g,
                        None => {
                            labels.push(label);
                            labels.len() - 1
                        }
                    };
                    if g >= N_GROUPS {
                        return Err(IdentifyError::invalid(
                            format!("vessel.inputs.thrusters[{j}].coefficient_group"),
                            format!(
                                "the parallel EKF estimates at most {N_GROUPS} thrust coefficients; thruster '{}' opens a fifth group: give thrusters that share a coefficient the same coefficient_group",
                                th.name
                            ),
                        ));
                    }
                    groups.push(g);
                }
                (
                    groups,
                    format!(
                        "Thrust coefficients grouped as the profile says: {}.",
                        labels.join(", ")
                    ),
                )
            } else if thrusters.len() <= N_GROUPS {
                (
                    (0..thrusters.len()).collect(),
                    "One thrust coefficient per thruster (no coefficient_group given in the profile).".to_string(),
                )
            } else {
                let kinds: Vec<ThrusterKind> = {
                    let mut k: Vec<ThrusterKind> = Vec::new();
                    for th in thrusters {
                        if !k.contains(&th.kind) {
                            k.push(th.kind);
                        }
                    }
                    k
                };
                (
                    thrusters
                        .iter()
                        .map(|th| kinds.iter().position(|k| *k == th.kind).unwrap_or(0))
                        .collect(),
                    format!(
                        "{} thrusters and at most {N_GROUPS} coefficients: thrusters of one kind share one ({}); set coefficient_group in the profile to group them otherwise.",
                        thrusters.len(),
                        kinds
                            .iter()
                            .map(|k| format!("{k:?}").to_lowercase())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                )
            };
            // A turning azimuth's two components share its coefficient.
            let groups = inputs.iter().map(|c| groups[c.thruster]).collect();
            (ThrustLayout { t, groups }, None, note)
        }
    };
    let names = thrust.theta_names(&columns);
    Ok(EkfLayout {
        thrust,
        columns,
        names,
        force_ref_n,
        note,
    })
}

/// RMS of each group's force (Σ_{j∈g} T_j·u_j, all three DOFs) over the
/// blocks `u` of one stage.
fn group_rms(thrust: &ThrustLayout, blocks: &[&nalgebra::DMatrix<f64>]) -> [f64; N_GROUPS] {
    let mut sum = [0.0; N_GROUPS];
    let mut n = 0usize;
    let mut row = vec![0.0; thrust.columns()];
    for u in blocks {
        for k in 0..u.nrows() {
            for (j, r) in row.iter_mut().enumerate() {
                *r = u[(k, j)];
            }
            for (g, s) in sum.iter_mut().enumerate() {
                *s += thrust.group_force(g, &row).norm_squared();
            }
            n += 1;
        }
    }
    sum.map(|s| if n > 0 { (s / n as f64).sqrt() } else { 0.0 })
}

/// The θ″ each stage SI1–SI3 estimates, from the commands `stages[s]` of
/// its blocks: SI1 A″_h11, SI2 A″_h22 … A″_h33, and each stage the K″ of
/// the groups it drives first. A stage that would estimate nothing gets an
/// empty list (its runs are not used). Errors name a group no run drives.
pub fn stage_frees(
    layout: &EkfLayout,
    stages: &[Vec<&nalgebra::DMatrix<f64>>; 3],
) -> Result<[Vec<usize>; 3], IdentifyError> {
    let rms: Vec<[f64; N_GROUPS]> = stages
        .iter()
        .map(|b| group_rms(&layout.thrust, b))
        .collect();
    let mut frees: [Vec<usize>; 3] = [vec![0], vec![1, 2, 3, 4], Vec::new()];
    for g in (0..N_GROUPS).filter(|&g| layout.thrust.uses(g)) {
        let top = rms.iter().map(|r| r[g]).fold(0.0, f64::max);
        match (0..3).find(|&s| top > 0.0 && rms[s][g] >= DRIVEN_SHARE * top) {
            Some(s) => frees[s].push(5 + g),
            None => {
                let members: Vec<&str> = (0..layout.thrust.columns())
                    .filter(|&j| layout.thrust.groups[j] == g)
                    .map(|j| layout.columns[j].as_str())
                    .collect();
                return Err(IdentifyError::invalid(
                    "run_ids",
                    format!(
                        "no estimation run drives {}, so its thrust coefficient {} cannot be estimated: fly a manoeuvre with it (dp_surge, dp_sway_yaw or dp_azimuth)",
                        members.join(", "),
                        layout.names[5 + g]
                    ),
                ));
            }
        }
    }
    for f in &mut frees {
        f.sort_unstable();
    }
    Ok(frees)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::planning::examples::supply_vessel;
    use crate::planning::vessel::Thruster;
    use nalgebra::DMatrix;

    fn az_tunnels(groups: Option<[&str; 4]>) -> VesselProfile {
        let mut p = supply_vessel();
        let kinds = [
            ThrusterKind::Tunnel,
            ThrusterKind::Tunnel,
            ThrusterKind::Azimuth,
            ThrusterKind::Azimuth,
        ];
        let thrusters = (0..4)
            .map(|j| Thruster {
                name: format!("t{j}"),
                kind: kinds[j],
                max_command: 1.0,
                max_rate: 0.1,
                coefficient_group: groups.map(|g| g[j].to_string()),
                signal: Default::default(),
                logged_angle: None,
            })
            .collect();
        p.inputs = InputChannels::Thrusters {
            thrusters,
            configuration: vec![
                vec![0.0, 0.0, 0.866, 0.866],
                vec![1.0, 1.0, 0.5, -0.5],
                vec![0.45, -0.4, -0.173, 0.173],
            ],
        };
        p
    }

    #[test]
    fn the_paper_layout_keeps_eq_47_and_its_names() {
        let l = ekf_layout(&supply_vessel(), 76.2).unwrap();
        assert_eq!(l.thrust, ThrustLayout::paper());
        assert_eq!(l.names[5], "K1=K2");
        assert_eq!(l.names[8], "K6");
    }

    #[test]
    fn groups_come_from_the_profile_or_one_per_thruster() {
        let l = ekf_layout(&az_tunnels(None), 76.2).unwrap();
        assert_eq!(l.thrust.groups, [0, 1, 2, 3]);
        assert_eq!(l.names[7], "K(thr_3)");
        let l = ekf_layout(&az_tunnels(Some(["bow", "stern", "az", "az"])), 76.2).unwrap();
        assert_eq!(l.thrust.groups, [0, 1, 2, 2]);
        assert_eq!(l.names[7], "K(thr_3=thr_4)");
        assert_eq!(l.names[8], "—");
        assert!(l.note.contains("bow, stern, az"), "{}", l.note);
        let e = ekf_layout(&az_tunnels(Some(["a", "b", "c", "d"])), 76.2);
        assert!(e.is_ok());
    }

    #[test]
    fn five_groups_are_refused_naming_the_thruster() {
        let mut p = az_tunnels(Some(["a", "b", "c", "d"]));
        if let InputChannels::Thrusters {
            thrusters,
            configuration,
        } = &mut p.inputs
        {
            let mut extra = thrusters[0].clone();
            extra.name = "fifth".into();
            extra.coefficient_group = Some("e".into());
            thrusters.push(extra);
            for row in configuration.iter_mut() {
                row.push(0.1);
            }
        }
        let e = ekf_layout(&p, 76.2).unwrap_err();
        assert_eq!(e.field(), "vessel.inputs.thrusters[4].coefficient_group");
        assert!(e.to_string().contains("'fifth'"), "{e}");
    }

    #[test]
    fn generalized_forces_are_one_group_scaled_by_the_force_limit() {
        let mut p = supply_vessel();
        p.inputs = InputChannels::GeneralizedForces;
        let l = ekf_layout(&p, 76.2).unwrap();
        let f = p.limit(Dof::Surge).max_force;
        assert_eq!(l.force_ref_n, Some(f));
        assert_eq!(l.thrust.groups, [0, 0, 0]);
        assert_eq!(l.columns, ["tau_X", "tau_Y", "tau_N"]);
        // 1 N·m of yaw moment is 1/L of 1 N of force in Bis.
        let w = l.thrust.group_force(0, &[f, 2.0 * f, 76.2 * f]);
        assert!((w - nalgebra::Vector3::new(1.0, 2.0, 1.0)).norm() < 1e-12);
    }

    /// 20 samples of `width` commands, the columns `on` moving.
    fn commands(width: usize, on: &[usize]) -> DMatrix<f64> {
        DMatrix::from_fn(20, width, |k, j| {
            if on.contains(&j) {
                ((k % 5) as f64 - 2.0) * 0.3
            } else {
                0.0
            }
        })
    }

    #[test]
    fn stages_free_the_groups_they_drive_first() {
        let l = ekf_layout(&supply_vessel(), 76.2).unwrap();
        let cols = |on: &[usize]| commands(6, on);
        let (s1, s2, s3) = (cols(&[0, 1]), cols(&[2, 3, 4]), cols(&[5]));
        let f = stage_frees(&l, &[vec![&s1], vec![&s2], vec![&s3]]).unwrap();
        assert_eq!(f, [vec![0, 5], vec![1, 2, 3, 4, 6, 7], vec![8]]);
        // Without SI3 runs the azimuth's coefficient has no stage.
        let e = stage_frees(&l, &[vec![&s1], vec![&s2], vec![]]).unwrap_err();
        assert!(e.to_string().contains("thr_6"), "{e}");
        // A tunnel-only vessel flown without SI3 needs none.
        let two = az_tunnels(Some(["bow", "stern", "az", "az"]));
        let l = ekf_layout(&two, 76.2).unwrap();
        let c4 = |on: &[usize]| commands(4, on);
        let (a, b) = (c4(&[2, 3]), c4(&[0, 1]));
        let f = stage_frees(&l, &[vec![&a], vec![&b], vec![]]).unwrap();
        assert_eq!(f, [vec![0, 7], vec![1, 2, 3, 4, 5, 6], vec![]]);
    }
}
