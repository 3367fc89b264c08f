//! The stated uncertainty is calibrated: over independent noise draws the
//! z-scores (estimate − truth)/σ have unit RMS with the robust (sandwich)
//! covariance, while the white-noise formula overstates σ because the λ
//! regression's equation error is coloured.

use nalgebra::DMatrix;

use super::super::filter::LambdaFilter;
use super::super::transform::{state_space, to_lambda};
use super::super::{CouplingMask, Inversion, LambdaSettings, Prior, Structure, identify};
use super::truth::run;
use crate::planning::dof::Dof;

/// RMS z-scores of A and of A_λ over `trials` noisy runs.
fn rms_z(robust: bool, trials: u64) -> (f64, f64) {
    let m = DMatrix::from_row_slice(
        3,
        3,
        &[500.0, 40.0, -20.0, 40.0, 800.0, 60.0, -20.0, 60.0, 120.0],
    );
    let d = DMatrix::from_row_slice(
        3,
        3,
        &[100.0, 20.0, 0.0, -10.0, 300.0, 30.0, 5.0, 15.0, 60.0],
    );
    let (a, b) = state_space(&m, &d, "m").unwrap();
    let mut s = LambdaSettings::new(
        vec![Dof::Surge, Dof::Sway, Dof::Yaw],
        1.0,
        Structure::Coupled(CouplingMask::full(3)),
        Prior::weak(
            DMatrix::from_diagonal(&(m.diagonal() * 0.5)),
            DMatrix::from_diagonal(&(d.diagonal() * 2.0)),
        ),
    );
    s.robust_covariance = robust;
    let f = LambdaFilter::new(1.0, 0.1).unwrap();
    let (al, _) = to_lambda(&a, &b, &f, Inversion::Exact).unwrap();
    let (mut za, mut zl, mut count) = (0.0, 0.0, 0.0);
    for t in 0..trials {
        let r = run(
            &a,
            &b,
            0.1,
            2000,
            &[1.5, 2.3, 3.1],
            &[100.0, 200.0, 20.0],
            &[0.0; 3],
            &[0.0; 3],
            &[0.01, 0.01, 0.005],
            500 + t,
        );
        let e = identify(&[r], &s).unwrap();
        for i in 0..3 {
            for j in 0..3 {
                za += ((e.a[(i, j)] - a[(i, j)]) / e.std_a[(i, j)]).powi(2);
                zl += ((e.a_lambda[(i, j)] - al[(i, j)]) / e.param_cov[i][(j, j)].sqrt()).powi(2);
                count += 1.0;
            }
        }
    }
    ((za / count).sqrt(), (zl / count).sqrt())
}

#[test]
fn robust_standard_deviations_are_calibrated() {
    let (robust_a, robust_l) = rms_z(true, 40);
    let (white_a, white_l) = rms_z(false, 40);
    println!(
        "RMS z of A (A_λ): robust {robust_a:.3} ({robust_l:.3}), white-noise formula {white_a:.3} ({white_l:.3})"
    );
    assert!(robust_a > 0.8 && robust_a < 1.2, "{robust_a}");
    assert!(robust_l > 0.8 && robust_l < 1.2, "{robust_l}");
    assert!(white_a < 0.75, "{white_a}");
}
