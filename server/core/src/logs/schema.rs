//! Which columns a log must carry, by vessel profile and file role.
//!
//! Column names (SI units, radians, Fossen's NED/body frames):
//! - `t` (s), always first;
//! - inputs: `tau_X … tau_N` of the modeled DOFs for a vessel actuated by
//!   generalized forces, `thr_1 … thr_r` for a thruster-actuated vessel
//!   (r thrusters, in the column order of its configuration matrix T);
//! - outputs (body velocities): `u v w p q r` of the modeled DOFs;
//! - pose: surge→`x`, sway→`y`, heave→`z`, roll→`phi`, pitch→`theta`,
//!   yaw→`psi` (m, rad) of the modeled DOFs.
//!
//! Within each group the order is that of the profile's `dofs`.
//!
//! A DP vessel (kind `dp3`) logs what its DP system records: the pose
//! (x, y, ψ — what the parallel EKF of Fossen et al. 1995 identifies
//! from), the body velocities (u, v, r), or both. Its files must carry at
//! least one of the two groups complete ([`measurement_groups`]); a ROV's
//! files carry both.

use serde::{Deserialize, Serialize};

use crate::planning::dof::Dof;
use crate::planning::vessel::{InputChannels, VesselKind, VesselProfile};

/// Name of the time column (s).
pub const TIME_COLUMN: &str = "t";

/// What a log file holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum LogRole {
    /// One file with time, inputs, velocities and pose.
    Single,
    /// The controller's file of a two-computer run: time, inputs and the
    /// shared channel.
    Control,
    /// The navigation computer's file of a two-computer run: time,
    /// velocities, pose and the shared channel.
    Nav,
}

impl LogRole {
    /// The name errors use for a file of this role: `file`, `control`, `nav`.
    pub fn label(self) -> &'static str {
        match self {
            LogRole::Single => "file",
            LogRole::Control => "control",
            LogRole::Nav => "nav",
        }
    }
}

/// Pose column of a DOF: surge→`x`, sway→`y`, heave→`z`, roll→`phi`,
/// pitch→`theta`, yaw→`psi`.
pub fn pose_column(dof: Dof) -> &'static str {
    ["x", "y", "z", "phi", "theta", "psi"][dof.index()]
}

/// Column of thruster command `i`, counted from 1: `thr_1`, `thr_2`, ….
pub fn thruster_column(i: usize) -> String {
    format!("thr_{i}")
}

/// Input columns: `tau_*` of the modeled DOFs, or `thr_1..thr_r`.
pub fn input_columns(vessel: &VesselProfile) -> Vec<String> {
    match &vessel.inputs {
        InputChannels::GeneralizedForces => vessel
            .dofs
            .iter()
            .map(|d| d.force_column().to_string())
            .collect(),
        InputChannels::Thrusters { thrusters, .. } => {
            (1..=thrusters.len()).map(thruster_column).collect()
        }
    }
}

/// Column of azimuth `i`'s logged angle, counted from 1: `azi_1`, ….
pub fn azimuth_angle_column(i: usize) -> String {
    format!("azi_{i}")
}

/// The logged-angle columns `azi_j` of the thrusters that declare one.
pub fn azimuth_angle_columns(vessel: &VesselProfile) -> Vec<String> {
    vessel
        .thrusters()
        .iter()
        .enumerate()
        .filter(|(_, t)| t.logged_angle.is_some())
        .map(|(j, _)| azimuth_angle_column(j + 1))
        .collect()
}

/// Output columns: body velocities of the modeled DOFs (`u`, `v`, `r`, …).
pub fn output_columns(vessel: &VesselProfile) -> Vec<String> {
    Dof::velocity_symbols(&vessel.dofs)
}

/// Pose columns of the modeled DOFs (`x`, `y`, `psi`, …).
pub fn pose_columns(vessel: &VesselProfile) -> Vec<String> {
    vessel
        .dofs
        .iter()
        .map(|d| pose_column(*d).to_string())
        .collect()
}

/// Every column a file of `role` must carry for `vessel`, `t` first, without
/// repetitions. `shared` is the channel both computers record in a
/// two-file run (e.g. depth `z`); it is added to every role when given
/// (blank names are ignored).
///
/// - `Single`: `t`, inputs, velocities, pose;
/// - `Control`: `t`, inputs, shared;
/// - `Nav`: `t`, velocities, pose, shared.
pub fn required_columns(
    vessel: &VesselProfile,
    role: LogRole,
    shared: Option<&str>,
) -> Vec<String> {
    let mut cols = vec![TIME_COLUMN.to_string()];
    let mut groups = Vec::new();
    if matches!(role, LogRole::Single | LogRole::Control) {
        groups.push(input_columns(vessel));
        groups.push(azimuth_angle_columns(vessel));
    }
    if matches!(role, LogRole::Single | LogRole::Nav) {
        groups.push(output_columns(vessel));
        groups.push(pose_columns(vessel));
    }
    if let Some(s) = shared.map(str::trim).filter(|s| !s.is_empty()) {
        groups.push(vec![s.to_string()]);
    }
    for c in groups.into_iter().flatten() {
        if !cols.contains(&c) {
            cols.push(c);
        }
    }
    cols
}

