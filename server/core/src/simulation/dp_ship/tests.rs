use nalgebra::{Matrix3, Vector3};

use super::model::{coriolis, coriolis_force, coriolis_force_jacobian, rotation};
use super::*;
use crate::simulation::integrate::simulate;

/// Rounding to the paper's four decimals.
fn printed(x: f64) -> f64 {
    (x * 1e4).round() / 1e4
}

#[test]
fn b_from_eq_29_30_49_reproduces_eq_52_where_k_is_not_rounded_away() {
    let ship = DpShip::supply_vessel();
    let b = ship.state_space_b();
    let exceptions = [(1, 4), (2, 4), (2, 5)];
    for i in 0..3 {
        for j in 0..6 {
            let p = paper::B_STATE_SPACE[i][j];
            if exceptions.contains(&(i, j)) {
                // Off by one or two in the last printed digit.
                assert!(
                    (b[(i, j)] - p).abs() < 2.5e-4,
                    "B[{i},{j}] {} vs {p}",
                    b[(i, j)]
                );
                assert_ne!(printed(b[(i, j)]), p);
            } else {
                assert_eq!(printed(b[(i, j)]), p, "B[{i},{j}] = {}", b[(i, j)]);
            }
        }
    }
    // K″5 = 2.848e-3 and K″6 = 2.61e-3 round to eq. 49's 2.8 and 2.6 and give
    // all 18 printed entries of eq. 52.
    let mut k = ship.clone();
    k.k[4] = 2.848e-3;
    k.k[5] = 2.61e-3;
    assert_eq!(
        ((k.k[4] * 1e4).round(), (k.k[5] * 1e4).round()),
        (28.0, 26.0)
    );
    let b = k.state_space_b();
    for i in 0..3 {
        for j in 0..6 {
            assert_eq!(printed(b[(i, j)]), paper::B_STATE_SPACE[i][j], "B[{i},{j}]");
        }
    }
}

#[test]
fn a_from_eq_30_48_reproduces_eq_51_except_the_sensitive_a32() {
    let a = DpShip::supply_vessel().state_space_a();
    for i in 0..3 {
        for j in 0..3 {
            let p = paper::A_STATE_SPACE[i][j];
            if (i, j) == (2, 1) {
                assert!((a[(i, j)] - p).abs() < 1.5e-4, "A32 {}", a[(i, j)]);
            } else {
                assert_eq!(printed(a[(i, j)]), p, "A[{i},{j}] = {}", a[(i, j)]);
            }
        }
    }
}

#[test]
fn theta_round_trips_through_a_h_and_k() {
    let ship = DpShip::supply_vessel();
    assert_eq!(ship.theta(), paper::THETA);
    let back = DpShip::from_theta(ship.m, ship.thrust.clone(), &paper::THETA);
    assert_eq!(back, ship);
    // A_h = −D·M⁻¹ (eq. 39).
    let d = ship.damping();
    assert!((-(d * ship.m_inv()) - ship.a_h).abs().max() < 1e-15);
}

#[test]
fn coriolis_does_no_work_and_its_jacobian_matches_differences() {
    let m = DpShip::supply_vessel().m;
    let nu = Vector3::new(0.12, -0.03, 0.02);
    assert!((nu.dot(&coriolis_force(&m, &nu))).abs() < 1e-18);
    let c = coriolis(&m, &nu);
    assert!((c + c.transpose()).abs().max() < 1e-18);
    let jac = coriolis_force_jacobian(&m, &nu);
    let eps = 1e-7;
    for j in 0..3 {
        let mut p = nu;
        p[j] += eps;
        let mut q = nu;
        q[j] -= eps;
        let fd = (coriolis_force(&m, &p) - coriolis_force(&m, &q)) / (2.0 * eps);
        assert!((fd - jac.column(j)).abs().max() < 1e-9, "column {j}");
    }
}

#[test]
fn free_motion_keeps_its_kinetic_energy() {
    // No damping, thrust or bias: only C(ν) acts, and it does no work, so
    // ½·hᵀM⁻¹h is conserved while surge, sway and yaw exchange momentum.
    let mut ship = DpShip::supply_vessel();
    ship.a_h = Matrix3::zeros();
    let m_inv = ship.m_inv();
    let energy = |h: &Vector3<f64>| 0.5 * h.dot(&(m_inv * h));
    let h0 = ship.m * Vector3::new(0.1, 0.05, 0.03);
    let zero = Vector3::zeros();
    let u = vec![vec![0.0; 6]; 2000];
    let xs = simulate(
        |x, u, dx| {
            let h = Vector3::new(x[0], x[1], x[2]);
            dx.copy_from_slice(ship.h_dot(&m_inv, &h, u, &zero).as_slice());
        },
        h0.as_slice(),
        &u,
        0.05,
    );
    let last = xs.last().unwrap();
    let h1 = Vector3::new(last[0], last[1], last[2]);
    assert!((h1 - h0).norm() > 1e-3, "momentum must be redistributed");
    assert!((energy(&h1) / energy(&h0) - 1.0).abs() < 1e-9);
}

