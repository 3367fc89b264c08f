//! Inference of a run's description on records with known answers:
//! synthetic first-order DOFs driven open loop (each of the six DOFs alone,
//! square and PRBS, static holds with noise, a step-and-hold, every DOF at
//! once, the forward speed stepping through the grid), and a planned
//! campaign flown under the planner's PI control by the ROV truth.

use super::*;
use crate::identification::description::{RunRole, RunSignal};
use crate::planning::examples::surveyor_rov;
use crate::rng::SplitMix64;
use crate::signals::prbs::mls;

const FS: f64 = 10.0;

fn grid() -> Vec<f64> {
    [0.5, 1.0, 1.5, 2.0].iter().map(|k| k * KNOT).collect()
}

/// How a DOF's force is driven (fraction of its force limit).
#[derive(Clone, Copy)]
enum Drive {
    Hold,
    Prbs {
        amp: f64,
        chip_s: f64,
        seed: u64,
    },
    Square {
        amp: f64,
        half_s: f64,
    },
    /// Ramp over 5 s from 0 to `amp` after 5 s, then hold.
    Step {
        amp: f64,
    },
}

impl Drive {
    fn level(self, k: usize, chips: &[i8]) -> f64 {
        let t = k as f64 / FS;
        match self {
            Drive::Hold => 0.0,
            Drive::Prbs { amp, chip_s, .. } => {
                amp * f64::from(chips[(t / chip_s) as usize % chips.len()])
            }
            Drive::Square { amp, half_s } => {
                if ((t / half_s) as usize).is_multiple_of(2) {
                    amp
                } else {
                    -amp
                }
            }
            Drive::Step { amp } => amp * ((t - 5.0) / 5.0).clamp(0.0, 1.0),
        }
    }
}

/// A synthetic ROV run: each DOF first order, ν̇ = (τ/D − ν)/T with D =
/// max force / max velocity, τ open loop; surge trimmed to `speed(t)`.
/// DVL/gyro-like noise on ν, a little on τ.
fn synth(
    duration_s: f64,
    speed: impl Fn(f64) -> f64,
    drives: [Drive; 6],
    seed: u64,
) -> UniformRecord {
    let p = surveyor_rov();
    let n = (duration_s * FS) as usize;
    let mut rng = SplitMix64::new(seed);
    let noise_nu = [0.01, 0.01, 0.01, 0.005, 0.005, 0.005];
    let mut names = Vec::new();
    let mut data = Vec::new();
    let mut nus = Vec::new();
    for (j, d) in Dof::ALL.iter().enumerate() {
        let l = p.limit(*d);
        let dmp = l.max_force / l.max_velocity;
        let chips = match drives[j] {
            Drive::Prbs { seed, .. } => mls(7, seed).unwrap(),
            _ => vec![1],
        };
        let a = (-1.0 / (FS * l.time_constant_s)).exp();
        let mut nu = if j == 0 { speed(0.0) } else { 0.0 };
        let (mut tau, mut vel) = (Vec::with_capacity(n), Vec::with_capacity(n));
        for k in 0..n {
            let trim = if j == 0 {
                dmp * speed(k as f64 / FS)
            } else {
                0.0
            };
            let f = trim + drives[j].level(k, &chips) * l.max_force;
            tau.push(f + 5.0 * rng.normal());
            vel.push(nu + noise_nu[j] * rng.normal());
            nu = a * nu + (1.0 - a) * f / dmp;
        }
        names.push(d.force_column().to_string());
        data.push(tau);
        nus.push(vel);
    }
    for (d, v) in Dof::ALL.iter().zip(nus) {
        names.push(d.velocity_symbol().to_string());
        data.push(v);
    }
    UniformRecord {
        sample_rate_hz: FS,
        t0: 0.0,
        names,
        data,
        valid: std::iter::once(0..n).collect(),
    }
}

fn infer(rec: &UniformRecord) -> InferredDescription {
    let p = surveyor_rov();
    let inputs: Vec<String> = p
        .dofs
        .iter()
        .map(|d| d.force_column().to_string())
        .collect();
    infer_description(rec, &p, &inputs, &grid()).unwrap()
}

fn only(j: usize, d: Drive) -> [Drive; 6] {
    let mut out = [Drive::Hold; 6];
    out[j] = d;
    out
}

