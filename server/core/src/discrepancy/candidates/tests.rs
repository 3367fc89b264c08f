use super::*;

#[test]
fn coriolis_from_diagonal_m_has_fossens_products_and_does_no_work() {
    let dofs = Dof::ALL.to_vec();
    let m = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![
        10.0, 20.0, 30.0, 4.0, 5.0, 6.0,
    ]));
    let nu = [0.3, -0.2, 0.1, 0.05, -0.04, 0.07];
    let f = coriolis_force(&dofs, &m, &nu);
    let [u, v, w, p, q, r] = nu;
    assert!((f[0] - (30.0 * w * q - 20.0 * v * r)).abs() < 1e-12);
    assert!((f[5] - ((20.0 - 10.0) * u * v + (5.0 - 4.0) * p * q)).abs() < 1e-12);
    // Skew-symmetric C: νᵀC(ν)ν = 0.
    let work: f64 = f.iter().zip(&nu).map(|(a, b)| a * b).sum();
    assert!(work.abs() < 1e-12);
}

#[test]
fn a_tether_pull_is_the_ned_force_seen_in_the_body_frame() {
    // f_b = R(Θ)ᵀ f_n with R from nalgebra's roll–pitch–yaw (z-y-x)
    // rotation; the regressor is the left-hand side, −f_b per newton.
    let dofs = Dof::ALL.to_vec();
    let z = DMatrix::zeros(6, 6);
    let ctx = TermContext {
        dofs: &dofs,
        m_ref: &z,
        d_ref: &z,
    };
    let f_n = nalgebra::Vector3::new(120.0, -45.0, 0.0);
    for eta in [
        [0.0, 0.0, 10.0, 0.0, 0.0, 0.0],
        [0.0, 0.0, 10.0, 0.2, -0.15, 2.4],
        [0.0, 0.0, 10.0, -0.1, 0.3, -1.1],
    ] {
        let r = nalgebra::Rotation3::from_euler_angles(eta[3], eta[4], eta[5]);
        let f_b = r.transpose() * f_n;
        for (row, want) in [(0, f_b.x), (1, f_b.y)] {
            let got: f64 = (0..2)
                .map(|p| Effect::TetherPull.regressor(p, row, &ctx, &[0.0; 6], &eta) * f_n[p])
                .sum();
            assert!(
                (got + want).abs() < 1e-9,
                "row {row} at {eta:?}: {got} vs −{want}"
            );
        }
        for row in 2..6 {
            assert_eq!(
                Effect::TetherPull.regressor(0, row, &ctx, &[0.0; 6], &eta),
                0.0
            );
        }
    }
    assert_eq!(Effect::TetherPull.rows(&dofs, &z), vec![0, 1]);
    assert_eq!(Effect::TetherPull.family(), Family::Tether);
}

#[test]
fn a_terms_force_is_the_sum_of_its_regressors() {
    let dofs = Dof::ALL.to_vec();
    let m = DMatrix::from_fn(6, 6, |i, j| {
        if i == j {
            50.0 + 7.0 * i as f64
        } else {
            0.5 * (i * j) as f64
        }
    });
    let d = DMatrix::from_fn(6, 6, |i, j| {
        if i == j {
            20.0
        } else {
            (i as f64 - j as f64) * 1.5
        }
    });
    let ctx = TermContext {
        dofs: &dofs,
        m_ref: &m,
        d_ref: &d,
    };
    let nu = [0.8, -0.2, 0.1, 0.05, -0.03, 0.12];
    let eta = [1.0, 2.0, 30.0, 0.1, -0.05, 2.2];
    for (e, theta) in [
        (Effect::CoriolisFromM, vec![0.9]),
        (Effect::Current, vec![0.25, -0.1]),
        (Effect::TetherPull, vec![30.0, 12.0]),
        (Effect::QuadraticDamping { dof: Dof::Sway }, vec![40.0]),
    ] {
        let mut got = [0.0; 6];
        e.add_force(&theta, &ctx, &nu, &eta, &mut got);
        for (row, g) in got.iter().enumerate() {
            let want: f64 = theta
                .iter()
                .enumerate()
                .map(|(p, t)| t * e.regressor(p, row, &ctx, &nu, &eta))
                .sum();
            assert!(
                (g - want).abs() < 1e-12 * (1.0 + want.abs()),
                "{e:?} row {row}: {g} vs {want}"
            );
        }
    }
}

#[test]
fn library_lists_coupling_only_where_the_baseline_has_none() {
    let dofs = vec![Dof::Surge, Dof::Sway, Dof::Yaw];
    let mut m = DMatrix::identity(3, 3);
    m[(1, 2)] = 0.1;
    let d = DMatrix::identity(3, 3);
    let lib = library(&dofs, &m, &d, &LibrarySettings::default());
    assert!(!lib.contains(&Effect::Coupling {
        dof: Dof::Sway,
        from: Dof::Yaw
    }));
    assert!(lib.contains(&Effect::Coupling {
        dof: Dof::Yaw,
        from: Dof::Sway
    }));
    assert!(lib.contains(&Effect::Current));
    assert!(lib.contains(&Effect::TetherPull));
    assert!(lib.contains(&Effect::CoriolisProduct {
        dof: Dof::Yaw,
        a: Dof::Surge,
        b: Dof::Sway
    }));
    // Cubic per DOF, cross-flow for every ordered pair of modeled DOFs.
    assert!(lib.contains(&Effect::CubicDamping { dof: Dof::Yaw }));
    assert!(lib.contains(&Effect::CrossDamping {
        dof: Dof::Sway,
        from: Dof::Yaw
    }));
    let cross = lib
        .iter()
        .filter(|e| e.family() == Family::CrossDamping)
        .count();
    assert_eq!(cross, 6);
    // |r|·v in sway is sign-symmetric in r, v·r is not.
    let ctx = TermContext {
        dofs: &dofs,
        m_ref: &m,
        d_ref: &d,
    };
    let e = Effect::CrossDamping {
        dof: Dof::Sway,
        from: Dof::Yaw,
    };
    let eta = [0.0; 6];
    assert_eq!(e.regressor(0, 1, &ctx, &[0.1, 0.5, -0.2], &eta), 0.1);
    assert_eq!(e.regressor(0, 1, &ctx, &[0.1, 0.5, 0.2], &eta), 0.1);
    assert_eq!(e.regressor(0, 0, &ctx, &[0.1, 0.5, 0.2], &eta), 0.0);
    let c = Effect::CubicDamping { dof: Dof::Surge };
    assert!((c.regressor(0, 0, &ctx, &[-0.5, 0.0, 0.0], &eta) + 0.125).abs() < 1e-15);
    // No attitude DOFs: no restoring shapes.
    assert!(!lib.iter().any(|e| e.family() == Family::Restoring));
}
