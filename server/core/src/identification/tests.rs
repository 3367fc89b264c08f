//! End-to-end proof of the campaign pipeline on a simulated ROV whose truth
//! is known: runs → roles → λ identification per grid point → validation.

use nalgebra::DMatrix;

use super::dataset::RunInput;
use super::lambda_campaign::{LambdaCampaignSettings, StructureChoice, identify_lambda_campaign};
use crate::estimation::NoProgress;
use crate::planning::campaign::ExperimentFamily;
use crate::planning::examples::surveyor_rov;
use crate::rng::SplitMix64;
use crate::simulation::rov::{RovRecord, RovTruth, SimConfig};
use crate::timeseries::UniformRecord;

pub(crate) const H: f64 = 0.1;

/// τ columns of a force-actuated vessel, in DOF order.
pub(crate) fn force_columns(profile: &crate::planning::VesselProfile) -> Vec<String> {
    profile
        .dofs
        .iter()
        .map(|d| d.force_column().to_string())
        .collect()
}

/// τ: the trim force that holds `speed` in surge, plus a random-binary
/// excitation in every DOF (clock 2 s) of `amp` times the DOF's force limit.
fn excitation(truth: &RovTruth, speed: &[f64], amp: f64, seed: u64) -> DMatrix<f64> {
    let profile = surveyor_rov();
    let mut rng = SplitMix64::new(seed);
    let n = speed.len();
    let mut tau = DMatrix::zeros(n, 6);
    let clock = (2.0 / H) as usize;
    let mut level = [0.0; 6];
    for k in 0..n {
        if k % clock == 0 {
            for l in &mut level {
                *l = if rng.uniform() < 0.5 { -1.0 } else { 1.0 };
            }
        }
        let d = truth.damping.at(speed[k]);
        for (i, dof) in profile.dofs.iter().enumerate() {
            let f = profile.limit(*dof).max_force;
            tau[(k, i)] = amp * f * level[i];
        }
        tau[(k, 0)] += d[(0, 0)] * speed[k];
    }
    tau
}

pub(crate) fn to_run(
    id: &str,
    family: ExperimentFamily,
    grid: Option<f64>,
    rec: &RovRecord,
) -> RunInput {
    let mut names = vec!["t".to_string()];
    let mut data = vec![rec.t.clone()];
    for (j, c) in ["tau_X", "tau_Y", "tau_Z", "tau_K", "tau_M", "tau_N"]
        .iter()
        .enumerate()
    {
        names.push(c.to_string());
        data.push(rec.tau_commanded.column(j).iter().copied().collect());
    }
    for (j, c) in ["u", "v", "w", "p", "q", "r"].iter().enumerate() {
        names.push(c.to_string());
        data.push(rec.nu.column(j).iter().copied().collect());
    }
    for (j, c) in ["x", "y", "z", "phi", "theta", "psi"].iter().enumerate() {
        names.push(c.to_string());
        data.push(rec.eta.column(j).iter().copied().collect());
    }
    let n = rec.t.len();
    RunInput {
        run_id: id.into(),
        name: id.into(),
        family: Some(family),
        grid_speed_mps: grid,
        excited_dofs: vec![],
        record: UniformRecord {
            sample_rate_hz: 1.0 / H,
            t0: 0.0,
            names,
            data,
            valid: std::iter::once(0..n).collect(),
        },
    }
}

pub(crate) fn simulate(truth: &RovTruth, speed: Vec<f64>, seed: u64) -> RovRecord {
    let tau = excitation(truth, &speed, 0.25, seed);
    let cfg = SimConfig {
        h: H,
        nu0: [speed[0], 0.0, 0.0, 0.0, 0.0, 0.0],
        noise_nu: [0.005, 0.005, 0.005, 0.002, 0.002, 0.002],
        noise_seed: seed ^ 0xA5,
        ..SimConfig::default()
    };
    truth.simulate(&tau, &cfg).expect("simulation")
}

fn campaign() -> (RovTruth, Vec<f64>, Vec<RunInput>) {
    // Linear truth (no quadratic damping, no Coriolis, neutral restoring):
    // what the λ method's model M ν̇ + D̄ ν = γ can represent exactly at each
    // grid point.
    let mut truth = RovTruth::surveyor_like();
    truth.restoring = Default::default();
    let grid = vec![0.5, 1.0];
    let mut runs = Vec::new();
    for (g, &u0) in grid.iter().enumerate() {
        for r in 0..2 {
            let rec = simulate(&truth, vec![u0; 3000], 100 + 10 * g as u64 + r);
            runs.push(to_run(
                &format!("dyn-{g}-{r}"),
                ExperimentFamily::Recursive,
                Some(u0),
                &rec,
            ));
        }
    }
    // Validation: 300 s at each grid speed in turn, never fitted.
    let speed: Vec<f64> = (0..4000)
        .map(|k| if k < 2000 { 0.5 } else { 1.0 })
        .collect();
    let rec = simulate(&truth, speed, 999);
    runs.push(to_run("val", ExperimentFamily::Validation, None, &rec));
    (truth, grid, runs)
}

