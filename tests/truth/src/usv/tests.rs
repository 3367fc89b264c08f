//! Tests of the surface-vessel truth against closed forms, hand integrals
//! and the published numbers.

use nalgebra::{Matrix3, Vector3};

use super::*;
use crate::dp_ship;
use crate::rng::Rng;

fn still(n: usize) -> CurrentTrack {
    Current::None.realise(n, 1.0, &mut Rng::new(0))
}

/// Flies constant τ for `t_s` seconds from `s0` at step `dt` in a constant
/// current; the final state.
fn hold(
    sim: &Simulator,
    s0: [f64; 6],
    tau: Vector3<f64>,
    cur: CurrentNow,
    t_s: f64,
    dt: f64,
) -> [f64; 6] {
    let mut s = s0;
    for _ in 0..(t_s / dt).round() as usize {
        s = sim.step(&s, &tau, &cur, dt);
    }
    s
}

fn both() -> [(SurfaceVessel, f64); 2] {
    // (vessel, RK4 step).
    [(otter(), 0.01), (supply(), 0.1)]
}

/// (a) A constant τ_X on a straight course settles where
/// X_u u + X_|u|u |u| u + τ_X = 0, checked against the quadratic formula
/// written out here, with every other effect on (they vanish at v = r = 0).
#[test]
fn steady_surge_speed_matches_the_closed_form() {
    for (vessel, dt) in both() {
        let sim = Simulator::new(&vessel, Effects::all(Current::None));
        let tau_x = if vessel.name == "otter" { 150.0 } else { 1.0e5 };
        let settle = if vessel.name == "otter" { 60.0 } else { 4000.0 };
        let s = hold(
            &sim,
            [0.0; 6],
            Vector3::new(tau_x, 0.0, 0.0),
            CurrentNow::NONE,
            settle,
            dt,
        );
        let (a, b) = (-vessel.x_uu, -vessel.x_u);
        let closed = (-b + (b * b + 4.0 * a * tau_x).sqrt()) / (2.0 * a);
        assert!(
            (s[0] / closed - 1.0).abs() < 1e-9,
            "{}: {} vs {closed}",
            vessel.name,
            s[0]
        );
        assert_eq!((s[1], s[2]), (0.0, 0.0));
        assert!((vessel.steady_surge_speed(tau_x, true) / closed - 1.0).abs() < 1e-12);
        assert!((vessel.steady_surge_speed(-tau_x, true) + closed).abs() < 1e-12);
        // The linear speed is higher.
        assert!(vessel.steady_surge_speed(tau_x, false) > 1.2 * closed);
    }
}

/// (b) With C_A on, a vessel moving through the water at a drift angle
/// (r = 0) feels N = (Y_v̇ − X_u̇) u_r v_r from C_A(ν_r)ν_r and nothing else
/// from it; through the simulator, with a current, the Munk switch changes
/// M ν̇ by exactly [0, 0, (Y_v̇ − X_u̇) u_r v_r].
#[test]
fn munk_moment_is_the_yaw_entry_of_c_a() {
    for (vessel, _) in both() {
        let (u_r, v_r) = (1.2, -0.35);
        let nu_r = Vector3::new(u_r, v_r, 0.0);
        let ca = vessel.c_a(&nu_r) * nu_r;
        let munk = (vessel.y_vdot - vessel.x_udot) * u_r * v_r;
        assert!(ca[0].abs() < 1e-12 && ca[1].abs() < 1e-12);
        assert!((-ca[2] - munk).abs() <= 1e-12 * munk.abs());
        assert_eq!(vessel.munk_moment(u_r, v_r), munk);
        // Destabilising: it turns the bow away from the flow (N v_r u_r < 0).
        assert!(munk * u_r * v_r < 0.0);

        let cur = CurrentNow {
            speed_mps: 0.4,
            rate_mps2: 0.0,
            direction_rad: 2.1,
        };
        let psi = 0.3;
        let [u_c, v_c] = cur.body(psi);
        let nu = nu_r + Vector3::new(u_c, v_c, 0.0);
        let tau = Vector3::new(10.0, -3.0, 2.0);
        let mut fx = Effects::all(Current::None);
        let on = Simulator::new(&vessel, fx).nu_dot(&nu, psi, &tau, &cur);
        fx.munk = false;
        let off = Simulator::new(&vessel, fx).nu_dot(&nu, psi, &tau, &cur);
        let diff = vessel.mass_matrix() * (on - off);
        let scale = munk.abs();
        assert!(diff[0].abs() < 1e-9 * scale && diff[1].abs() < 1e-9 * scale);
        assert!(
            (diff[2] - munk).abs() < 1e-9 * scale,
            "{} vs {munk}",
            diff[2]
        );
    }
}

