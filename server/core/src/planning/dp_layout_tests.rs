//! DP plans for vessels outside the paper's six-thruster layout: thrusters
//! assigned to SI1/SI2 by where they push, and force schedules τ for a
//! vessel that logs forces.

use super::campaign::ExperimentFamily;
use super::examples::{supply_vessel, supply_vessel_azimuths_tunnels, supply_vessel_campaign};
use super::vessel::InputChannels;
use super::*;

fn excited(plan: &Plan, i: usize) -> Vec<&str> {
    plan.experiments[i]
        .experiment
        .channels
        .iter()
        .filter(|c| c.excited)
        .map(|c| c.column.as_str())
        .collect()
}

#[test]
fn other_layouts_fly_surge_thrusters_together_and_lateral_ones_apart() {
    let mut c = supply_vessel_campaign(7);
    c.families = vec![
        ExperimentFamily::DpSurge,
        ExperimentFamily::DpSwayYaw,
        ExperimentFamily::Validation,
    ];
    let plan = generate_plan(&supply_vessel_azimuths_tunnels(), &c).unwrap();
    // SI1: the azimuth pair on one signal (its sway and yaw cancel).
    assert_eq!(excited(&plan, 0), ["thr_3", "thr_4"]);
    let s1 = &plan.experiments[0].schedule.values;
    assert_eq!(s1[2], s1[3]);
    // SI2: the tunnels, stern and bow independently.
    assert_eq!(excited(&plan, 2), ["thr_1", "thr_2"]);
    let s2 = &plan.experiments[2].schedule.values;
    assert_ne!(s2[0], s2[1]);
    assert!(
        plan.experiments[0]
            .experiment
            .instruction
            .contains("port azimuth and starboard azimuth"),
        "{}",
        plan.experiments[0].experiment.instruction
    );
}

#[test]
fn a_vessel_logging_forces_flies_force_schedules_within_its_limits() {
    let mut p = supply_vessel();
    p.inputs = InputChannels::GeneralizedForces;
    let mut c = supply_vessel_campaign(7);
    c.families = vec![
        ExperimentFamily::DpSurge,
        ExperimentFamily::DpSwayYaw,
        ExperimentFamily::Validation,
    ];
    let plan = generate_plan(&p, &c).unwrap();
    assert_eq!(excited(&plan, 0), ["tau_X"]);
    assert_eq!(excited(&plan, 2), ["tau_Y", "tau_N"]);
    let last = plan.experiments.len() - 1;
    assert_eq!(excited(&plan, last), ["tau_X", "tau_Y", "tau_N"]);
    for e in &plan.experiments {
        for (ch, col) in e.experiment.channels.iter().zip(&e.schedule.values) {
            let limit = p.limit(ch.dof.unwrap()).max_force;
            assert_eq!(ch.limit, limit);
            assert!(col.iter().all(|v| v.abs() <= limit + 1e-9), "{}", ch.column);
        }
    }
    let s2 = &plan.experiments[2].schedule.values;
    assert_ne!(s2[1], s2[2], "sway and yaw are driven independently");
    // No azimuth manoeuvre for forces: refused naming the family list.
    c.families.push(ExperimentFamily::DpAzimuth);
    let e = generate_plan(&p, &c).unwrap_err();
    assert_eq!(e.field, "families");
    assert!(e.to_string().contains("dp_azimuth"), "{e}");
}
