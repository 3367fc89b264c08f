//! A declared autopilot flying attitude holds against the restoring moment.

use super::*;

/// The Surveyor profile with an autopilot: PI on u, v, w, r at 0.8 rad/s,
/// PD attitude loops on φ, θ at 1.2 rad/s (ζ = 0.8), feeding forward
/// `ff` × the truth's righting moment z_G W − z_B B (and its W − B).
fn with_autopilot(truth: &RovTruth, ff: f64) -> VesselProfile {
    use crate::planning::{Autopilot, AutopilotLoop, RestoringFeedForward};
    let mut profile = surveyor_rov();
    let m = truth.m;
    let loops = profile
        .dofs
        .iter()
        .map(|&d| {
            let mi = m[(d.index(), d.index())];
            let l = if matches!(d, Dof::Roll | Dof::Pitch) {
                let kp = mi * 1.2 * 1.2;
                AutopilotLoop {
                    kp,
                    ki: 0.0,
                    kd: Some(2.0 * 0.8 * (kp * mi).sqrt()),
                }
            } else {
                AutopilotLoop {
                    kp: mi * 0.8,
                    ki: mi * 0.8 * 0.8 / 3.0,
                    kd: None,
                }
            };
            (d, l)
        })
        .collect();
    let r = &truth.restoring;
    profile.autopilot = Some(Autopilot {
        loops,
        restoring_feed_forward: Some(RestoringFeedForward {
            w_minus_b: r.weight - r.buoyancy,
            zg_w_minus_zb_b: ff * (r.r_g[2] * r.weight - r.r_b[2] * r.buoyancy),
        }),
    });
    profile.validate().unwrap();
    profile
}

#[test]
fn a_declared_autopilot_holds_attitude_where_its_pd_law_and_the_restoring_moment_balance() {
    // Static roll and pitch holds at one grid speed, noise-free. With ĝ
    // exact the PD loop's steady error is zero; with ĝ's righting moment
    // 30 % short it settles where K_p (η_ref − η) = 0.3·BG·W·sin η (roll:
    // ·cos θ), Fossen eq. 4.6 with the loop's own law, solved by Newton.
    let mut truth = RovTruth::surveyor_like();
    truth.quadratic_damping = RovTruth::SURVEYOR_QUADRATIC_DAMPING;
    let bg = truth.restoring.r_g[2] * truth.restoring.weight
        - truth.restoring.r_b[2] * truth.restoring.buoyancy;
    for ff in [1.0, 0.7] {
        let profile = with_autopilot(&truth, ff);
        let plan = plan_of(&profile, Quantity::Velocity);
        let runs = fly_campaign(&profile, &truth, &plan, &quiet(), |e| {
            e.family == ExperimentFamily::Static && e.grid_index == Some(1)
        })
        .unwrap();
        let mut holds = 0;
        for run in &runs {
            let rec = &run.record;
            let k = rec.len() - 1;
            for d in [Dof::Roll, Dof::Pitch] {
                let i = d.index();
                let Drive::Attitude(c) = run.drives[i] else {
                    continue;
                };
                let planned = find(&plan, &run.code);
                let eta_ref = *planned.schedule.values[c].last().unwrap();
                if eta_ref.abs() < 1e-3 {
                    continue;
                }
                holds += 1;
                let kp = profile.autopilot.as_ref().unwrap().loops[&d].kp;
                // Newton on f(η) = K_p (η_ref − η) − (1 − ff)·BG·sin η.
                let short = (1.0 - ff) * bg;
                let mut eta = eta_ref;
                for _ in 0..50 {
                    let f = kp * (eta_ref - eta) - short * eta.sin();
                    let df = -kp - short * eta.cos();
                    eta -= f / df;
                }
                let got = rec.eta_true[(k, i)];
                assert!(
                    (got - eta).abs() < 2e-3 * eta_ref.abs(),
                    "{} ff {ff}: {} settled at {got:.6} rad, expected {eta:.6} (ref {eta_ref})",
                    run.code,
                    d.name()
                );
                if ff < 1.0 {
                    assert!((got - eta_ref).abs() > 0.01 * eta_ref.abs(), "{}", run.code);
                }
            }
            // The velocity loops' integral action: no steady-state error.
            for d in [Dof::Surge, Dof::Sway, Dof::Heave, Dof::Yaw] {
                let i = d.index();
                if let Drive::Velocity(_) = run.drives[i] {
                    let e = run.nu_ref[(k, i)] - rec.nu_true[(k, i)];
                    assert!(
                        e.abs() < 1e-3 * profile.limit(d).max_velocity,
                        "{}: {} e = {e}",
                        run.code,
                        d.name()
                    );
                }
            }
        }
        assert!(holds >= 4, "{holds} attitude holds flown");
    }
}