#[test]
fn lpv_campaign_recovers_the_coupled_truth_and_validates_on_held_out_data() {
    let (truth, grid, runs) = campaign();
    let profile = surveyor_rov();
    let inputs = force_columns(&profile);
    let settings = LambdaCampaignSettings::default();
    let out = identify_lambda_campaign(&profile, &grid, &inputs, &runs, &settings, &mut NoProgress)
        .unwrap();
    assert_eq!(out.validation_run_ids, ["val"]);
    assert_eq!(out.estimation_run_ids.len(), 4);
    let lpv = out.document.lpv.as_ref().unwrap();
    assert_eq!(lpv.points.len(), 2);
    // M is speed-independent in the truth: every grid point recovers it.
    for p in &lpv.points {
        for i in 0..6 {
            let (est, true_m) = (p.m[i][i], truth.m[(i, i)]);
            assert!(
                (est - true_m).abs() < 0.1 * true_m,
                "M[{i},{i}] at {} m/s: {est} vs {true_m}",
                p.speed_mps
            );
        }
    }
    // Held-out validation: every channel fits well in simulation.
    let rep = &out.validation[0].report;
    for ch in &rep.channels {
        let fit = ch.fit_simulation.expect("simulation fit");
        assert!(fit > 0.8, "{}: simulation fit {fit}", ch.output);
        assert!(ch.fit_one_step.unwrap() > 0.8, "{}: 1-step", ch.output);
    }
    assert!(!out.document.parameters.is_empty());
    assert!(out.document.parameters.iter().all(|p| p.std.is_some()));
}

#[test]
fn diagonal_structure_is_worse_on_the_coupled_truth() {
    let (_, grid, runs) = campaign();
    let profile = surveyor_rov();
    let inputs = force_columns(&profile);
    let fit = |structure| {
        let s = LambdaCampaignSettings {
            structure,
            ..Default::default()
        };
        let out =
            identify_lambda_campaign(&profile, &grid, &inputs, &runs, &s, &mut NoProgress).unwrap();
        out.validation[0]
            .report
            .channels
            .iter()
            .map(|c| c.fit_simulation.unwrap())
            .collect::<Vec<_>>()
    };
    let coupled = fit(StructureChoice::Auto);
    let diagonal = fit(StructureChoice::Diagonal);
    // Sway–yaw and heave–pitch are coupled in the truth.
    let worst_gap = coupled
        .iter()
        .zip(&diagonal)
        .map(|(c, d)| c - d)
        .fold(f64::NEG_INFINITY, f64::max);
    assert!(
        worst_gap > 0.02,
        "coupled {coupled:?} vs diagonal {diagonal:?}"
    );
}

#[test]
fn missing_validation_and_bad_settings_name_the_field() {
    let (_, grid, runs) = campaign();
    let profile = surveyor_rov();
    let inputs = force_columns(&profile);
    let e = identify_lambda_campaign(
        &profile,
        &grid,
        &inputs,
        &runs[..4],
        &LambdaCampaignSettings::default(),
        &mut NoProgress,
    )
    .unwrap_err();
    assert_eq!(e.field(), "settings.validation_run_ids");
    let s = LambdaCampaignSettings {
        t_lambda_s: Some(0.01),
        ..Default::default()
    };
    let e =
        identify_lambda_campaign(&profile, &grid, &inputs, &runs, &s, &mut NoProgress).unwrap_err();
    assert_eq!(e.field(), "settings.t_lambda_s");
    let s = LambdaCampaignSettings {
        structure: StructureChoice::Custom,
        ..Default::default()
    };
    let e =
        identify_lambda_campaign(&profile, &grid, &inputs, &runs, &s, &mut NoProgress).unwrap_err();
    assert_eq!(e.field(), "settings.coupling");
}