#[test]
fn each_dof_excited_alone_is_a_dynamic_run_at_its_grid_speed() {
    for (j, dof) in Dof::ALL.iter().enumerate() {
        // Surge: ±0.3 kn about the grid speed, like the planner's default.
        let amp = if j == 0 { 0.035 } else { 0.3 };
        let drive = Drive::Prbs {
            amp,
            chip_s: 4.0,
            seed: 3 + j as u64,
        };
        let rec = synth(300.0, |_| KNOT, only(j, drive), 10 + j as u64);
        let d = infer(&rec);
        assert_eq!(
            d.excited_dofs,
            vec![*dof],
            "{dof:?}: {}",
            d.excited_dofs_reason
        );
        assert_eq!(d.role, RunRole::Dynamic, "{dof:?}: {}", d.role_reason);
        assert_eq!(d.family, ExperimentFamily::Dynamic);
        let g = d.grid_speed_mps.expect("a grid speed");
        assert!((g - KNOT).abs() < 1e-12, "{dof:?}: {}", d.grid_speed_reason);
        assert!(
            d.grid_speed_reason.contains("1.00 kn"),
            "{}",
            d.grid_speed_reason
        );
        assert_eq!(d.signal, RunSignal::Prbs, "{dof:?}: {}", d.signal_reason);
        assert!(d.signal_reason.contains("4.0"), "{}", d.signal_reason);
    }
}

#[test]
fn a_square_wave_has_regular_half_periods() {
    let rec = synth(
        300.0,
        |_| 1.5 * KNOT,
        only(
            1,
            Drive::Square {
                amp: 0.3,
                half_s: 15.0,
            },
        ),
        4,
    );
    let d = infer(&rec);
    assert_eq!(d.excited_dofs, vec![Dof::Sway]);
    assert_eq!(d.signal, RunSignal::Square, "{}", d.signal_reason);
    assert!(d.signal_reason.contains("15.0"), "{}", d.signal_reason);
    assert!((d.grid_speed_mps.unwrap() - 1.5 * KNOT).abs() < 1e-12);
}

#[test]
fn a_held_run_with_noise_is_static_and_says_how_far_its_speed_was_from_the_grid() {
    let rec = synth(120.0, |_| 1.55 * KNOT, [Drive::Hold; 6], 5);
    let d = infer(&rec);
    assert_eq!(d.role, RunRole::Static, "{}", d.role_reason);
    assert!(d.excited_dofs.is_empty(), "{}", d.excited_dofs_reason);
    assert!(d.role_reason.contains("noise floor"), "{}", d.role_reason);
    assert!((d.grid_speed_mps.unwrap() - 1.5 * KNOT).abs() < 1e-12);
    assert!(
        d.grid_speed_reason.contains("above the grid point"),
        "{}",
        d.grid_speed_reason
    );
    let mean = d.mean_forward_speed_mps.unwrap();
    assert!((mean - 1.55 * KNOT).abs() < 0.01, "{mean}");
    assert_eq!(d.signal, RunSignal::Other);
}

#[test]
fn a_step_and_hold_is_a_static_run_of_that_dof() {
    let rec = synth(80.0, |_| KNOT, only(2, Drive::Step { amp: 0.4 }), 6);
    let d = infer(&rec);
    assert_eq!(d.role, RunRole::Static, "{}", d.role_reason);
    assert_eq!(
        d.excited_dofs,
        vec![Dof::Heave],
        "{}",
        d.excited_dofs_reason
    );
    assert!(
        d.role_reason.contains("heave steps once"),
        "{}",
        d.role_reason
    );
}

#[test]
fn every_dof_at_once_at_one_speed_is_recursive() {
    let mut drives = [Drive::Hold; 6];
    for (j, dr) in drives.iter_mut().enumerate() {
        *dr = Drive::Prbs {
            amp: if j == 0 { 0.035 } else { 0.25 },
            chip_s: 3.0,
            seed: 40 + 7 * j as u64,
        };
    }
    let d = infer(&synth(400.0, |_| 2.0 * KNOT, drives, 7));
    assert_eq!(d.role, RunRole::Recursive, "{}", d.role_reason);
    assert_eq!(
        d.excited_dofs,
        Dof::ALL.to_vec(),
        "{}",
        d.excited_dofs_reason
    );
    assert!((d.grid_speed_mps.unwrap() - 2.0 * KNOT).abs() < 1e-12);
}

#[test]
fn a_speed_stepping_through_the_grid_is_a_validation_run() {
    let mut drives = [Drive::Hold; 6];
    for (j, dr) in drives.iter_mut().enumerate().skip(1) {
        *dr = Drive::Prbs {
            amp: 0.25,
            chip_s: 2.0,
            seed: 70 + j as u64,
        };
    }
    // 1 kn, then 1.5 kn, then 2 kn, 150 s each.
    let speed = |t: f64| (1.0 + 0.5 * (t / 150.0).floor().min(2.0)) * KNOT;
    let d = infer(&synth(450.0, speed, drives, 8));
    assert_eq!(d.role, RunRole::Validation, "{}", d.role_reason);
    assert_eq!(d.family, ExperimentFamily::Validation);
    assert!(d.grid_speed_mps.is_none(), "{}", d.grid_speed_reason);
    for k in ["1.00 kn", "1.50 kn", "2.00 kn"] {
        assert!(d.role_reason.contains(k), "{}", d.role_reason);
    }
    // A surge excitation of ±0.3 kn about one grid speed does not wander.
    let surge = only(
        0,
        Drive::Square {
            amp: 0.035,
            half_s: 20.0,
        },
    );
    let d = infer(&synth(300.0, |_| KNOT, surge, 9));
    assert_eq!(d.role, RunRole::Dynamic, "{}", d.role_reason);
    assert_eq!(d.signal, RunSignal::Square, "{}", d.signal_reason);
}

