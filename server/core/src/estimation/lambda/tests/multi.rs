//! Multi-experiment identification: two short runs from different initial
//! states, each filtered from its own state with its own transient, give a
//! better estimate than either alone.

use nalgebra::DMatrix;

use super::super::transform::state_space;
use super::super::{
    CouplingMask, Experiment, LambdaEstimate, LambdaSettings, Prior, Structure, identify,
};
use super::truth::run;
use crate::planning::dof::Dof;

fn error(est: &LambdaEstimate, a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    (&est.a - a).norm() / a.norm() + (&est.b - b).norm() / b.norm()
}

#[test]
fn two_short_runs_beat_either_alone() {
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
    let prior = Prior::weak(
        DMatrix::from_diagonal(&(m.diagonal() * 0.5)),
        DMatrix::from_diagonal(&(d.diagonal() * 2.0)),
    );
    let mut s = LambdaSettings::new(
        vec![Dof::Surge, Dof::Sway, Dof::Yaw],
        1.0,
        Structure::Coupled(CouplingMask::full(3)),
        prior,
    );
    // Information adding up across runs: without the symmetric-M scaling,
    // whose Birge ratio on 3 pairs is itself a random draw per run.
    s.symmetric_inertia = false;
    let short = |nu0: &[f64], seed| -> Experiment {
        run(
            &a,
            &b,
            0.1,
            600,
            &[1.5, 2.3, 3.1],
            &[100.0, 200.0, 20.0],
            &[0.0; 3],
            nu0,
            &[0.01, 0.01, 0.005],
            seed,
        )
    };
    // Expected errors over independent noise/excitation draws: the combined
    // estimate must beat each single run's on average (a single draw can go
    // either way, so the mean is what is asserted).
    let trials = 12;
    let mut sums = [0.0; 3];
    for t in 0..trials {
        let r1 = short(&[0.0, 0.0, 0.0], 100 + t);
        let r2 = short(&[0.8, -0.3, 0.2], 200 + t);
        let e1 = identify(std::slice::from_ref(&r1), &s).unwrap();
        let e2 = identify(std::slice::from_ref(&r2), &s).unwrap();
        let both = identify(&[r1, r2], &s).unwrap();
        assert_eq!(both.n_runs, 2);
        assert_eq!(both.n_samples, 1200);
        sums[0] += error(&e1, &a, &b) / trials as f64;
        sums[1] += error(&e2, &a, &b) / trials as f64;
        sums[2] += error(&both, &a, &b) / trials as f64;
        // The stated uncertainty shrinks too.
        let (s1, s2, s12) = (e1.std_a.norm(), e2.std_a.norm(), both.std_a.norm());
        assert!(s12 < s1.min(s2), "‖σ(A)‖ {s12} vs {s1}, {s2}");
    }
    println!(
        "mean relative error of (A, B): run 1 alone {:.4}, run 2 alone {:.4}, both {:.4}",
        sums[0], sums[1], sums[2]
    );
    assert!(sums[2] < 0.85 * sums[0].min(sums[1]), "{sums:?}");
}