#[test]
fn n4sid_campaign_fits_held_out_data_about_the_mean_operating_point() {
    use super::n4sid_campaign::{N4sidCampaignSettings, identify_n4sid_campaign};
    let (_, _, runs) = campaign();
    let profile = surveyor_rov();
    let inputs = force_columns(&profile);
    let s = N4sidCampaignSettings {
        order: Some(6),
        ..Default::default()
    };
    let out = identify_n4sid_campaign(&profile, &inputs, &runs, &s, &mut NoProgress).unwrap();
    let ss = out.document.state_space.as_ref().unwrap();
    assert_eq!(ss.order, 6);
    // The truth is first order per DOF with speed-dependent damping: an LTI
    // model about the mean speed predicts one step ahead well.
    for ch in &out.validation[0].report.channels {
        assert!(
            ch.fit_one_step.unwrap() > 0.8,
            "{}: {:?}",
            ch.output,
            ch.fit_one_step
        );
    }
    // Every discrete pole of a stable vessel lies inside the unit circle.
    assert!(out.document.parameters.iter().all(|p| p.value < 1.0));
}

#[test]
fn a_stored_model_validates_on_a_run_as_it_did_at_identification() {
    use super::predictor::validate_on_run;
    let (_, grid, runs) = campaign();
    let profile = surveyor_rov();
    let inputs = force_columns(&profile);
    for method in ["lambda", "n4sid"] {
        let out = if method == "lambda" {
            identify_lambda_campaign(
                &profile,
                &grid,
                &inputs,
                &runs,
                &Default::default(),
                &mut NoProgress,
            )
        } else {
            super::n4sid_campaign::identify_n4sid_campaign(
                &profile,
                &inputs,
                &runs,
                &Default::default(),
                &mut NoProgress,
            )
        }
        .unwrap();
        // Through JSON, as the store keeps it.
        let doc: super::document::ModelDocument =
            serde_json::from_value(serde_json::to_value(&out.document).unwrap()).unwrap();
        let again = validate_on_run(&doc, &runs[4], &inputs, 10).unwrap();
        for (a, b) in again
            .channels
            .iter()
            .zip(&out.validation[0].report.channels)
        {
            assert!(
                (a.fit_one_step.unwrap() - b.fit_one_step.unwrap()).abs() < 1e-9,
                "{method} {}: {:?} vs {:?}",
                a.output,
                a.fit_one_step,
                b.fit_one_step
            );
        }
    }
}

/// A surge–pitch [`lpv_doc`] at 0.5 and 1.0 m/s with coupled M and D̄ (the
/// export tests' fixture).
pub(crate) fn surge_pitch_doc() -> super::document::ModelDocument {
    use crate::planning::dof::Dof;
    lpv_doc(
        vec![Dof::Surge, Dof::Pitch],
        vec![
            (
                0.5,
                vec![vec![2000.0, 10.0], vec![10.0, 300.0]],
                vec![vec![500.0, 1.0], vec![2.0, 90.0]],
            ),
            (
                1.0,
                vec![vec![2100.0, 11.0], vec![11.0, 310.0]],
                vec![vec![700.0, 1.5], vec![2.5, 95.0]],
            ),
        ],
    )
}

/// A λ LPV document over `dofs` with one sub-model per (speed, M, D̄):
/// A = −M⁻¹D̄, B = M⁻¹ (zero when M is singular), zero stds, no loads, no
/// restoring — the fixture tests adjust what they need.
pub(crate) fn lpv_doc(
    dofs: Vec<crate::planning::dof::Dof>,
    points: Vec<(f64, super::document::Matrix, super::document::Matrix)>,
) -> super::document::ModelDocument {
    use super::document::{LpvDoc, LpvPoint, Method, ModelDocument, ModelKind, from_rows, to_rows};
    let n = dofs.len();
    let zeros = vec![vec![0.0; n]; n];
    let points = points
        .into_iter()
        .map(|(speed, m, d_bar)| {
            let (mm, dm) = (from_rows(&m).unwrap(), from_rows(&d_bar).unwrap());
            let b = mm.try_inverse().unwrap_or_else(|| DMatrix::zeros(n, n));
            LpvPoint {
                speed_mps: speed,
                a: to_rows(&(-&b * dm)),
                b: to_rows(&b),
                m,
                d_bar,
                m_std: zeros.clone(),
                d_bar_std: zeros.clone(),
                a_std: zeros.clone(),
                b_std: zeros.clone(),
                load: None,
                load_std: None,
                n_samples: 1,
                run_ids: vec![],
                current_force: None,
                augmentation: None,
            }
        })
        .collect();
    ModelDocument {
        kind: ModelKind::Lpv,
        method: Method::LambdaKf,
        dofs,
        inputs: vec![],
        outputs: vec![],
        restoring: None,
        lpv: Some(LpvDoc {
            t_lambda_s: 1.0,
            structure: "diagonal".into(),
            coupling: vec![],
            points,
            logged_controller: None,
            extension: None,
            coriolis_second_order: false,
            quadratic_damping: None,
            quadratic_damping_std: None,
            current: None,
        }),
        dp_ship: None,
        state_space: None,
        parameters: vec![],
        structure_findings: vec![],
        notes: vec![],
    }
}