#[test]
fn surge_step_follows_the_first_order_law() {
    // Pure surge from rest, no bias: (M11) u̇ = A_h11·M11·u + (K1 + K2)·u1,
    // so u(t) = −(K1+K2)·u1/(A_h11·M11)·(1 − e^{A_h11·t}) and x = ∫u along ψ0.
    let ship = DpShip::supply_vessel();
    let cfg = TrialConfig {
        bias_initial_std: [0.0; 3],
        bias_walk_std: [0.0; 3],
        position_noise_std: 0.0,
        heading_noise_std: 0.0,
        ..TrialConfig::supply_vessel()
    };
    let n = 300;
    let mut u = nalgebra::DMatrix::zeros(n, 6);
    u.column_mut(0).fill(0.1);
    u.column_mut(1).fill(0.1);
    let psi0 = 0.7;
    let run = simulate_trial(&ship, Manoeuvre::Surge, &u, [1.0, 2.0, psi0], &cfg, 3);
    let a = paper::A_H[0][0];
    let m11 = paper::M_INERTIA[0][0];
    let gain = -(2.0 * paper::K_THRUST[0] * 0.1) / (a * m11);
    for k in [1, 50, 299] {
        let t = run.t[k];
        let speed = gain * (1.0 - (a * t).exp());
        let dist = gain * (t - ((a * t).exp() - 1.0) / a);
        assert!((run.nu[(k, 0)] - speed).abs() < 1e-10 * gain.max(1.0));
        assert!((run.nu[(k, 1)]).abs() < 1e-15 && (run.nu[(k, 2)]).abs() < 1e-15);
        assert!((run.eta[(k, 0)] - 1.0 - dist * psi0.cos()).abs() < 1e-9);
        assert!((run.eta[(k, 1)] - 2.0 - dist * psi0.sin()).abs() < 1e-9);
        assert_eq!(run.eta[(k, 2)], psi0);
    }
}

#[test]
fn campaign_looks_like_the_sea_trials_and_has_the_stated_noise() {
    let ship = DpShip::supply_vessel();
    let cfg = TrialConfig::supply_vessel();
    let runs = simulate_campaign(&ship, &cfg, paper::SAMPLES_PER_RUN, 11);
    assert_eq!(runs.len(), 6);
    let speed_unit = (paper::LENGTH_M * paper::GRAVITY).sqrt();
    for run in &runs {
        let kind = run.manoeuvre;
        let max = |c: usize| run.nu.column(c).amax();
        match kind {
            Manoeuvre::Surge => {
                let top = max(0) * speed_unit;
                assert!(top > 1.5 && top < 5.0, "surge speed {top} m/s");
                assert!(run.u.columns(2, 4).amax() == 0.0);
            }
            Manoeuvre::SwayYaw => {
                let psi = run.eta_true.column(2);
                let turn = (psi.max() - psi.min()).to_degrees();
                assert!(turn > 30.0, "turn {turn}°");
                assert!(run.u.columns(0, 2).amax() == 0.0 && run.u.column(5).amax() == 0.0);
            }
            Manoeuvre::Azimuth => {
                // Yaw rates of up to ≈ 1°/s as in Fig. 7.
                let r = max(2) / paper::bis_time_unit_s();
                assert!(r.to_degrees() > 0.3 && r.to_degrees() < 2.0, "r {r}");
                assert!(run.u.columns(0, 5).amax() == 0.0);
            }
        }
        let e = &run.eta - &run.eta_true;
        let std = |c: usize| (e.column(c).norm_squared() / e.nrows() as f64).sqrt();
        assert!((std(0) / cfg.position_noise_std - 1.0).abs() < 0.12);
        assert!((std(2) / cfg.heading_noise_std - 1.0).abs() < 0.12);
    }
    // J(ψ) rotates body surge into the heading direction.
    let j = rotation(std::f64::consts::FRAC_PI_2);
    assert!((j * Vector3::new(1.0, 0.0, 0.0) - Vector3::new(0.0, 1.0, 0.0)).norm() < 1e-15);
}
