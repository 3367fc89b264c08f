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

/// `apply` puts the velocity through the water in place of ν and leaves γ:
/// a current of 0.2 m/s towards north seen at ψ = 90° is v_c = −0.2 m/s
/// (ν = (0.5, 0.1, 0.05) → ν_r = (0.5, 0.3, 0.05)), at ψ = 0 u_c = 0.2
/// (→ (0.3, 0.1, 0.05)). With the attitude logged (a 6-DOF vehicle) ν_c is
/// R(φ, θ, ψ)ᵀ V: pitched 0.3 rad at ψ = 0, u_c = 0.2 cos 0.3 and the heave
/// w_c = 0.2 sin 0.3.
#[test]
fn apply_fits_the_velocity_through_the_water() {
    let r = Relative {
        dofs: Dof::HORIZONTAL.to_vec(),
        v: Vector2::new(0.2, 0.0),
        tilt: None,
    };
    let psi = [std::f64::consts::FRAC_PI_2, 0.0];
    let seg = Segment {
        run_id: "a".into(),
        h: 0.1,
        t0: 0.0,
        u: DMatrix::from_fn(2, 4, |k, j| if j == 3 { psi[k] } else { 1.0 }),
        y: DMatrix::zeros(2, 3),
    };
    let nu = DMatrix::from_row_slice(2, 3, &[0.5, 0.1, 0.05, 0.5, 0.1, 0.05]);
    let gamma = DMatrix::from_fn(2, 3, |k, j| (k * 3 + j) as f64);
    let out = r.apply(Experiment::new(0.1, nu, gamma.clone()), &seg, 3);
    let want = [0.5, 0.3, 0.05, 0.3, 0.1, 0.05];
    for (k, w) in want.chunks(3).enumerate() {
        for (j, w) in w.iter().enumerate() {
            assert!((out.nu[(k, j)] - w).abs() < 1e-15, "{k},{j}");
        }
    }
    assert_eq!(out.gamma, gamma);

    let r6 = Relative {
        dofs: Dof::ALL.to_vec(),
        v: Vector2::new(0.2, 0.0),
        tilt: Some((1, 2)),
    };
    let seg6 = Segment {
        run_id: "b".into(),
        h: 0.1,
        t0: 0.0,
        // [τ_X, φ, θ, ψ]
        u: DMatrix::from_row_slice(1, 4, &[1.0, 0.0, 0.3, 0.0]),
        y: DMatrix::zeros(1, 6),
    };
    let out = r6.apply(
        Experiment::new(0.1, DMatrix::zeros(1, 6), DMatrix::zeros(1, 6)),
        &seg6,
        3,
    );
    let (u_c, w_c) = (0.2 * 0.3f64.cos(), 0.2 * 0.3f64.sin());
    for (j, want) in [-u_c, 0.0, -w_c, 0.0, 0.0, 0.0].into_iter().enumerate() {
        assert!(
            (out.nu[(0, j)] - want).abs() < 1e-15,
            "{j}: {}",
            out.nu[(0, j)]
        );
    }
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