/// (c) C_RB(ν) and C_A(ν_r) are skew-symmetric and do no work.
#[test]
fn coriolis_matrices_do_no_work() {
    let mut rng = Rng::new(11);
    for (vessel, _) in both() {
        for _ in 0..100 {
            let nu = Vector3::new(
                rng.range(-3.0, 3.0),
                rng.range(-1.0, 1.0),
                rng.range(-0.5, 0.5),
            );
            let crb = vessel.c_rb(&nu);
            let ca = vessel.c_a(&nu);
            let scale = vessel.mass_kg * nu.norm_squared() * (1.0 + vessel.length_m);
            assert!(nu.dot(&(crb * nu)).abs() < 1e-12 * scale);
            assert!(nu.dot(&(ca * nu)).abs() < 1e-12 * scale);
            assert_eq!(crb + crb.transpose(), Matrix3::zeros());
            assert_eq!(ca + ca.transpose(), Matrix3::zeros());
        }
    }
}

/// (d) In a current with no thrust a vessel starting at rest over ground
/// ends drifting with the water: ν_r → 0, and its NED velocity → V_c
/// (cos β_c, sin β_c). With every effect on (the Munk moment turns it on
/// the way).
#[test]
fn without_thrust_the_vessel_drifts_with_the_current() {
    for (vessel, dt) in both() {
        let cur = CurrentNow {
            speed_mps: 0.4,
            rate_mps2: 0.0,
            direction_rad: -2.5,
        };
        let sim = Simulator::new(&vessel, Effects::all(Current::None));
        let settle = if vessel.name == "otter" {
            120.0
        } else {
            6000.0
        };
        let s = hold(
            &sim,
            [0.0, 0.0, 0.0, 0.0, 0.0, 0.7],
            Vector3::zeros(),
            cur,
            settle,
            dt,
        );
        let [u_c, v_c] = cur.body(s[5]);
        let nu_r = Vector3::new(s[0] - u_c, s[1] - v_c, s[2]);
        assert!(nu_r.norm() < 1e-6, "{}: ν_r = {nu_r}", vessel.name);
        let (sn, cs) = s[5].sin_cos();
        let north = cs * s[0] - sn * s[1];
        let east = sn * s[0] + cs * s[1];
        assert!((north - 0.4 * (-2.5f64).cos()).abs() < 1e-6);
        assert!((east - 0.4 * (-2.5f64).sin()).abs() < 1e-6);
        // A drifting vessel stays drifting (ν_r = 0 is an equilibrium).
        let s0 = [u_c, v_c, 0.0, 0.0, 0.0, s[5]];
        let d = sim.derivative(&s0, &Vector3::zeros(), &cur);
        assert!(d[..3].iter().all(|a| a.abs() < 1e-15));
    }
}

/// A Gauss–Markov current drags the idle vessel along: ν_r stays small
/// against V_c, and the realised track is the one returned.
#[test]
fn idle_vessel_follows_a_slowly_varying_current() {
    let vessel = otter();
    let gm = Current::GaussMarkov {
        mean_mps: 0.3,
        std_mps: 0.05,
        time_constant_s: 60.0,
        max_mps: 0.6,
        direction_rad: 1.0,
    };
    let sim = Simulator::new(&vessel, Effects::all(gm));
    let n = 3000;
    let track = gm.realise(n, 0.1, &mut Rng::new(3));
    let [u_c, v_c] = track.segment(0, 0.1).body(0.0);
    let states = sim.fly(
        [u_c, v_c, 0.0, 0.0, 0.0, 0.0],
        &vec![Vector3::zeros(); n],
        &track,
        0.1,
        10,
    );
    let rel: Vec<f64> = states
        .iter()
        .enumerate()
        .map(|(k, s)| {
            let [u_c, v_c] = track.segment(k, 0.1).body(s[5]);
            (s[0] - u_c).hypot(s[1] - v_c)
        })
        .collect();
    let worst = rel.iter().copied().fold(0.0, f64::max);
    let mean = rel.iter().sum::<f64>() / n as f64;
    eprintln!("GM current: |ν_r| max {worst:.4}, mean {mean:.4} m/s");
    assert!(worst < 0.03 && mean < 0.01, "{worst} {mean}");
}

