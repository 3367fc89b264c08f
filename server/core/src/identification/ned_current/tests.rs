use super::*;
use crate::estimation::lambda::{Inversion, UncertaintyMethod};

/// An estimate whose F is exactly −D̄_{:,uv} Q(V) with std 1.
fn estimate(d: DMatrix<f64>, v: Vector2<f64>) -> LambdaEstimate {
    let dofs = Dof::HORIZONTAL.to_vec();
    let f_c = force(&d, &dofs, &v);
    let mut f = DMatrix::zeros(3, 3);
    f.columns_mut(1, 2).copy_from(&f_c);
    let z = DMatrix::zeros(3, 3);
    LambdaEstimate {
        dofs,
        t_lambda: 1.0,
        h: 0.1,
        inversion: Inversion::Exact,
        mask: crate::estimation::lambda::CouplingMask::full(3),
        a_lambda: z.clone(),
        b_lambda: z.clone(),
        a: z.clone(),
        b: z.clone(),
        m: DMatrix::identity(3, 3),
        d_bar: d,
        param_cov: Vec::new(),
        std_a: z.clone(),
        std_b: z.clone(),
        std_m: z.clone(),
        std_d_bar: z.clone(),
        exogenous: vec!["1".into(), COS_PSI.into(), SIN_PSI.into()],
        k_lambda: z.clone(),
        force: f,
        std_force: DMatrix::from_element(3, 3, 1.0),
        uncertainty: UncertaintyMethod::DeltaMethod,
        residual_variance: vec![0.0; 3],
        noise_variance: vec![0.0; 3],
        n_samples: 100,
        n_runs: 1,
        symmetry: None,
    }
}

fn d_bar() -> DMatrix<f64> {
    DMatrix::from_row_slice(3, 3, &[80.0, 0.0, 0.0, 0.0, 160.0, 24.0, 0.0, 12.0, 44.0])
}

#[test]
fn the_current_seen_in_the_body_frame_is_damped_as_relative_velocity() {
    // −D̄ ν_c(ψ) at ψ = 30° for a current of 0.5 m/s towards east.
    let v = Vector2::new(0.0, 0.5);
    let psi = 30f64.to_radians();
    let nu_c = [
        v[0] * psi.cos() + v[1] * psi.sin(),
        -v[0] * psi.sin() + v[1] * psi.cos(),
        0.0,
    ];
    let d = d_bar();
    let f = force(&d, &Dof::HORIZONTAL, &v);
    let e = functions_of(&[psi, psi]);
    for i in 0..3 {
        let want = -(0..3).map(|j| d[(i, j)] * nu_c[j]).sum::<f64>();
        let got = f[(i, 0)] * e[(0, 0)] + f[(i, 1)] * e[(0, 1)];
        assert!((got - want).abs() < 1e-12, "{i}: {got} vs {want}");
    }
}

/// With D_q the model applies to ν, `drive` adds D_q(f(ν) − f(ν_r)):
/// the drag then acts on the velocity through the water. A current of
/// 0.2 m/s towards north seen at ψ = 90° is v_c = −0.2 m/s; at
/// ν = (0.5, 0.1, 0) and u₀ = 0.5: sway 20·(0.1² − 0.3²) = −1.6 N, surge
/// 0 (u_c = 0). At ψ = 0: u_r = 0.3, surge 10·(0 − (0.3 − 0.5)²) = −0.4 N.
#[test]
fn the_quadratic_drag_is_moved_onto_the_relative_velocity() {
    let r = Relative {
        dofs: Dof::HORIZONTAL.to_vec(),
        v: Vector2::new(0.2, 0.0),
        m: DMatrix::identity(3, 3),
        coriolis: false,
        quadratic: Some(DVector::from_vec(vec![10.0, 20.0, 0.0])),
    };
    let nu = DVector::from_vec(vec![0.5, 0.1, 0.0]);
    let f = DMatrix::zeros(3, 2);
    let east = r.drive(&nu, std::f64::consts::FRAC_PI_2, 0.5, &f);
    let north = r.drive(&nu, 0.0, 0.5, &f);
    for (got, want) in [
        (east[0], 0.0),
        (east[1], -1.6),
        (north[0], -0.4),
        (north[1], 0.0),
    ] {
        assert!((got - want).abs() < 1e-12, "{got} vs {want}");
    }
    assert_eq!(east[2], 0.0);
}

#[test]
fn a_points_force_gives_back_its_current() {
    let v = Vector2::new(0.3, -0.2);
    let c = current_of(&estimate(d_bar(), v)).unwrap();
    assert!((c.v - v).norm() < 1e-12);
    assert!(c.significant());
    let (s, _) = c.speed();
    assert!((s - v.norm()).abs() < 1e-12);
    let (b, b_sd) = c.direction();
    assert!((b - (-0.2f64).atan2(0.3)).abs() < 1e-12);
    assert!(b_sd > 0.0 && b_sd < 0.1);
    // No current: not significant.
    let none = current_of(&estimate(d_bar(), Vector2::zeros())).unwrap();
    assert!(!none.significant());
}

#[test]
fn pooling_weights_by_covariance_and_inflates_on_disagreement() {
    let a = CurrentEstimate {
        v: Vector2::new(1.0, 0.0),
        cov: Matrix2::identity(),
        birge_ratio_sq: 1.0,
        count: 1,
    };
    let b = CurrentEstimate {
        v: Vector2::new(0.0, 0.0),
        cov: Matrix2::identity() * 4.0,
        ..a
    };
    let p = pool(&[a, b]).unwrap();
    assert!((p.v[0] - 0.8).abs() < 1e-12 && p.v[1].abs() < 1e-12);
    assert_eq!(p.count, 2);
    // χ² = 0.2² + 0.8²/4 = 0.2 on 2: no inflation.
    assert!((p.cov[(0, 0)] - 0.8).abs() < 1e-12);
    let far = CurrentEstimate {
        v: Vector2::new(10.0, 0.0),
        ..a
    };
    let q = pool(&[a, far]).unwrap();
    assert!(q.birge_ratio_sq > 10.0 && q.cov[(0, 0)] > 0.5);
}

#[test]
fn heading_shapes_are_step_averages() {
    let e = functions_of(&[0.0, 0.2, 0.4]);
    assert!((e[(0, 0)] - 0.5 * (1.0 + 0.2f64.cos())).abs() < 1e-15);
    assert!((e[(1, 1)] - 0.5 * (0.2f64.sin() + 0.4f64.sin())).abs() < 1e-15);
    assert!((e[(2, 0)] - 0.4f64.cos()).abs() < 1e-15);
    assert!(applies(&Dof::HORIZONTAL));
    assert!(!applies(&Dof::ALL));
    assert!(!applies(&[Dof::Surge, Dof::Yaw]));
}
