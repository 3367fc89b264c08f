//! Bad input gives typed errors naming the field, never a panic; LPV
//! progress and cancellation.

use nalgebra::DMatrix;

use super::super::{
    Experiment, LambdaError, LambdaSettings, Prior, Structure, identify, identify_lpv,
    propose_coupling,
};
use crate::estimation::Cancelled;
use crate::planning::dof::Dof;

fn good(len: usize) -> Experiment {
    let gamma = DMatrix::from_fn(len, 2, |k, j| (((k * (j + 3)) / 7) % 2) as f64 * 2.0 - 1.0);
    let mut nu = DMatrix::zeros(len, 2);
    for k in 1..len {
        for j in 0..2 {
            nu[(k, j)] = 0.95 * nu[(k - 1, j)] + 0.01 * gamma[(k - 1, j)];
        }
    }
    Experiment::new(0.1, nu, gamma)
}

fn settings() -> LambdaSettings {
    let m = DMatrix::from_diagonal_element(2, 2, 10.0);
    LambdaSettings::new(
        vec![Dof::Surge, Dof::Sway],
        1.0,
        Structure::Diagonal,
        Prior::weak(m.clone(), m),
    )
}

fn field(e: Result<impl std::fmt::Debug, LambdaError>) -> String {
    e.unwrap_err().field().to_string()
}

#[test]
fn bad_runs_and_settings_name_their_field() {
    let s = settings();
    assert!(identify(&[good(400)], &s).is_ok());

    let mut r = good(400);
    r.gamma = DMatrix::zeros(400, 3);
    assert_eq!(field(identify(&[r], &s)), "runs[0].gamma");
    let mut r = good(400);
    r.gamma = DMatrix::zeros(399, 2);
    assert_eq!(field(identify(&[good(400), r], &s)), "runs[1].gamma");
    let mut r = good(400);
    r.nu[(5, 1)] = f64::NAN;
    let e = identify(&[r], &s).unwrap_err();
    assert!(
        matches!(e, LambdaError::NonFinite { ref field, index: Some(5), .. } if field == "runs[0].nu"),
        "{e:?}"
    );
    assert_eq!(field(identify(&[good(5)], &s)), "runs[0].nu");
    assert!(matches!(
        identify(&[], &s),
        Err(LambdaError::TooFewSamples { .. })
    ));
    let mut r = good(400);
    r.h = 0.2;
    assert_eq!(field(identify(&[good(400), r], &s)), "runs[1].h");

    let mut bad = s.clone();
    bad.t_lambda = 0.0;
    assert_eq!(field(identify(&[good(400)], &bad)), "settings.t_lambda");
    bad.t_lambda = 0.2; // 2h: not ≫ h
    assert!(
        matches!(identify(&[good(400)], &bad), Err(LambdaError::InvalidParameter { ref field, .. }) if field == "settings.t_lambda")
    );
    let mut bad = s.clone();
    bad.prior.m0 = DMatrix::zeros(2, 2);
    assert!(
        matches!(identify(&[good(400)], &bad), Err(LambdaError::Singular { ref field, .. }) if field == "settings.prior.m0")
    );
    let mut bad = s.clone();
    bad.prior.d_bar0 = DMatrix::zeros(3, 3);
    assert_eq!(field(identify(&[good(400)], &bad)), "settings.prior.d_bar0");
    let mut bad = s.clone();
    bad.noise_variance = Some(vec![1.0, -1.0]);
    assert_eq!(
        field(identify(&[good(400)], &bad)),
        "settings.noise_variance[1]"
    );
    let mut bad = s.clone();
    bad.dofs = vec![Dof::Surge, Dof::Surge];
    assert_eq!(field(identify(&[good(400)], &bad)), "settings.dofs[1]");
    let mut bad = s;
    let mut mask = super::super::CouplingMask::full(2);
    mask.a[(0, 0)] = false;
    bad.structure = Structure::Coupled(mask);
    assert_eq!(field(identify(&[good(400)], &bad)), "structure.a");

    assert_eq!(field(propose_coupling(&[good(400)], 1.5)), "threshold");
    assert_eq!(field(propose_coupling(&[good(40)], 0.2)), "runs[0].nu");
}

#[test]
fn lpv_reports_progress_per_grid_point_and_dof_and_cancels() {
    let s = settings();
    let points = vec![(0.5, vec![good(300)]), (1.0, vec![good(300), good(200)])];
    let mut seen: Vec<(f64, String)> = Vec::new();
    let mut sink = |f: f64, stage: &str| {
        seen.push((f, stage.to_string()));
        Ok(())
    };
    let out = identify_lpv(&points, &s, &mut sink).unwrap();
    assert_eq!(out.len(), 2);
    assert_eq!(out[1].1.n_runs, 2);
    assert!(seen.windows(2).all(|w| w[1].0 >= w[0].0), "not monotone");
    assert_eq!(seen.last().unwrap().0, 1.0);
    assert!(
        seen.iter()
            .any(|(_, st)| st.contains("grid point 2/2") && st.contains("sway"))
    );

    let mut cancel = |f: f64, _: &str| if f > 0.6 { Err(Cancelled) } else { Ok(()) };
    assert_eq!(
        identify_lpv(&points, &s, &mut cancel).unwrap_err(),
        LambdaError::Cancelled
    );

    let mut bad = points.clone();
    bad[1].1[0].nu[(3, 0)] = f64::INFINITY;
    assert_eq!(
        field(identify_lpv(&bad, &s, &mut crate::estimation::NoProgress)),
        "points[1].runs[0].nu"
    );
    assert_eq!(
        field(identify_lpv(&[], &s, &mut crate::estimation::NoProgress)),
        "points"
    );
}