#[test]
fn too_little_data_or_mismatched_inputs_are_errors() {
    let p = surveyor_rov();
    let rec = synth(0.5, |_| 0.0, [Drive::Hold; 6], 1);
    let inputs: Vec<String> = p
        .dofs
        .iter()
        .map(|d| d.force_column().to_string())
        .collect();
    assert!(infer_description(&rec, &p, &inputs, &grid()).is_err());
    let rec = synth(60.0, |_| 0.0, [Drive::Hold; 6], 1);
    assert!(infer_description(&rec, &p, &inputs[..2], &grid()).is_err());
}

/// A planned campaign (static, dynamic, recursive and validation at 1 and
/// 2 kn) flown by the ROV truth under the planner's PI control and logged
/// with the default DVL/gyro noise: the right role, grid speed and excited
/// DOFs on ≥ 95 % of the runs.
#[test]
fn a_flown_campaign_is_described_as_planned() {
    use crate::identification::tests::to_run;
    use crate::planning::{CampaignSpec, generate_plan};
    use crate::simulation::rov::RovTruth;
    use crate::simulation::trials::{TrialSettings, fly_experiment};
    let profile = surveyor_rov();
    let spec: CampaignSpec = serde_json::from_value(serde_json::json!({
        "name": "description trial",
        "grid": { "unit": "kn", "speeds": [1.0, 2.0] },
        "families": ["static", "dynamic", "recursive", "validation"],
        "repetitions": 1,
        "seed": 5
    }))
    .unwrap();
    let plan = generate_plan(&profile, &spec).unwrap();
    let truth = RovTruth::surveyor_like();
    let settings = TrialSettings {
        max_duration_s: Some(240.0),
        seed: 9,
        ..TrialSettings::default()
    };
    let grid = spec.grid.speeds_si();
    let inputs: Vec<String> = profile
        .dofs
        .iter()
        .map(|d| d.force_column().to_string())
        .collect();
    let (mut ok_role, mut ok_speed, mut ok_dofs, mut n, mut prbs) = (0, 0, 0, 0, 0);
    let mut misses = Vec::new();
    for p in &plan.experiments {
        let e = &p.experiment;
        let f = fly_experiment(&profile, &truth, p, &settings).unwrap();
        let run = to_run(&f.code, f.family, f.grid_speed_mps, &f.record);
        let d = infer_description(&run.record, &profile, &inputs, &grid).unwrap();
        n += 1;
        let role_ok = d.role == RunRole::of_family(e.family);
        let speed_ok = d.grid_speed_mps == e.grid_speed_mps;
        // A static surge run holds the grid speed: nothing moves.
        let want: Vec<Dof> = if e.family == ExperimentFamily::Static && e.dofs == [Dof::Surge] {
            vec![]
        } else {
            e.dofs.clone()
        };
        let dofs_ok = d.excited_dofs == want;
        // The planned signal is a PRBS: told as such, or honestly as other
        // (too few switches in a short closed-loop run), never as a square.
        if e.family == ExperimentFamily::Dynamic {
            assert!(
                matches!(d.signal, RunSignal::Prbs | RunSignal::Other),
                "{}: {:?} ({})",
                e.code,
                d.signal,
                d.signal_reason
            );
            prbs += usize::from(d.signal == RunSignal::Prbs);
        }
        ok_role += usize::from(role_ok);
        ok_speed += usize::from(speed_ok);
        ok_dofs += usize::from(dofs_ok);
        if !(role_ok && speed_ok && dofs_ok) {
            misses.push(format!(
                "{} {:?}: role {:?} ({}), speed {:?} ({}), dofs {:?} ({})",
                e.code,
                d.dofs
                    .iter()
                    .map(|a| (a.dof.name(), a.switches, a.step_share, a.score))
                    .collect::<Vec<_>>(),
                d.role,
                d.role_reason,
                d.grid_speed_mps,
                d.grid_speed_reason,
                d.excited_dofs,
                d.excited_dofs_reason
            ));
        }
    }
    let need = (0.95 * n as f64).ceil() as usize;
    assert!(
        ok_role >= need && ok_speed >= need && ok_dofs >= need,
        "of {n} runs: role {ok_role}, grid speed {ok_speed}, DOFs {ok_dofs} right; misses:\n{}",
        misses.join("\n")
    );
    assert!(prbs >= 4, "only {prbs} of the 12 dynamic runs told as PRBS");
}
