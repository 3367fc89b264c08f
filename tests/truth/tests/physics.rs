//! The plant against analytic facts of Fossen's model.

use nalgebra::{Matrix6, Vector6};
use seatrial_truth::forces::{coriolis_force, coriolis_matrix};
use seatrial_truth::rng::Rng;
use seatrial_truth::{Plant, State, Vessel};

fn random_nu(rng: &mut Rng) -> Vector6<f64> {
    Vector6::from_fn(|i, _| {
        if i < 3 {
            rng.range(-1.0, 1.0)
        } else {
            rng.range(-0.4, 0.4)
        }
    })
}

fn at_rest() -> State {
    State::new(
        Vector6::new(0.0, 0.0, 50.0, 0.0, 0.0, 0.3),
        Vector6::zeros(),
    )
}

#[test]
fn steady_surge_speed_is_the_root_of_linear_plus_quadratic_damping() {
    for seed in 0..5 {
        // W = B so surge sees no restoring force; z_G W still rights pitch.
        let v = Vessel {
            w_minus_b: 0.0,
            ..Vessel::draw(seed)
        };
        let plant = Plant::new(&v);
        for tau_x in [40.0, -25.0, 150.0] {
            let tau = Vector6::new(tau_x, 0.0, 0.0, 0.0, 0.0, 0.0);
            // lightly damped pitch couples in through m z_G: fly long
            let x = plant.advance(&at_rest(), &tau, 900.0, 0.01);
            // (l0 + lu|u|)u + q|u|u = τ  ⇒  (lu + q)u² + l0 u − |τ| = 0 for |u|
            let (l0, a) = (
                v.damping_linear[0],
                v.damping_linear_per_speed[0] + v.damping_quadratic[0],
            );
            let root = (-l0 + (l0 * l0 + 4.0 * a * tau_x.abs()).sqrt()) / (2.0 * a);
            let expected = root * tau_x.signum();
            assert!(
                (x.nu[0] - expected).abs() < 1e-9 * expected.abs(),
                "seed {seed} τ_X {tau_x}: u = {} vs root {expected}",
                x.nu[0]
            );
            assert!(
                x.nu.rows(1, 5).norm() < 1e-9,
                "only surge moves: {:?}",
                x.nu
            );
        }
    }
}

#[test]
fn coriolis_is_skew_symmetric_and_does_no_work() {
    let mut rng = Rng::new(11);
    for seed in 0..20 {
        let v = Vessel::draw(seed);
        for m in [v.m(), v.m_rb(), v.m_a()] {
            for _ in 0..20 {
                let nu = random_nu(&mut rng);
                let c = coriolis_matrix(&m, &nu);
                let f = coriolis_force(&m, &nu);
                let scale = m.norm() * nu.norm_squared();
                assert!((c + c.transpose()).norm() < 1e-12 * m.norm() * nu.norm());
                assert!((c * nu - f).norm() < 1e-12 * scale);
                assert!(nu.dot(&f).abs() < 1e-13 * scale, "νᵀC(ν)ν = {}", nu.dot(&f));
                assert!(
                    f.norm() > 1e-6 * scale,
                    "the check must not pass on a zero force"
                );
            }
        }
    }
}

#[test]
fn unforced_restoring_free_motion_never_gains_kinetic_energy() {
    let mut rng = Rng::new(5);
    for seed in 0..5 {
        let v = Vessel::draw(seed).without_restoring();
        let plant = Plant::new(&v);
        let mut x = State::new(at_rest().eta, random_nu(&mut rng));
        let e0 = plant.kinetic_energy(&x.nu);
        let mut e = e0;
        for _ in 0..6000 {
            x = plant.rk4_step(&x, &Vector6::zeros(), 0.005);
            let next = plant.kinetic_energy(&x.nu);
            assert!(
                next <= e + 1e-13 * e0,
                "seed {seed}: energy rose {e} → {next}"
            );
            e = next;
        }
        assert!(e < 0.5 * e0, "damping must dissipate: {e0} → {e}");

        // Without damping the energy is conserved (C(ν) does no work).
        let free = Plant::new(&v.without_damping());
        let mut x = State::new(at_rest().eta, random_nu(&mut rng));
        let e0 = free.kinetic_energy(&x.nu);
        x = free.advance(&x, &Vector6::zeros(), 20.0, 0.005);
        let drift = (free.kinetic_energy(&x.nu) - e0).abs() / e0;
        assert!(drift < 1e-8, "seed {seed}: energy drift {drift}");
    }
}