/// (e) Cross-flow drag: zero at rest, odd in (v_r, r), and for a
/// rectangular hull (L = 2 m, constant T and C_d) at v_r = 0.5 m/s,
/// r = 1 rad/s equal to the hand integrals ∫₋₁¹ |0.5 + x|(0.5 + x) dx = 13/12
/// and ∫₋₁¹ x|0.5 + x|(0.5 + x) dx = 71/96 (the flow reverses at x = −0.5).
#[test]
fn cross_flow_drag_is_odd_and_matches_hand_integrals() {
    let hull = CrossFlow {
        length_m: 2.0,
        draft_m: 0.5,
        cd: 1.2,
        rho: 1025.0,
    };
    let k = -0.5 * 1025.0 * 0.5 * 1.2;
    assert_eq!(hull.force(0.0, 0.0), (0.0, 0.0));
    let (y, n) = hull.force(0.5, 1.0);
    assert!((y - k * 13.0 / 12.0).abs() < 1e-10, "{y}");
    assert!((n - k * 71.0 / 96.0).abs() < 1e-10, "{n}");
    // Pure sway: Y = k L |v|v, N = 0; pure yaw: Y = 0, N = k |r| r L⁴/32.
    let (y, n) = hull.force(-0.3, 0.0);
    assert!((y - k * 2.0 * -0.09).abs() < 1e-10 && n.abs() < 1e-12);
    let (y, n) = hull.force(0.0, 0.4);
    assert!(y.abs() < 1e-12 && (n - k * 0.16 * 16.0 / 32.0).abs() < 1e-10);
    let mut rng = Rng::new(5);
    for (vessel, _) in both() {
        for _ in 0..50 {
            let (v, r) = (rng.range(-1.0, 1.0), rng.range(-0.3, 0.3));
            let (y1, n1) = vessel.cross_flow.force(v, r);
            let (y2, n2) = vessel.cross_flow.force(-v, -r);
            assert!((y1 + y2).abs() <= 1e-12 * y1.abs().max(1.0));
            assert!((n1 + n2).abs() <= 1e-12 * n1.abs().max(1.0));
            // Drag opposes the motion: it dissipates.
            assert!(y1 * v + n1 * r <= 0.0);
        }
    }
}

fn rows(csv: &str) -> Vec<Vec<f64>> {
    csv.lines()
        .skip(1)
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect()
}

