use super::super::examples::{supply_vessel, surveyor_rov};
use super::*;

#[test]
fn examples_are_valid() {
    surveyor_rov().validate().unwrap();
    supply_vessel().validate().unwrap();
}

#[test]
fn missing_limits_and_bad_configuration_name_the_field() {
    let mut v = surveyor_rov();
    v.limits.remove(&Dof::Roll);
    assert_eq!(v.validate().unwrap_err().field, "limits.roll");

    let mut v = supply_vessel();
    if let InputChannels::Thrusters { configuration, .. } = &mut v.inputs {
        configuration[1].pop();
    }
    assert_eq!(v.validate().unwrap_err().field, "inputs.configuration[1]");

    let mut v = supply_vessel();
    v.dofs.push(Dof::Heave);
    assert_eq!(v.validate().unwrap_err().field, "dofs[3]");

    let mut v = supply_vessel();
    v.dp_prior.as_mut().unwrap().inertia_bis.as_mut().unwrap()[1][2] = 0.5;
    assert_eq!(v.validate().unwrap_err().field, "dp_prior.inertia_bis");
    let mut v = surveyor_rov();
    v.dp_prior = supply_vessel().dp_prior;
    assert_eq!(v.validate().unwrap_err().field, "dp_prior");

    let mut v = surveyor_rov();
    v.limits.get_mut(&Dof::Yaw).unwrap().max_force_rate = f64::NAN;
    assert_eq!(v.validate().unwrap_err().field, "limits.yaw.max_force_rate");
}