/// Columns a file of `role` must carry without exception: [`required_columns`]
/// less the measurement groups of a DP vessel, of which one complete group
/// suffices ([`measurement_groups`]).
pub fn strict_columns(vessel: &VesselProfile, role: LogRole, shared: Option<&str>) -> Vec<String> {
    let groups = measurement_groups(vessel, role);
    let shared = shared.map(str::trim).filter(|s| !s.is_empty());
    required_columns(vessel, role, shared)
        .into_iter()
        .filter(|c| Some(c.as_str()) == shared || !groups.iter().flatten().any(|g| g == c))
        .collect()
}

/// Alternative measurement groups of a file of `role`, at least one of which
/// must be complete: for a DP vessel's single or navigation file the body
/// velocities (`u v r`) and the pose (`x y psi`); empty otherwise (a ROV
/// needs both, and [`strict_columns`] lists them).
pub fn measurement_groups(vessel: &VesselProfile, role: LogRole) -> Vec<Vec<String>> {
    if vessel.kind != VesselKind::Dp3 || role == LogRole::Control {
        return Vec::new();
    }
    vec![output_columns(vessel), pose_columns(vessel)]
}

/// The vessel in words for messages, e.g. `the 6-DOF ROV 'Surveyor ROV'`.
pub fn describe_vessel(vessel: &VesselProfile) -> String {
    let kind = match vessel.kind {
        VesselKind::Rov6 => "ROV",
        VesselKind::Dp3 => "DP vessel",
    };
    format!("the {}-DOF {kind} '{}'", vessel.dofs.len(), vessel.name)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::planning::examples::{supply_vessel, surveyor_rov};

    fn strs(v: &[String]) -> Vec<&str> {
        v.iter().map(String::as_str).collect()
    }

    #[test]
    fn surveyor_rov_single_needs_tau_velocities_and_pose() {
        let v = surveyor_rov();
        let cols = required_columns(&v, LogRole::Single, None);
        assert_eq!(
            strs(&cols),
            [
                "t", "tau_X", "tau_Y", "tau_Z", "tau_K", "tau_M", "tau_N", "u", "v", "w", "p", "q",
                "r", "x", "y", "z", "phi", "theta", "psi"
            ]
        );
        assert_eq!(describe_vessel(&v), "the 6-DOF ROV 'Surveyor ROV'");
    }

    #[test]
    fn surveyor_rov_two_files_share_depth_once() {
        let v = surveyor_rov();
        let control = required_columns(&v, LogRole::Control, Some("z"));
        assert_eq!(
            strs(&control),
            [
                "t", "tau_X", "tau_Y", "tau_Z", "tau_K", "tau_M", "tau_N", "z"
            ]
        );
        let nav = required_columns(&v, LogRole::Nav, Some(" z "));
        assert_eq!(
            strs(&nav),
            [
                "t", "u", "v", "w", "p", "q", "r", "x", "y", "z", "phi", "theta", "psi"
            ]
        );
        assert_eq!(required_columns(&v, LogRole::Nav, Some("")).len(), 13);
    }

    #[test]
    fn supply_vessel_needs_thruster_commands_and_horizontal_columns() {
        let v = supply_vessel();
        let cols = required_columns(&v, LogRole::Single, None);
        assert_eq!(
            strs(&cols),
            [
                "t", "thr_1", "thr_2", "thr_3", "thr_4", "thr_5", "thr_6", "u", "v", "r", "x", "y",
                "psi"
            ]
        );
        assert_eq!(
            strs(&input_columns(&v)),
            ["thr_1", "thr_2", "thr_3", "thr_4", "thr_5", "thr_6"]
        );
        assert_eq!(strs(&output_columns(&v)), ["u", "v", "r"]);
        assert_eq!(strs(&pose_columns(&v)), ["x", "y", "psi"]);
        let control = required_columns(&v, LogRole::Control, Some("psi"));
        assert_eq!(strs(&control)[..2], ["t", "thr_1"]);
        assert_eq!(control.last().map(String::as_str), Some("psi"));
        assert_eq!(LogRole::Nav.label(), "nav");
    }

    #[test]
    fn a_dp_vessel_needs_its_pose_or_its_velocities() {
        let v = supply_vessel();
        let strict = strict_columns(&v, LogRole::Single, None);
        assert_eq!(strict.len(), 7, "{strict:?}");
        assert_eq!(strs(&strict)[..2], ["t", "thr_1"]);
        let groups = measurement_groups(&v, LogRole::Nav);
        assert_eq!(strs(&groups[0]), ["u", "v", "r"]);
        assert_eq!(strs(&groups[1]), ["x", "y", "psi"]);
        // A shared channel stays required even when it is a pose column.
        assert_eq!(
            strict_columns(&v, LogRole::Nav, Some("psi")),
            ["t".to_string(), "psi".to_string()]
        );
        let rov = surveyor_rov();
        assert!(measurement_groups(&rov, LogRole::Single).is_empty());
        assert_eq!(
            strict_columns(&rov, LogRole::Single, None),
            required_columns(&rov, LogRole::Single, None)
        );
    }
}