/// (f) Logs: the documented headers, names, families, finite values, ψ in
/// (−π, π], the current per row, and the same seed gives the same bytes.
#[test]
fn logs_have_documented_headers_and_are_reproducible() {
    let gm = Current::GaussMarkov {
        mean_mps: 0.2,
        std_mps: 0.03,
        time_constant_s: 120.0,
        max_mps: 0.4,
        direction_rad: 0.5,
    };
    let usv = UsvTrial {
        effects: Effects::all(gm),
        run_s: 30.0,
        validation_s: 40.0,
        ..UsvTrial::default()
    };
    let a = fly_usv_campaign(&otter(), &usv, 9);
    assert_eq!(a, fly_usv_campaign(&otter(), &usv, 9));
    assert_ne!(
        a.runs[0].csv,
        fly_usv_campaign(&otter(), &usv, 10).runs[0].csv
    );
    let names: Vec<&str> = a.runs.iter().map(|r| r.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "surge-1", "surge-2", "surge-3", "turn-1", "turn-2", "turn-3", "VAL"
        ]
    );
    assert!(a.runs[..6].iter().all(|r| r.family == "dynamic"));
    assert_eq!(a.runs[6].family, "validation");
    let cmd = UsvTrial {
        logged: UsvLogged::Commands,
        ..usv
    };
    let c = fly_usv_campaign(&otter(), &cmd, 9);
    let sup = SupplyTrial {
        effects: Effects::all(Current::Constant {
            speed_mps: 0.4,
            direction_rad: -1.0,
        }),
        samples: 300,
        ..SupplyTrial::default()
    };
    let s = fly_supply_campaign(&supply(), &sup, 9);
    assert_eq!(s, fly_supply_campaign(&supply(), &sup, 9));
    let names: Vec<(&str, &str)> = s.runs.iter().map(|r| (r.name.as_str(), r.family)).collect();
    assert_eq!(
        names,
        [
            ("SI1-1", "dp_surge"),
            ("SI1-2", "dp_surge"),
            ("SI2-1", "dp_sway_yaw"),
            ("SI2-2", "dp_sway_yaw"),
            ("VAL", "validation")
        ]
    );
    for (camp, header, rate, cols) in [
        (&a, FORCES_HEADER, 10.0, 10),
        (&c, COMMANDS_HEADER, 10.0, 9),
        (&s, FORCES_HEADER, 1.0, 10),
    ] {
        assert_eq!(camp.rate_hz, rate);
        for run in &camp.runs {
            assert_eq!(run.csv.lines().next(), Some(header));
            let r = rows(&run.csv);
            assert_eq!(r.len(), run.current.speed_mps.len());
            for (k, row) in r.iter().enumerate() {
                assert_eq!(row.len(), cols);
                assert!(row.iter().all(|x| x.is_finite()));
                assert!((row[0] - k as f64 / rate).abs() < 1e-9);
                let psi = row[cols - 1];
                assert!(psi > -std::f64::consts::PI && psi <= std::f64::consts::PI);
            }
        }
    }
    // Otter: τ_Y is zero in every row; the commands give the logged forces.
    for (rf, rc) in a.runs.iter().zip(&c.runs) {
        assert_eq!(rf.current, rc.current);
        for (f, m) in rows(&rf.csv).iter().zip(rows(&rc.csv)) {
            assert_eq!(f[2], 0.0);
            let x = OTTER_THRUST_N * (m[1] + m[2]);
            let n = OTTER_THRUST_N * OTTER_PROPELLER_Y_M * (m[1] - m[2]);
            assert!((f[1] - x).abs() < 1e-5 && (f[3] - n).abs() < 1e-5);
            // Same motion and noise.
            assert_eq!(&f[4..], &m[3..]);
        }
    }
    // Gauss–Markov: V_c varies within a run; constant current: it does not.
    assert!(a.runs[6].current.speed_mps.windows(2).any(|w| w[0] != w[1]));
    assert!(s.runs[0].current.speed_mps.iter().all(|&v| v == 0.4));
}

/// (g) The clean model is linear where C_RB, its one nonlinearity, is
/// silent: from rest, doubling a surge τ doubles ν to 1e-9; with C_RB off
/// (a check only) doubling any τ does; with C_RB on a turning τ does not,
/// and neither does surge with quadratic damping.
#[test]
fn clean_configuration_is_linear() {
    let response =
        |vessel: &SurfaceVessel, fx: Effects, tau: Vector3<f64>, dt: f64| -> Vec<[f64; 6]> {
            let sim = Simulator::new(vessel, fx);
            let h = 10.0 * dt;
            let taus: Vec<Vector3<f64>> = (0..300)
                .map(|k| if k % 70 < 35 { tau } else { -0.5 * tau })
                .collect();
            sim.fly([0.0; 6], &taus, &still(300), h, 10)
        };
    let gap = |a: &[[f64; 6]], b: &[[f64; 6]]| -> f64 {
        let mut worst = 0.0_f64;
        for (x, y) in a.iter().zip(b) {
            let scale = (2.0 * x[0]).hypot(2.0 * x[1]).max(1e-300);
            worst = worst.max((y[0] - 2.0 * x[0]).hypot(y[1] - 2.0 * x[1]) / scale);
        }
        worst
    };
    for (vessel, dt) in both() {
        let f = if vessel.name == "otter" { 20.0 } else { 2.0e4 };
        let surge = Vector3::new(f, 0.0, 0.0);
        let r1 = response(&vessel, Effects::CLEAN, surge, dt);
        let r2 = response(&vessel, Effects::CLEAN, 2.0 * surge, dt);
        assert!(gap(&r1, &r2) < 1e-9, "{}", gap(&r1, &r2));
        let turn = Vector3::new(f, 0.3 * f, 0.5 * f * vessel.length_m);
        let no_crb = Effects {
            rigid_body_coriolis: false,
            ..Effects::CLEAN
        };
        let r1 = response(&vessel, no_crb, turn, dt);
        let r2 = response(&vessel, no_crb, 2.0 * turn, dt);
        assert!(gap(&r1, &r2) < 1e-9, "{}", gap(&r1, &r2));
        let r1 = response(&vessel, Effects::CLEAN, turn, dt);
        let r2 = response(&vessel, Effects::CLEAN, 2.0 * turn, dt);
        assert!(gap(&r1, &r2) > 1e-6, "{}", gap(&r1, &r2));
        let quad = Effects {
            quadratic_surge: true,
            ..Effects::CLEAN
        };
        let r1 = response(&vessel, quad, surge, dt);
        let r2 = response(&vessel, quad, 2.0 * surge, dt);
        assert!(gap(&r1, &r2) > 1e-3, "{}", gap(&r1, &r2));
    }
}

