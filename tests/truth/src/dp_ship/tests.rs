//! The DP ship's flight checks.
use super::*;

/// A steady surge under constant thrust settles at u = K·2·c / (−A_h11·M11)
/// (D·ν = T·K·u with D = −A_h·M), and νᵀC(ν)ν = 0.
#[test]
fn steady_surge_and_coriolis_do_no_work() {
    let m = mat(&M);
    let nu = Vector3::new(0.3, -0.2, 0.05);
    assert!(nu.dot(&coriolis(&m, &nu)).abs() < 1e-15);
    let m_inv = m.try_inverse().unwrap();
    let d = -mat(&A_H) * m;
    let c = 0.25;
    let f = Vector3::new(2.0 * K[0] * c, 0.0, 0.0);
    let mut s = [0.0; 6];
    let dt = 0.05;
    for _ in 0..40_000 {
        let k = deriv(&m_inv, &m, &d, &s, &f);
        for i in 0..6 {
            s[i] += dt * k[i];
        }
    }
    let expected = 2.0 * K[0] * c / (-A_H[0][0] * M[0][0]);
    assert!(
        (s[0] / expected - 1.0).abs() < 1e-6,
        "{} vs {expected}",
        s[0]
    );
    assert!(s[1].abs() < 1e-12 && s[2].abs() < 1e-12);
}

#[test]
fn campaign_logs_position_only_at_one_hertz() {
    let logs = fly_dp_campaign(&DpTrial::default(), 7);
    assert_eq!(logs.len(), 7);
    let first = &logs[0].csv;
    assert!(first.starts_with("t,thr_1,thr_2,thr_3,thr_4,thr_5,thr_6,x,y,psi\n"));
    assert_eq!(first.lines().count(), 601);
    assert_eq!(logs[6].manoeuvre.family(), "validation");
}

/// Every order's register runs through all 2ⁿ − 1 nonzero states: the
/// sequence is balanced (one more +1 than −1) and has 2ⁿ⁻¹ runs.
#[test]
fn shift_register_sequences_are_maximum_length() {
    let mut rng = Rng::new(3);
    for order in 3..=10 {
        let s = m_sequence(&mut rng, order);
        let m = (1usize << order) - 1;
        assert_eq!(s.len(), m);
        assert_eq!(s.iter().sum::<f64>(), 1.0, "order {order}");
        let runs = (0..m).filter(|&i| s[i] != s[(i + m - 1) % m]).count();
        assert_eq!(runs, 1 << (order - 1), "order {order}");
    }
}

#[test]
fn prbs_campaign_flies_binary_slewed_commands() {
    let run = |order, chip_s, samples| PrbsRun {
        order,
        chip_s,
        samples,
    };
    let trial = DpTrial {
        inputs: DpInputs::Prbs {
            level: 0.5,
            slew: 0.1,
            surge: run(3, 87.6, 613),
            sway_yaw: run(5, 20.0, 620),
            azimuth: run(5, 20.0, 620),
            validation: run(0, 20.0, 600),
        },
        validation_runs: 2,
        ..DpTrial::default()
    };
    let logs = fly_dp_campaign(&trial, 4);
    assert_eq!(logs.len(), 8);
    assert_eq!(logs[7].name, "VAL-2");
    let col = |log: &DpLog, c: usize| -> Vec<f64> {
        log.csv
            .lines()
            .skip(1)
            .map(|l| l.split(',').nth(c).unwrap().parse().unwrap())
            .collect()
    };
    assert_eq!(col(&logs[0], 1).len(), 613);
    let stern = col(&logs[2], 3);
    let bow = col(&logs[2], 5);
    assert_eq!(stern.len(), 620);
    assert!((stern[0].abs() - 0.1).abs() < 1e-9);
    assert!(stern.iter().all(|u| u.abs() <= 0.5 + 1e-9));
    assert!(stern.windows(2).all(|w| (w[1] - w[0]).abs() <= 0.1 + 1e-9));
    // 31 chips of 20 s: 16 holds, each a whole number of chips.
    let held: Vec<f64> = stern.iter().copied().filter(|u| u.abs() > 0.25).collect();
    let flips = held.windows(2).filter(|w| w[0] * w[1] < 0.0).count();
    assert!((14..=16).contains(&flips), "{flips}");
    assert_ne!(stern, bow);
    assert!(col(&logs[4], 1).iter().all(|&u| u == 0.0));
}