#[test]
fn static_pitch_equilibrium_balances_the_righting_moment() {
    for seed in 0..5 {
        let v = Vessel {
            w_minus_b: 0.0,
            ..Vessel::draw(seed)
        };
        let plant = Plant::new(&v);
        let zw = v.zg_w_minus_zb_b();
        for frac in [0.2, -0.5] {
            let tau_m = frac * zw;
            let tau = Vector6::new(0.0, 0.0, 0.0, 0.0, tau_m, 0.0);
            let x = plant.advance(&at_rest(), &tau, 900.0, 0.01);
            let theta = x.eta[4];
            assert!(
                (zw * theta.sin() - tau_m).abs() < 1e-9 * zw,
                "seed {seed}: (z_G W − z_B B) sin θ = {} vs τ_M = {tau_m}",
                zw * theta.sin()
            );
            assert!((theta - frac.asin()).abs() < 1e-9);
            assert!(x.eta[3].abs() < 1e-12 && x.nu.norm() < 1e-9);
        }
    }
}

#[test]
fn rk4_error_falls_sixteenfold_when_the_step_halves() {
    let mut rng = Rng::new(3);
    for seed in 0..4 {
        // |ν|ν and |u|ν are only C¹: a velocity crossing zero caps RK4 below
        // fourth order, so the order is measured on the smooth part (inertia,
        // C(ν)ν, linear damping, g(η)).
        let mut v = Vessel::draw(seed);
        v.damping_quadratic = Vector6::zeros();
        v.damping_linear_per_speed = Vector6::zeros();
        let plant = Plant::new(&v);
        let x0 = State::new(
            Vector6::new(0.0, 0.0, 30.0, 0.1, -0.1, 0.5),
            random_nu(&mut rng),
        );
        let tau = Vector6::from_fn(|i, _| 0.2 * v.m()[(i, i)] * rng.range(-1.0, 1.0));
        let run = |h: f64| plant.advance(&x0, &tau, 5.0, h);
        let reference = run(0.05 / 64.0);
        let err = |x: State| {
            let d = x.nu - reference.nu;
            let e = x.eta - reference.eta;
            (d.norm_squared() + e.norm_squared()).sqrt()
        };
        let (e1, e2) = (err(run(0.05)), err(run(0.025)));
        let ratio = e1 / e2;
        println!("seed {seed}: error {e1:.3e} → {e2:.3e}, ratio {ratio:.2}");
        assert!((13.0..19.5).contains(&ratio), "seed {seed}: ratio {ratio}");
    }
}

#[test]
fn actuator_lag_delays_the_force_and_limits_clip_it() {
    let v = Vessel::draw(2);
    let tau = Vector6::new(100.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let ideal = Plant::new(&v).advance(&at_rest(), &tau, 0.3, 0.005);
    let mut lagged_v = v.clone();
    lagged_v.actuator.lag_s = Some(Vector6::repeat(0.5));
    let lagged = Plant::new(&lagged_v).advance(&at_rest(), &tau, 0.3, 0.005);
    // τ_act = 100 (1 − e^{−t/0.5})
    let expected = 100.0 * (1.0 - (-0.3f64 / 0.5).exp());
    assert!((lagged.tau_act[0] - expected).abs() < 1e-6);
    assert!(lagged.nu[0] < 0.5 * ideal.nu[0]);
    let mut limited_v = v.clone();
    limited_v.actuator.limits = Some(Vector6::repeat(40.0));
    let p = Plant::new(&limited_v);
    assert_eq!(p.applied_force(&at_rest(), &tau)[0], 40.0);
    let m: Matrix6<f64> = v.m();
    let accel = p.derivative(&at_rest(), &tau).nu;
    // at rest and level only the clipped τ_X acts in surge: (M ν̇)_X = 40
    assert!(((m * accel)[0] - 40.0).abs() < 1e-9);
}