/// The Otter's published numbers come out of the formulas; it cannot sway
/// by itself: its surge runs (clean, no current, no noise) never leave the
/// straight line, and its turn runs sway.
#[test]
fn otter_numbers_and_sway_only_through_yaw() {
    let o = otter();
    assert_eq!(o.mass_kg, 80.0);
    assert!((o.x_g_m - 0.153125).abs() < 1e-12);
    assert!((o.i_z - 16.0125).abs() < 1e-9, "{}", o.i_z);
    let m = o.mass_matrix();
    assert!((m[(0, 0)] - 85.5).abs() < 1e-12 && (m[(1, 1)] - 162.5).abs() < 1e-12);
    assert!((m[(1, 2)] - 12.25).abs() < 1e-12);
    assert!((o.x_u + 77.554).abs() < 1e-3 && (o.x_uu + 25.128).abs() < 1e-3);
    assert!((o.cross_flow.draft_m - 0.195122).abs() < 1e-6);
    assert!(
        (o.cross_flow.cd - 1.0046).abs() < 1e-3,
        "{}",
        o.cross_flow.cd
    );
    let crit = o.critical_speed(true).unwrap();
    assert!((1.1..1.2).contains(&crit), "{crit}");
    assert!(o.critical_speed(false).is_none());
    let trial = UsvTrial {
        noise: Noise::NONE,
        run_s: 60.0,
        ..UsvTrial::default()
    };
    let camp = fly_usv_campaign(&o, &trial, 1);
    for run in &camp.runs[..3] {
        assert!(rows(&run.csv).iter().all(|r| r[5] == 0.0 && r[6] == 0.0));
    }
    for run in &camp.runs[3..] {
        let v = rows(&run.csv)
            .iter()
            .map(|r| r[5].abs())
            .fold(0.0, f64::max);
        assert!(v > 0.01, "{}: {v}", run.name);
    }
    // The clean speed levels.
    let speeds: Vec<f64> = trial
        .levels
        .iter()
        .map(|c| o.steady_surge_speed(2.0 * OTTER_THRUST_N * c, false))
        .collect();
    assert!((speeds[0] - 0.31).abs() < 0.01 && (speeds[2] - 0.80).abs() < 0.01);
}

