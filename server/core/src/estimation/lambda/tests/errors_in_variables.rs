//! Bias-compensated least squares against a known truth: a force signal
//! whose logged value carries an error the vehicle never felt.

use nalgebra::{DMatrix, DVector};

use super::super::{Experiment, LambdaSettings, Prior, RegressorNoise, Structure, identify};
use super::truth::{noisy, rel_err, run};
use crate::estimation::lambda::transform::state_space;
use crate::planning::dof::Dof;

/// A diagonal three-DOF vehicle driven by random binary γ; the regression
/// sees γ plus white errors of 1.2 times the signal's amplitude (the
/// vehicle felt γ alone). Plain least squares shrinks the input gain and
/// inflates M by a fifth or more; told the errors' covariance, the
/// compensated fit recovers M and D̄ within 3 %.
#[test]
fn a_known_regressor_error_no_longer_inflates_m() {
    let m = DMatrix::from_diagonal(&DVector::from_vec(vec![500.0, 800.0, 120.0]));
    let d = DMatrix::from_diagonal(&DVector::from_vec(vec![100.0, 300.0, 60.0]));
    let (a, b) = state_space(&m, &d, "m").unwrap();
    let amp = [100.0, 200.0, 20.0];
    let sigma: Vec<f64> = amp.iter().map(|x| 1.2 * x).collect();
    let runs: Vec<Experiment> = (0..4)
        .map(|seed| {
            let clean = run(
                &a,
                &b,
                0.1,
                4000,
                &[1.5, 2.3, 3.1],
                &amp,
                &[0.0; 3],
                &[0.0; 3],
                &[0.0; 3],
                seed,
            );
            Experiment::new(
                0.1,
                clean.nu.clone(),
                noisy(&clean.gamma, &sigma, 100 + seed),
            )
        })
        .collect();
    let dofs = vec![Dof::Surge, Dof::Sway, Dof::Yaw];
    let prior = Prior::weak(
        DMatrix::from_diagonal(&(m.diagonal() * 0.5)),
        DMatrix::from_diagonal(&(d.diagonal() * 2.0)),
    );
    let mut s = LambdaSettings::new(dofs, 1.0, Structure::Diagonal, prior);
    let plain = identify(&runs, &s).unwrap();
    let mut lag0 = DMatrix::zeros(6, 6);
    for (i, v) in sigma.iter().enumerate() {
        lag0[(3 + i, 3 + i)] = v * v;
    }
    s.regressor_noise = Some(RegressorNoise {
        lag0,
        lag1: DMatrix::zeros(6, 6),
    });
    let compensated = identify(&runs, &s).unwrap();
    let inflation: Vec<f64> = (0..3).map(|i| plain.m[(i, i)] / m[(i, i)] - 1.0).collect();
    let (em, ed) = (rel_err(&compensated.m, &m), rel_err(&compensated.d_bar, &d));
    println!("plain M inflated by {inflation:?}; compensated M {em:.4}, D̄ {ed:.4}");
    assert!(inflation.iter().all(|&x| x > 0.1), "{inflation:?}");
    assert!(em < 0.03 && ed < 0.03, "M {em}, D̄ {ed}");
    // A wrongly sized covariance is refused by name.
    s.regressor_noise = Some(RegressorNoise::held_over_step(DMatrix::zeros(5, 5)));
    let err = identify(&runs, &s).unwrap_err().to_string();
    assert!(err.contains("regressor_noise"), "{err}");
}