/// The supply vessel in SI is MSS supply.m's conversion of the Bis model:
/// M = m·diag(1, 1, L)·M″·diag(1, 1, L) pattern and D = m√(g/L)·(same) of
/// D″ = −A″_h M″, which is supply.m's Dbis to its printed digits; and with
/// C_A on in still water it is the Bis model M″ν̇″ + C″(ν″)ν″ + D″ν″ = τ″
/// (C″ from the whole M″) of [`crate::dp_ship`].
#[test]
fn supply_vessel_is_the_bis_model_in_si() {
    let s = supply();
    let (m, l, g) = (SUPPLY_MASS, dp_ship::LENGTH_M, dp_ship::GRAVITY);
    let mb = Matrix3::from_fn(|i, j| dp_ship::M[i][j]);
    let db = -Matrix3::from_fn(|i, j| dp_ship::A_H[i][j]) * mb;
    let dbis = [
        [0.0358, 0.0, 0.0],
        [0.0, 0.1183, -0.0124],
        [0.0, -0.0041, 0.0308],
    ];
    for i in 0..3 {
        for j in 0..3 {
            assert!((db[(i, j)] - dbis[i][j]).abs() < 1e-4, "D″{i}{j}");
        }
    }
    let t = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, l));
    let m_si = m * t * mb * t;
    let d_si = m * (g / l).sqrt() * t * db * t;
    assert!((s.mass_matrix() - m_si).norm() < 1e-6 * m_si.norm());
    assert!((s.d_l() - d_si).norm() < 1e-9 * d_si.norm());
    assert!((s.x_g_m + 0.0744 * 76.2).abs() < 1e-9);

    let fx = Effects {
        munk: true,
        ..Effects::CLEAN
    };
    let sim = Simulator::new(&s, fx);
    let nu = Vector3::new(1.1, 0.3, 0.004);
    let tau = Vector3::new(1e5, 5e4, 1e6);
    let si = sim.nu_dot(&nu, 0.0, &tau, &CurrentNow::NONE);
    let vs = (g * l).sqrt();
    let nb = Vector3::new(nu[0] / vs, nu[1] / vs, nu[2] * (l / g).sqrt());
    let tb = Vector3::new(tau[0] / (m * g), tau[1] / (m * g), tau[2] / (m * g * l));
    let c13 = -mb[(1, 1)] * nb[1] - mb[(1, 2)] * nb[2];
    let c23 = mb[(0, 0)] * nb[0];
    let cnu = Vector3::new(c13 * nb[2], c23 * nb[2], -c13 * nb[0] - c23 * nb[1]);
    let ab = mb.try_inverse().unwrap() * (tb - cnu - db * nb);
    let bis = Vector3::new(ab[0] * g, ab[1] * g, ab[2] * g / l);
    assert!((si - bis).norm() < 1e-9 * bis.norm(), "{si} vs {bis}");
    let crit = s.critical_speed(true).unwrap();
    assert!((1.7..2.0).contains(&crit), "{crit}");
}

const SUPPLY_MASS: f64 = vessels::SUPPLY_MASS_KG;

/// Draws are seeded, within ±20 % of the nominal, and stable to their
/// design speed.
#[test]
fn draws_are_seeded_bounded_and_stable() {
    for (vessel, _) in both() {
        for seed in 0..20 {
            let d = vessel.draw(seed);
            assert_eq!(d, vessel.draw(seed));
            let pairs = [
                (d.mass_kg, vessel.mass_kg),
                (d.x_g_m, vessel.x_g_m),
                (d.i_z, vessel.i_z),
                (d.x_udot, vessel.x_udot),
                (d.y_vdot, vessel.y_vdot),
                (d.n_rdot, vessel.n_rdot),
                (d.x_u, vessel.x_u),
                (d.y_v, vessel.y_v),
                (d.n_r, vessel.n_r),
                (d.x_uu, vessel.x_uu),
                (d.cross_flow.cd, vessel.cross_flow.cd),
            ];
            for (a, b) in pairs {
                assert!((0.8..1.2).contains(&(a / b)), "{} seed {seed}", vessel.name);
            }
            assert!(d.critical_speed(true).is_none_or(|c| c > d.stable_to_mps));
        }
        assert_ne!(vessel.draw(1), vessel.draw(2));
    }
}

/// Every effect on, the default campaigns stay in the speed range the
/// vessels are stable in and keep moving in sway and yaw.
#[test]
fn full_physics_campaigns_stay_in_range() {
    let cur = Current::Constant {
        speed_mps: 0.3,
        direction_rad: 1.0,
    };
    let usv = UsvTrial {
        effects: Effects::all(cur),
        noise: Noise::NONE,
        ..UsvTrial::default()
    };
    let sup = SupplyTrial {
        effects: Effects::all(Current::Constant {
            speed_mps: 0.5,
            direction_rad: 1.0,
        }),
        noise: Noise::NONE,
        ..SupplyTrial::default()
    };
    for (camp, u_max, r_max) in [
        (fly_usv_campaign(&otter(), &usv, 2), 1.5, 1.0),
        (fly_supply_campaign(&supply(), &sup, 2), 2.0, 0.02),
    ] {
        for run in &camp.runs {
            let r = rows(&run.csv);
            let n = r[0].len();
            let (u, v, rr) = (n - 6, n - 5, n - 4);
            let peak = |c: usize| r.iter().map(|x| x[c].abs()).fold(0.0, f64::max);
            assert!(peak(u) < u_max, "{} u {}", run.name, peak(u));
            assert!(peak(rr) < r_max, "{} r {}", run.name, peak(rr));
            assert!(peak(v) > 0.0);
        }
    }
}
